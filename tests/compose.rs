//! Composition (docs/custom-topologies.md, "Composition"): a model that extends a base
//! (`extends`, with added, replaced, removed and modified items) is the same model as its
//! hand-written equivalent declaration: the same states in the same order, the same rows of
//! the right-hand side, the Jacobian and the parameter Jacobian (columns matched by parameter
//! name) to round-off, at n = 1, 2, 10 and seeded random states and parameters; and an
//! extended model's Jacobians match central finite differences like any model's.
//!
//! The hand-written declarations below copy the default engine on purpose: they are the
//! reference the extended models are compared with.

mod common;
#[path = "../examples/custom_topology.rs"]
#[allow(dead_code)]
mod ex;

use stirling::dsl::{Closure, Model};
use stirling::stirling_model;

stirling_model! {
    /// `nsection` with a closed bounce space that replaces the fixed-pressure one in place.
    pub model ClosedBounce extends stirling::models::nsection_engine {
        params {
            /// bounce-space volume at rest
            Vb0: 2.0e-3 "m^3",
            /// bounce-space wall temperature
            Tb: 300.0 "K",
            /// bounce-space wall area
            Awb: 0.06 "m^2",
            /// bounce-space heat-transfer coefficient
            hb: 20.0 "W/(m^2 K)",
        }
        remove param Pb;
        replace cv bounce {
            volume: Vb0,
            faces { displacer: Ar, piston: A - Ar },
            port wall { h: hb, area: Awb, wall: Tb },
        }
    }
}

stirling_model! {
    /// [`ClosedBounce`] written in full: the bounce CV where the space was.
    pub model HandClosedBounce {
        params {
                /// specific gas constant
                R: 287.05 "J/(kg K)",
                /// heat-capacity ratio
                gamma: 1.4 "-",
                /// cylinder and displacer area
                A: pi / 4.0 * 0.06 * 0.06 "m^2",
                /// displacer rod area
                Ar: pi / 4.0 * 0.015 * 0.015 "m^2",
                /// hot-space volume at rest
                Vh0: 1.5e-4 "m^3",
                /// cold-space volume at rest
                Vc0: 1.2e-4 "m^3",
                /// regenerator volume
                Vr: 4.0e-5 "m^3",
                /// heater wall temperature
                Th: 600.0 "K",
                /// cooler wall temperature
                Tk: 300.0 "K",
                /// charge (mean) pressure
                Pmean: 101325.0 "Pa",
                /// displacer moving mass
                md: 0.08228 "kg",
                /// power-piston moving mass
                mp: 0.33363 "kg",
                /// displacer spring rate
                kd: 650.74 "N/m",
                /// power-piston spring rate
                kp: 61.482 "N/m",
                /// displacer viscous damping
                bd: 0.48643 "N s/m",
                /// power-piston viscous damping (load)
                bp: 7.9083 "N s/m",
                /// displacer-piston coupling damping
                b: 0.1 "N s/m",
                /// displacer quadratic damping
                bqd: 0.5 "N s^2/m^2",
                /// power-piston quadratic damping
                bqp: 5.0 "N s^2/m^2",
                /// hot-space wall area at rest
                Awh0: 0.0128 "m^2",
                /// cold-space wall area at rest
                Awc0: 0.0112 "m^2",
                /// regenerator wall area
                Awr: 0.0377 "m^2",
                /// heater heat-transfer coefficient
                hh: 500.0 "W/(m^2 K)",
                /// cooler heat-transfer coefficient
                hk: 500.0 "W/(m^2 K)",
                /// regenerator heat-transfer coefficient
                hr: 100.0 "W/(m^2 K)",
                /// regenerator flow resistance
                Rf: 1.0e5 "Pa s/kg",
                /// smoothing scale of the upwind switch
                mdot_eps: 1.0e-5 "kg/s",
            Vb0: 2.0e-3 "m^3",
            Tb: 300.0 "K",
            Awb: 0.06 "m^2",
            hb: 20.0 "W/(m^2 K)",
        }
        let D = sqrt(4.0 * A / pi);
        gas { R: R, gamma: gamma, charge: Pmean, mdot_eps: mdot_eps }
        body displacer(x, v) { mass: md, spring: kd, damper: bd, quad_damper: bqd }
        body piston(y, w) { mass: mp, spring: kp, damper: bp, quad_damper: bqp }
        coupling displacer, piston { damper: b }
        cv bounce {
            volume: Vb0,
            faces { displacer: Ar, piston: A - Ar },
            port wall { h: hb, area: Awb, wall: Tb },
        }
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv regen[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        cv cold {
            volume: Vc0,
            faces { displacer: A - Ar, piston: -(A - Ar) },
            port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
        }
        link hot -> regen[0] { resistance: Rf / (2.0 * n) }
        link regen[j] -> regen[j + 1] for j in 0..n - 1 { resistance: Rf / n }
        link regen[n - 1] -> cold { resistance: Rf / (2.0 * n) }
    }
}

stirling_model! {
    /// Every kind of change at once: parameters added and a default replaced, a `let`
    /// replaced, fields of a body, a space, a CV port and a link modified, a link removed and
    /// added again with another law, a leak added.
    pub model Variant extends stirling::models::nsection_engine {
        name "variant";
        params {
            /// quadratic regenerator friction
            Rq: 1.0e7 "Pa s^2/kg^2",
            /// seal leak, cold space to bounce space
            Gleak: 1.0e-9 "kg/(s Pa)",
        }
        replace params { kd: 700.0 "N/m" }
        replace let D = 1.01 * sqrt(4.0 * A / pi);
        modify body displacer { spring: 1.1 * kd, force: -0.01 * v }
        modify space bounce { temperature: Tk, faces { piston: A - 1.1 * Ar } }
        modify cv cold { port cold { h: 1.2 * hk, area: Awc0 + pi * D * (x - y), wall: Tk } }
        modify link regen[j] -> regen[j + 1] { quadratic: Rq / n }
        remove link regen[n - 1] -> cold;
        link regen[n - 1] -> cold { resistance: Rf / (2.0 * n), quadratic: Rq / (2.0 * n) }
        link cold -> bounce { conductance: Gleak }
    }
}

stirling_model! {
    /// [`Variant`] written in full.
    pub model HandVariant {
        name "variant";
        params {
                /// specific gas constant
                R: 287.05 "J/(kg K)",
                /// heat-capacity ratio
                gamma: 1.4 "-",
                /// cylinder and displacer area
                A: pi / 4.0 * 0.06 * 0.06 "m^2",
                /// displacer rod area
                Ar: pi / 4.0 * 0.015 * 0.015 "m^2",
                /// hot-space volume at rest
                Vh0: 1.5e-4 "m^3",
                /// cold-space volume at rest
                Vc0: 1.2e-4 "m^3",
                /// regenerator volume
                Vr: 4.0e-5 "m^3",
                /// heater wall temperature
                Th: 600.0 "K",
                /// cooler wall temperature
                Tk: 300.0 "K",
                /// charge (mean) pressure
                Pmean: 101325.0 "Pa",
                /// bounce-space pressure
                Pb: 101325.0 "Pa",
                /// displacer moving mass
                md: 0.08228 "kg",
                /// power-piston moving mass
                mp: 0.33363 "kg",
                /// displacer spring rate
                kd: 700.0 "N/m",
                /// power-piston spring rate
                kp: 61.482 "N/m",
                /// displacer viscous damping
                bd: 0.48643 "N s/m",
                /// power-piston viscous damping (load)
                bp: 7.9083 "N s/m",
                /// displacer-piston coupling damping
                b: 0.1 "N s/m",
                /// displacer quadratic damping
                bqd: 0.5 "N s^2/m^2",
                /// power-piston quadratic damping
                bqp: 5.0 "N s^2/m^2",
                /// hot-space wall area at rest
                Awh0: 0.0128 "m^2",
                /// cold-space wall area at rest
                Awc0: 0.0112 "m^2",
                /// regenerator wall area
                Awr: 0.0377 "m^2",
                /// heater heat-transfer coefficient
                hh: 500.0 "W/(m^2 K)",
                /// cooler heat-transfer coefficient
                hk: 500.0 "W/(m^2 K)",
                /// regenerator heat-transfer coefficient
                hr: 100.0 "W/(m^2 K)",
                /// regenerator flow resistance
                Rf: 1.0e5 "Pa s/kg",
                /// smoothing scale of the upwind switch
                mdot_eps: 1.0e-5 "kg/s",
            Rq: 1.0e7 "Pa s^2/kg^2",
            Gleak: 1.0e-9 "kg/(s Pa)",
        }
        let D = 1.01 * sqrt(4.0 * A / pi);
        gas { R: R, gamma: gamma, charge: Pmean, mdot_eps: mdot_eps }
        body displacer(x, v) { mass: md, spring: 1.1 * kd, damper: bd, quad_damper: bqd, force: -0.01 * v }
        body piston(y, w) { mass: mp, spring: kp, damper: bp, quad_damper: bqp }
        coupling displacer, piston { damper: b }
        space bounce { pressure: Pb, faces { displacer: Ar, piston: A - 1.1 * Ar }, temperature: Tk }
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv regen[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        cv cold {
            volume: Vc0,
            faces { displacer: A - Ar, piston: -(A - Ar) },
            port cold { h: 1.2 * hk, area: Awc0 + pi * D * (x - y), wall: Tk },
        }
        link hot -> regen[0] { resistance: Rf / (2.0 * n) }
        link regen[j] -> regen[j + 1] for j in 0..n - 1 { resistance: Rf / n, quadratic: Rq / n }
        link regen[n - 1] -> cold { resistance: Rf / (2.0 * n), quadratic: Rq / (2.0 * n) }
        link cold -> bounce { conductance: Gleak }
    }
}

stirling_model! {
    /// `examples/custom_topology.rs`'s engine as it was declared before composition: in full.
    pub model HandAlternator {
        name "hand_alternator";
        params {
            /// specific gas constant
            R: 287.05 "J/(kg K)",
            /// heat-capacity ratio
            gamma: 1.4 "-",
            /// cylinder and displacer area
            A: pi / 4.0 * 0.06 * 0.06 "m^2",
            /// displacer rod area
            Ar: pi / 4.0 * 0.015 * 0.015 "m^2",
            /// hot-space volume at rest
            Vh0: 1.5e-4 "m^3",
            /// cold-space volume at rest
            Vc0: 1.2e-4 "m^3",
            /// regenerator volume
            Vr: 4.0e-5 "m^3",
            /// bounce-space volume at rest (closed crankcase)
            Vb0: 2.0e-3 "m^3",
            /// heater wall temperature
            Th: 600.0 "K",
            /// cooler wall temperature
            Tk: 300.0 "K",
            /// bounce-space wall temperature
            Tb: 300.0 "K",
            /// charge pressure (working and bounce gas at rest)
            Pmean: 101325.0 "Pa",
            /// displacer moving mass
            md: 0.08228 "kg",
            /// power-piston moving mass (with the alternator's mover)
            mp: 0.33363 "kg",
            /// displacer spring rate
            kd: 650.74 "N/m",
            /// power-piston spring rate
            kp: 61.482 "N/m",
            /// displacer viscous damping
            bd: 0.48643 "N s/m",
            /// power-piston friction
            bp: 1.9083 "N s/m",
            /// alternator load: force -c_alt w on the piston, electric power c_alt w^2
            c_alt: 6.0 "N s/m",
            /// alternator's motor constant: its voltage is Kv w (c_alt = Kv^2 / R_load)
            Kv: 25.0 "V s/m",
            /// displacer-piston coupling damping
            b: 0.1 "N s/m",
            /// displacer quadratic damping
            bqd: 0.5 "N s^2/m^2",
            /// power-piston quadratic damping
            bqp: 5.0 "N s^2/m^2",
            /// hot-space wall area at rest
            Awh0: 0.0128 "m^2",
            /// cold-space wall area at rest
            Awc0: 0.0112 "m^2",
            /// regenerator wall area
            Awr: 0.0377 "m^2",
            /// bounce-space wall area
            Awb: 0.06 "m^2",
            /// heater heat-transfer coefficient
            hh: 500.0 "W/(m^2 K)",
            /// cooler heat-transfer coefficient
            hk: 500.0 "W/(m^2 K)",
            /// regenerator heat-transfer coefficient
            hr: 100.0 "W/(m^2 K)",
            /// bounce-space heat-transfer coefficient
            hb: 20.0 "W/(m^2 K)",
            /// regenerator flow resistance
            Rf: 1.0e5 "Pa s/kg",
            /// smoothing scale of the upwind switch
            mdot_eps: 1.0e-5 "kg/s",
        }
        // cylinder diameter
        let D = sqrt(4.0 * A / pi);
        gas { R: R, gamma: gamma, charge: Pmean, mdot_eps: mdot_eps }
        body displacer(x, v) { mass: md, spring: kd, damper: bd, quad_damper: bqd }
        body piston(y, w) { mass: mp, spring: kp, damper: bp, quad_damper: bqp, force: -c_alt * w }
        coupling displacer, piston { damper: b }
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv regen[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        cv cold {
            volume: Vc0,
            faces { displacer: A - Ar, piston: -(A - Ar) },
            port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
        }
        // the closed bounce space: same faces as the seed's fixed-pressure space, but a gas
        // volume of its own (no mass-flow link, so its mass is a constant)
        cv bounce {
            volume: Vb0,
            faces { displacer: Ar, piston: A - Ar },
            port wall { h: hb, area: Awb, wall: Tb },
        }
        link hot -> regen[0] { resistance: Rf / (2.0 * n) }
        link regen[j] -> regen[j + 1] for j in 0..n - 1 { resistance: Rf / n }
        link regen[n - 1] -> cold { resistance: Rf / (2.0 * n) }
    }
}

const ROUND_OFF: f64 = 1e-12;

#[test]
fn replace_in_place_is_the_hand_written_model() {
    for n in [1, 2, 10] {
        for closure in [Closure::Full, Closure::Frozen] {
            let e = ClosedBounce::new(n, closure).unwrap();
            let h = HandClosedBounce::new(n, closure).unwrap();
            let names = e.state_names();
            // the bounce CV keeps the space's place: first of the pressures
            assert_eq!(names[4], "P_bounce", "{names:?}");
            let w = common::same::same_model(&e, &h, 11 + n as u64);
            println!("closed bounce, n = {n} ({closure}): worst scaled difference {w:.2e}");
            assert!(w <= ROUND_OFF, "n = {n} ({closure}): {w:.2e}");
        }
    }
}

#[test]
fn every_kind_of_change_is_the_hand_written_model() {
    for n in [1, 2, 10] {
        for closure in [Closure::Full, Closure::Frozen] {
            let e = Variant::new(n, closure).unwrap();
            let h = HandVariant::new(n, closure).unwrap();
            let w = common::same::same_model(&e, &h, 21 + n as u64);
            println!("variant, n = {n} ({closure}): worst scaled difference {w:.2e}");
            assert!(w <= ROUND_OFF, "n = {n} ({closure}): {w:.2e}");
        }
    }
}

/// The example's engine (`examples/custom_topology.rs`, extending `nsection_engine`) is the
/// full declaration it replaced; its parameters come in another order, matched by name.
#[test]
fn the_example_engine_is_its_former_full_declaration() {
    for n in [1, 2, 10] {
        let e = ex::AlternatorEngine::new(n, Closure::Full).unwrap();
        let h = HandAlternator::new(n, Closure::Full).unwrap();
        let w = common::same::same_model(&e, &h, 31 + n as u64);
        println!("alternator engine, n = {n}: worst scaled difference {w:.2e}");
        assert!(w <= ROUND_OFF, "n = {n}: {w:.2e}");
    }
}

/// The chained base: `nsection` (`nsection_engine` extends `default_engine`) is unchanged.
#[test]
fn the_family_nsection_extends_twice() {
    let m = stirling::models::family::NSection::new(3, Closure::Full).unwrap();
    assert_eq!(m.name(), "nsection");
    assert_eq!(m.n_states(), 2 * 3 + 8);
    assert!(m.param_index("Pb").is_some() && m.param_index("b").is_some());
}

#[test]
fn an_extended_model_matches_finite_differences() {
    for n in [1, 2, 10] {
        for closure in [Closure::Full, Closure::Frozen] {
            let m = Variant::new(n, closure).unwrap();
            common::assert_jacobians(&m, &format!("variant n = {n} ({closure})"), 41, 4);
        }
    }
}
