//! Every family member on the default engine: the right-half-plane pair near 85 rad/s with the
//! `full` closure, stable `frozen` models, the inventory mode, and the loop broken at the piston
//! and displacer forces (reference numbers: the independent Python check of docs/physics.md).

use stirling::dsl::{Closure, Model};
use stirling::models::linear::{
    self, equilibrium, LinearError, LinearOptions, Linearization, NewtonOptions,
};

fn run(
    name: &str,
    n: Option<usize>,
    closure: Closure,
    channel: Option<&str>,
) -> (Box<dyn Model>, Linearization) {
    let model = stirling::models::build(name, n, closure).unwrap();
    let p = model.default_params();
    let opts = LinearOptions {
        channel: channel.map(str::to_string),
        ..Default::default()
    };
    let lin = linear::linearize(model.as_ref(), &p, &opts).unwrap();
    (model, lin)
}

/// The complex poles (|im| > 1) with positive imaginary part, least stable first.
fn pairs(lin: &Linearization) -> Vec<(f64, f64)> {
    lin.dynamics
        .poles
        .iter()
        .filter(|p| p.im > 1.0)
        .map(|p| (p.re, p.im))
        .collect()
}

#[test]
fn every_full_member_has_its_rhp_pair() {
    let cases: [(&str, Option<usize>, [(f64, f64); 2], usize); 6] = [
        ("schmidt", None, [(9.6225, 89.5373), (-25.1879, 94.1366)], 4),
        ("cv1", None, [(1.5830, 84.8661), (-21.4817, 100.4632)], 5),
        ("cv2", None, [(1.1766, 83.8981), (-22.0659, 102.5202)], 8),
        (
            "nsection",
            Some(1),
            [(2.7700, 85.1573), (-23.5023, 103.7036)],
            10,
        ),
        (
            "nsection",
            Some(2),
            [(3.6258, 85.7538), (-24.2287, 104.4476)],
            12,
        ),
        (
            "nsection",
            Some(3),
            [(3.9407, 85.9654), (-24.4882, 104.7562)],
            14,
        ),
    ];
    for (name, n, want, states) in cases {
        let (model, lin) = run(name, n, Closure::Full, None);
        assert_eq!(model.n_states(), states, "{name} {n:?}");
        let got = pairs(&lin);
        assert_eq!(got.len(), 2, "{name} {n:?}: {got:?}");
        for (g, w) in got.iter().zip(want) {
            assert!(
                (g.0 - w.0).abs() < 1e-3 && (g.1 - w.1).abs() < 1e-3,
                "{name} {n:?}: {g:?} vs {w:?}"
            );
        }
        let rhp: Vec<_> = lin.dynamics.poles.iter().filter(|p| p.rhp).collect();
        assert_eq!(rhp.len(), 2, "{name} {n:?}: exactly one RHP pair");
        assert!(rhp[0].freq_rad_s > 83.0 && rhp[0].freq_rad_s < 90.0);
    }
}

#[test]
fn nsection_10_full_and_its_stiff_poles() {
    let (_, lin) = run("nsection", Some(10), Closure::Full, None);
    let got = pairs(&lin);
    assert_eq!(got.len(), 2, "{got:?}");
    assert!(
        (got[0].0 - 4.3654).abs() < 1e-3 && (got[0].1 - 86.2531).abs() < 1e-3,
        "{got:?}"
    );
    assert!(
        (got[1].0 + 24.8145).abs() < 1e-3 && (got[1].1 - 105.1827).abs() < 1e-3,
        "{got:?}"
    );
    assert_eq!(lin.dynamics.poles.len(), 27);
    let stiffest = lin.dynamics.poles.last().unwrap();
    assert!((stiffest.re / -2.209e7 - 1.0).abs() < 1e-3, "{stiffest:?}");
}

#[test]
fn frozen_members_are_stable() {
    for (name, n, want) in [
        ("cv2", None, (-7.0106, 99.5797)),
        ("nsection", Some(2), (-7.0033, 98.9103)),
    ] {
        let (_, lin) = run(name, n, Closure::Frozen, None);
        assert!(lin.dynamics.poles.iter().all(|p| !p.rhp), "{name}");
        let g = pairs(&lin)[0];
        assert!(
            (g.0 - want.0).abs() < 1e-3 && (g.1 - want.1).abs() < 1e-3,
            "{name}: {g:?}"
        );
        assert!(lin.dynamics.reduction.inventory.is_none());
    }
}

#[test]
fn the_inventory_mode_is_reported_and_removed() {
    let (model, lin) = run("nsection", Some(2), Closure::Full, None);
    let inv = lin.dynamics.reduction.inventory.as_ref().unwrap();
    assert_eq!(inv.mass_states, vec![8, 9, 10, 11]);
    assert!(
        inv.conservation_defect < 1e-14 && inv.eigenvalue.abs() < 1e-6,
        "{inv:?}"
    );
    // J r = 0 with c r = 1: adding charge raises every pressure.
    let j = &lin.dynamics.jacobian;
    let r = linear::nalgebra::DVector::from_vec(inv.direction.clone());
    assert!((j * &r).amax() < 1e-6 * j.amax() * r.amax());
    assert!(
        inv.direction[4..8].iter().all(|&dp| dp > 0.0),
        "{:?}",
        inv.direction
    );
    // eig J = eig(T'JT) + {0}: 12 states, 11 dynamic poles.
    assert_eq!(lin.dynamics.poles.len(), model.n_states() - 1);
}

fn assert_margins(lin: &Linearization, gm: (f64, f64), pm: (f64, f64), what: &str) {
    let m = &lin.margins;
    assert!(
        (m.gain_db.unwrap() - gm.0).abs() < 0.01
            && (m.phase_crossover_rad_s.unwrap() - gm.1).abs() < 0.01,
        "{what}: {m:?}"
    );
    assert!(
        (m.phase_deg.unwrap() - pm.0).abs() < 0.05
            && (m.gain_crossover_rad_s.unwrap() - pm.1).abs() < 0.01,
        "{what}: {m:?}"
    );
}

#[test]
fn loops_broken_at_the_piston_and_displacer_forces() {
    let (_, lin) = run("cv1", None, Closure::Full, Some("piston"));
    assert_margins(&lin, (-3.011, 80.22), (-8.88, 84.92), "cv1 piston");
    assert!((lin.open_loop.at(0.0).re - 51.0485).abs() < 1e-3);
    let (_, lin) = run("cv1", None, Closure::Full, Some("displacer"));
    assert_margins(&lin, (-4.092, 85.94), (28.73, 83.16), "cv1 displacer");
    let (_, lin) = run("cv2", None, Closure::Full, None);
    assert_eq!(lin.open_loop.full.name, "piston");
    assert_margins(&lin, (1.626, 86.34), (-4.74, 83.62), "cv2 piston");
    let (_, lin) = run("nsection", Some(2), Closure::Full, None);
    assert_margins(&lin, (2.976, 89.40), (-16.84, 84.42), "nsection 2 piston");
    let all: Vec<_> = lin
        .margins
        .all_gain
        .iter()
        .map(|g| (g.gain_db, g.phase_crossover_rad_s))
        .collect();
    assert!(
        (all[0].0 + 7.549).abs() < 0.01 && (all[0].1 - 70.26).abs() < 0.01,
        "{all:?}"
    );
    assert!(lin.open_loop.poles.iter().all(|p| !p.rhp));
    let (_, lin) = run("nsection", Some(2), Closure::Full, Some("displacer"));
    assert_margins(
        &lin,
        (-9.187, 87.55),
        (62.55, 82.27),
        "nsection 2 displacer",
    );
    let (_, lin) = run("nsection", Some(2), Closure::Frozen, None);
    assert!(lin.margins.gain_db.is_none() && lin.margins.phase_crossover_rad_s.is_none());
    assert!(
        (lin.margins.phase_deg.unwrap() - 29.99).abs() < 0.05 && lin.margins.all_phase.len() == 3
    );
}

#[test]
fn malformed_requests_give_clear_errors() {
    let model = stirling::models::build("cv2", None, Closure::Full).unwrap();
    let p = model.default_params();
    let bad = |ch: &str| {
        linear::linearize(
            model.as_ref(),
            &p,
            &LinearOptions {
                channel: Some(ch.into()),
                ..Default::default()
            },
        )
        .unwrap_err()
    };
    let e = bad("pressure");
    assert!(matches!(e, LinearError::UnknownChannel { .. }), "{e}");
    assert!(
        e.to_string().contains("valid channels: displacer, piston"),
        "{e}"
    );
    assert!(bad("crank").to_string().contains("`crank` does not exist"));
    let e = linear::locus::locus(model.as_ref(), &p, "Tx", &[1.0], &NewtonOptions::default())
        .unwrap_err();
    assert!(e.to_string().contains("unknown parameter `Tx`"), "{e}");
    let e = stirling::models::build("nsection", Some(0), Closure::Full)
        .err()
        .unwrap();
    assert!(e.to_string().contains("at least 1"), "{e}");
    assert!(stirling::models::build("stirling9", None, Closure::Full).is_err());
}

#[test]
fn newton_recovers_the_equilibrium_and_keeps_the_charge() {
    let model = stirling::models::build("nsection", Some(2), Closure::Full).unwrap();
    let p = model.default_params();
    let mut x0 = vec![0.0; model.n_states()];
    model.equilibrium_guess(&p, &mut x0);
    let mut start = x0.clone();
    start[0] += 2e-4;
    start[2] -= 1e-4;
    for i in 4..8 {
        start[i] *= 1.0 + 1e-3 * i as f64;
    }
    let eq =
        equilibrium::solve_from(model.as_ref(), &p, &start, &NewtonOptions::default()).unwrap();
    assert!(eq.iterations > 0 && eq.scaled_residual < 1e-8, "{eq:?}");
    for (a, b) in eq.x.iter().zip(&x0) {
        assert!(
            (a - b).abs() <= 1e-7 * b.abs().max(1e-3),
            "{:?} vs {x0:?}",
            eq.x
        );
    }
    let e = equilibrium::solve_from(
        model.as_ref(),
        &p,
        &start,
        &NewtonOptions {
            max_iter: 0,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(e, LinearError::NoConvergence { iterations: 0, .. }),
        "{e}"
    );
    assert!(e.to_string().contains("did not converge"));
}
