//! A gamma-type engine declared from scratch (no `extends`): the displacer in its own
//! cylinder with a rod into a buffer space, the power piston in a second cylinder joined to
//! the cold space by a duct, heat-exchanger areas fixed (not swept by the displacer), and a
//! pressure sensor on the cold side. Measured by the rig with its own sensors and fitted:
//! the intervals cover the truth.

mod common;

use stirling::dsl::{Closure, Model};
use stirling::stirling_model;

stirling_model! {
    /// Gamma-type free-piston engine: displacer cylinder (hot space above, cold space below,
    /// a rod into the buffer), power cylinder on the cold side through a duct.
    pub model Gamma {
        name "gamma";
        params {
            /// specific gas constant
            R: 287.05 "J/(kg K)",
            /// heat-capacity ratio
            gamma: 1.4 "-",
            /// charge pressure
            Pmean: 101325.0 "Pa",
            /// buffer pressure (under the power piston and behind the rod)
            Pb: 101325.0 "Pa",
            /// smoothing scale of the upwind switch
            mdot_eps: 1.0e-5 "kg/s",
            /// displacer-cylinder area
            Ad: pi / 4.0 * 0.06 * 0.06 "m^2",
            /// displacer rod area
            Ar: pi / 4.0 * 0.015 * 0.015 "m^2",
            /// power-cylinder area
            Ap: pi / 4.0 * 0.055 * 0.055 "m^2",
            /// hot-space volume at rest
            Vh0: 1.5e-4 "m^3",
            /// cold-space volume at rest, duct included
            Vc0: 1.5e-4 "m^3",
            /// regenerator volume
            Vr: 4.0e-5 "m^3",
            /// heater wall temperature
            Th: 600.0 "K",
            /// cooler wall temperature
            Tk: 300.0 "K",
            /// displacer moving mass
            md: 0.08 "kg",
            /// power-piston moving mass
            mp: 0.35 "kg",
            /// displacer spring rate
            kd: 650.0 "N/m",
            /// power-piston spring rate
            kp: 60.0 "N/m",
            /// displacer damping
            bd: 0.5 "N s/m",
            /// power-piston damping (load)
            bp: 7.0 "N s/m",
            /// quadratic damping of the displacer and the piston (the cycle's amplitude)
            bqd: 0.5 "N s^2/m^2",
            bqp: 5.0 "N s^2/m^2",
            /// heater area and coefficient
            Awh: 0.0128 "m^2",
            hh: 500.0 "W/(m^2 K)",
            /// cooler area and coefficient
            Awc: 0.0140 "m^2",
            hk: 500.0 "W/(m^2 K)",
            /// regenerator wall area and coefficient
            Awr: 0.0377 "m^2",
            hr: 100.0 "W/(m^2 K)",
            /// regenerator flow resistance
            Rf: 1.0e5 "Pa s/kg",
        }
        gas { R: R, gamma: gamma, charge: Pmean, mdot_eps: mdot_eps }
        body displacer(x, v) { mass: md, spring: kd, damper: bd, quad_damper: bqd }
        body piston(y, w) { mass: mp, spring: kp, damper: bp, quad_damper: bqp }
        space buffer { pressure: Pb, faces { displacer: Ar, piston: Ap } }
        cv hot {
            volume: Vh0,
            faces { displacer: -Ad },
            port hot { h: hh, area: Awh, wall: Th },
        }
        cv regen[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        cv cold {
            volume: Vc0,
            faces { displacer: Ad - Ar, piston: -Ap },
            port cold { h: hk, area: Awc, wall: Tk },
        }
        link hot -> regen[0] { resistance: Rf / (2.0 * n) }
        link regen[j] -> regen[j + 1] for j in 0..n - 1 { resistance: Rf / n }
        link regen[n - 1] -> cold { resistance: Rf / (2.0 * n) }
        sensor x: x "m";
        sensor y: y "m";
        sensor p: P_cold "Pa";
        // what a fit identifies by default
        free kd, kp, bd, bp, hh, hk, Rf;
    }
}

#[test]
fn the_gamma_engine_runs() {
    use stirling::models::linear::{linearize, LinearOptions};
    let m = Gamma::new(2, Closure::Full).unwrap();
    let p = m.default_params();
    let lin = linearize(&m, &p, &LinearOptions::default()).unwrap();
    let unstable: Vec<_> = lin.dynamics.poles.iter().filter(|p| p.rhp).collect();
    assert_eq!(unstable.len(), 2, "{:?}", lin.dynamics.poles);
    // growth 4.5 1/s at 12.8 Hz with the defaults
    assert!(
        unstable[0].freq_hz > 5.0 && unstable[0].freq_hz < 30.0,
        "{:?}",
        unstable[0]
    );
}

/// Measured by the rig with its own sensors (`p` on the cold side, `x`, `y`: 3 s of start-up,
/// offsets on every channel) and fitted from a start 5-50 % off: every interval covers the
/// truth and the free run matches the held-out amplitudes.
#[test]
fn the_gamma_engine_is_fitted_from_its_own_sensors() {
    use stirling::models::fit::{self, FitOptions};
    use stirling::models::rig::{measure, RigConfig};
    let m = Gamma::new(2, Closure::Full).unwrap();
    let truth = m.default_params();
    let cfg = RigConfig {
        t_end: 3.0,
        x0: 5e-4,
        offset_p: 50.0,
        offset_x: 0.131,
        offset_y: 0.046,
        seed: 2,
        channels: ["p", "x", "y"].map(String::from).to_vec(),
        ..Default::default()
    };
    let rec = measure(&m, &truth, &cfg).expect("measured");
    let mut p0 = truth.clone();
    for (k, v) in [
        ("kd", 683.0),
        ("hh", 650.0),
        ("hk", 650.0),
        ("bp", 9.0),
        ("Rf", 1.5e5),
    ] {
        p0[m.param_index(k).unwrap()] = v;
    }
    // the free parameters come from the declaration (`free ..;`), no option needed
    let free = m.declared_free();
    assert_eq!(free, ["kd", "kp", "bd", "bp", "hh", "hk", "Rf"]);
    let id = fit::identify(&m, &p0, &rec, &FitOptions::default()).expect("fitted");
    let truth_of = |k: &'static str| (k, truth[m.param_index(k).unwrap()]);
    common::fit::assert_recovered(&id, free.iter().map(|&k| truth_of(k)), 0.5);
    common::fit::assert_free_run_amplitudes(&id, &["x", "y", "p"], 0.05);
}

/// The gamma engine's bond graph (docs/bond-graphs.md): one stroke per bond, consistent
/// junctions, integral causality on every storage element, and its states one to one with
/// the model's, at 1, 2 and 10 regenerator sections.
#[test]
fn the_gamma_engine_has_an_integral_bond_graph_with_the_models_states() {
    for closure in [Closure::Full, Closure::Frozen] {
        for n in [1, 2, 10] {
            common::bond::check(&Gamma::new(n, closure).unwrap());
        }
    }
}
