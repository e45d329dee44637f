//! Limits of a wall's heat capacity (docs/custom-topologies.md, walls): as it grows the model
//! tends to the fixed-wall model (its poles converge; at `capacity: 1.0 / k` with `k = 0` the
//! rows are the fixed model's exactly), and as it shrinks the wall temperature follows the gas.

#[path = "dsl_walls/models.rs"]
mod models;

use models::{Fixed, HeadWall, MatrixWall};
use stirling::dsl::{Closure, Model, StateKind};
use stirling::models::linear::{self, NewtonOptions};
use stirling::models::sim::{self, SimOptions};

fn set(m: &dyn Model, p: &mut [f64], name: &str, v: f64) {
    p[m.param_index(name).unwrap()] = v;
}

/// The poles of the inventory-reduced Jacobian at the equilibrium.
fn poles(m: &dyn Model, p: &[f64]) -> Vec<(f64, f64)> {
    let d = linear::dynamic_poles(m, p, &NewtonOptions::default()).unwrap();
    d.poles.iter().map(|q| (q.re, q.im)).collect()
}

/// The largest distance from a pole of `fixed` to the nearest pole of `walls`, relative to
/// the pole's modulus.
fn distance(walls: &[(f64, f64)], fixed: &[(f64, f64)]) -> f64 {
    let near = |a: &(f64, f64)| {
        walls
            .iter()
            .map(|b| (a.0 - b.0).hypot(a.1 - b.1))
            .fold(f64::INFINITY, f64::min)
            / a.0.hypot(a.1).max(1.0)
    };
    fixed.iter().map(near).fold(0.0, f64::max)
}

/// `kh = 0` (the head's capacity `1/kh` infinite): the head's row is exactly zero and every
/// other row is the fixed-wall model's, at random states with the head at `Th`.
#[test]
fn infinite_capacity_is_the_fixed_wall_exactly() {
    let n = 3;
    let (walls, fixed) = (
        HeadWall::new(n, Closure::Full).unwrap(),
        Fixed::new(n, Closure::Full).unwrap(),
    );
    let mut p = walls.default_params();
    set(&walls, &mut p, "kh", 0.0);
    let nf = fixed.n_states();
    let mut xf = vec![0.0; nf];
    fixed.equilibrium_guess(&p, &mut xf);
    for k in 0..5 {
        let mut x = xf.clone();
        x[0] = 1e-3 * k as f64;
        x[1] = 0.1 * (k as f64 - 2.0);
        x.push(600.0);
        let (mut fw, mut ff) = (vec![0.0; nf + 1], vec![0.0; nf]);
        walls.rhs(&p, &x, 0.0, &mut fw);
        fixed.rhs(&p, &x[..nf], 0.0, &mut ff);
        assert_eq!(fw[nf], 0.0, "the head's row at kh = 0");
        for (a, b) in fw.iter().zip(&ff) {
            assert!((a - b).abs() <= 1e-14 * b.abs(), "{a} vs {b}");
        }
    }
}

/// The poles of the head model (`C = 1/kh`) and the matrix model (`Cm`) against the fixed
/// model's as the capacity grows tenfold per step: the distance falls about tenfold.
#[test]
fn large_capacity_poles_converge_to_the_fixed_wall() {
    let n = 3;
    let fixed = Fixed::new(n, Closure::Full).unwrap();
    let reference = poles(&fixed, &fixed.default_params());
    let head = HeadWall::new(n, Closure::Full).unwrap();
    let matrix = MatrixWall::new(n, Closure::Full).unwrap();
    let cases: [(&dyn Model, &str, [f64; 4]); 2] = [
        (&head, "kh", [4e-3, 4e-4, 4e-5, 4e-6]),
        (&matrix, "Cm", [25.0, 250.0, 2500.0, 25000.0]),
    ];
    for (m, name, values) in cases {
        let mut d = Vec::new();
        for v in values {
            let mut p = m.default_params();
            set(m, &mut p, name, v);
            d.push(distance(&poles(m, &p), &reference));
        }
        let d_text: Vec<String> = d.iter().map(|v| format!("{v:.3e}")).collect();
        eprintln!(
            "{}: relative pole distance to the fixed wall at {name} = {values:?}: {d_text:?}",
            m.name()
        );
        for k in 1..d.len() {
            assert!(d[k] < 0.2 * d[k - 1], "{}: {d:?}", m.name());
        }
        assert!(d[3] < 1e-4, "{}: {d:?}", m.name());
    }
}

/// A matrix of small capacity (time constant `Cm / (hr Awr)`, 2.7e-4 s and 2.7e-5 s against a
/// 74 ms cycle) follows its gas: along a start-up, `max |Tw_j - T_j|` relative to the gas's
/// temperature swing falls tenfold with the capacity, to below 1 %.
#[test]
fn small_capacity_wall_follows_the_gas() {
    let n = 2;
    let m = MatrixWall::new(n, Closure::Full).unwrap();
    let names = m.vessel_names();
    let gas: Vec<usize> = (0..n)
        .map(|j| names.iter().position(|s| *s == format!("r[{j}]")).unwrap())
        .collect();
    let states = m.states();
    let walls: Vec<usize> = (0..states.len())
        .filter(|&i| matches!(states[i].kind, StateKind::WallTemperature(_)))
        .collect();
    let mut ratios = Vec::new();
    for cm in [1e-3, 1e-4] {
        let mut p = m.default_params();
        set(&m, &mut p, "Cm", cm);
        set(&m, &mut p, "Gm", 1e-6);
        let mut x0 = vec![0.0; m.n_states()];
        m.equilibrium_guess(&p, &mut x0);
        let mut t0 = vec![0.0; names.len()];
        m.temperatures(&p, &x0, &mut t0);
        x0[0] = 5e-3;
        x0[3] = -0.2;
        let tr = sim::simulate(
            &m,
            &p,
            &x0,
            0.1,
            &sim::uniform_samples(0.1, 400),
            &SimOptions::default(),
        )
        .unwrap();
        let (mut lag, mut swing) = (0.0f64, 0.0f64);
        for x in &tr.x {
            let mut t = vec![0.0; names.len()];
            m.temperatures(&p, x, &mut t);
            for j in 0..n {
                lag = lag.max((x[walls[j]] - t[gas[j]]).abs());
                swing = swing.max((t[gas[j]] - t0[gas[j]]).abs());
            }
        }
        eprintln!("Cm = {cm:e} J/K: max |Tw - T| = {lag:.3e} K, gas swing {swing:.3e} K");
        ratios.push(lag / swing);
    }
    assert!(
        ratios[1] < 0.2 * ratios[0] && ratios[1] < 0.01,
        "{ratios:?}"
    );
}
