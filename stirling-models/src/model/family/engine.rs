//! The default engine (docs/physics.md section 8), declared once: parameters, the two bodies,
//! their coupling damper and the bounce space. It is the base `default_engine` (exported:
//! `stirling::models::default_engine`); each family member extends it with its gas spaces
//! and links (`model Cv1 extends default_engine { .. }`), the effect models and the
//! examples and tests extend it too (docs/custom-topologies.md, "Composition").

stirling_macros::stirling_model! {
    /// The default engine (docs/physics.md section 8): parameters, displacer and power piston,
    /// their coupling damper, the bounce space at the given pressure `Pb`; no gas spaces.
    /// Extend it: `stirling_model! { pub model Mine extends stirling::models::default_engine { .. } }`.
    pub base default_engine {
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
        }
        // cylinder diameter
        let D = sqrt(4.0 * A / pi);
        gas { R: R, gamma: gamma, charge: Pmean, mdot_eps: mdot_eps }
        body displacer(x, v) { mass: md, spring: kd, damper: bd, quad_damper: bqd }
        body piston(y, w) { mass: mp, spring: kp, damper: bp, quad_damper: bqp }
        coupling displacer, piston { damper: b }
        space bounce { pressure: Pb, faces { displacer: Ar, piston: A - Ar } }
        // the parameters the seed identifies: a fit frees these by default (those that enter
        // a member's equations: `cv1` has no `Rf`)
        free kd, kp, bd, bp, hh, hk, Rf;
        // the seed's position sensors (a member adds its pressure sensors)
        sensor x: x "m";
        sensor y: y "m";
    }
}
