//! The user-profile regenerator of `examples/custom_profile.rs`: an array of CVs whose wall
//! temperatures follow a power law chosen in user code, at a run-time `n`.

mod common;
#[path = "../examples/custom_profile.rs"]
#[allow(dead_code)]
mod ex;

use ex::ProfiledRegenerator;
use stirling::dsl::{Closure, Model};
use stirling::models::family::NSection;
use stirling::models::linear::{self, NewtonOptions};

#[test]
fn jacobians_match_finite_differences() {
    for n in [1, 4] {
        let m = ProfiledRegenerator::new(n, Closure::Full).unwrap();
        common::assert_jacobians(
            &m,
            &format!("profiled_regenerator n = {n}"),
            40 + n as u64,
            3,
        );
    }
    let m = ProfiledRegenerator::new(3, Closure::Frozen).unwrap();
    common::assert_jacobians(&m, "profiled_regenerator n = 3 frozen", 47, 2);
}

/// The declared profile is the one the generated model uses: at rest each section's gas
/// sits at its wall temperature.
#[test]
fn rest_temperatures_follow_the_declared_profile() {
    for n in [1, 2, 7] {
        let s = ex::run(&ex::Args {
            n,
            kappa: 2.0,
            json: false,
        })
        .unwrap();
        let c = &s.chosen;
        assert_eq!(c.gas.len(), n + 2);
        assert_eq!(c.wall, ex::wall_profile(600.0, 300.0, 2.0, n));
        for (tw, tg) in c.wall.iter().zip(&c.gas[1..=n]) {
            assert!(
                (tw - tg).abs() < 1e-9 * tw,
                "section wall {tw} K, gas {tg} K"
            );
        }
        // the profile sags toward Tk: below the linear one everywhere
        for (a, b) in c.wall.iter().zip(&s.linear_profile.wall) {
            assert!(a <= b, "{:?} vs {:?}", c.wall, s.linear_profile.wall);
        }
    }
}

/// With `kappa = 1` the user's model is the seed's `nsection`: same states, same
/// right-hand side, same poles.
#[test]
fn the_linear_profile_reproduces_nsection() {
    for n in [1, 3, 6] {
        let user = ProfiledRegenerator::new(n, Closure::Full).unwrap();
        let seed = NSection::new(n, Closure::Full).unwrap();
        assert_eq!(user.n_states(), seed.n_states());
        let mut pu = user.default_params();
        pu[user.param_index("kappa").unwrap()] = 1.0;
        let ps = seed.default_params();
        for (k, info) in seed.params().iter().enumerate() {
            assert_eq!(
                pu[user.param_index(info.name).unwrap()],
                ps[k],
                "{}",
                info.name
            );
        }
        let mut rng = common::rng(3 + n as u64);
        for _ in 0..3 {
            let x = common::random_state(&seed, &ps, common::Spread::Wide, &mut rng);
            let (mut fu, mut fs) = (vec![0.0; x.len()], vec![0.0; x.len()]);
            user.rhs(&pu, &x, 0.0, &mut fu);
            seed.rhs(&ps, &x, 0.0, &mut fs);
            for (a, b) in fu.iter().zip(&fs) {
                assert!(
                    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-6),
                    "rhs {a} vs {b}"
                );
            }
        }
        let du = linear::dynamic_poles(&user, &pu, &NewtonOptions::default()).unwrap();
        let ds = linear::dynamic_poles(&seed, &ps, &NewtonOptions::default()).unwrap();
        for (a, b) in du.poles.iter().zip(&ds.poles) {
            assert!(
                (a.re - b.re).abs() + (a.im - b.im).abs() <= 1e-7 * a.natural_rad_s.max(1.0),
                "{a:?} vs {b:?}"
            );
        }
    }
}

/// The example at a run-time `n` from the command line: both profiles analysed, an unstable
/// pair near 85 rad/s, margins read off.
#[test]
fn the_example_runs_at_a_runtime_n() {
    let args = ex::parse_args(["--n", "5", "--kappa", "2"].map(String::from)).unwrap();
    let s = ex::run(&args).unwrap();
    ex::print(&s);
    let json = ex::json(&s);
    assert_eq!(s.model.n(), 5);
    for c in [&s.chosen, &s.linear_profile] {
        let rhp: Vec<_> = c.linear.dynamics.poles.iter().filter(|p| p.rhp).collect();
        assert_eq!(
            rhp.len(),
            2,
            "kappa {}: {:?}",
            c.kappa,
            c.linear.dynamics.poles
        );
        assert!((rhp[0].im.abs() - 85.0).abs() < 30.0, "{:?}", rhp[0]);
        assert!(c.linear.margins.gain_db.is_some(), "{:?}", c.linear.margins);
    }
    assert_eq!(
        json["chosen"]["wall_temperatures"]
            .as_array()
            .unwrap()
            .len(),
        5
    );
    assert!(ex::parse_args(["--kappa", "-1"].map(String::from)).is_err());
    assert!(ex::parse_args(["--n", "x"].map(String::from)).is_err());
}
