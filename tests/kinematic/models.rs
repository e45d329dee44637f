//! The kinematic base and the gamma LTD engine of `examples/engines/bases/kinematic.stirling` and
//! `gamma_ltd.stirling`, declared with the macro (the same text: `tests/kinematic_dsl.rs`
//! checks that it has not drifted from the files, and that the two are one model).
#![allow(dead_code)]

use stirling::stirling_model;

stirling_model! {
    /// A flywheel driving a displacer crank `x = s_d(theta)` and a power-piston crank
    /// `y = s_p(theta)`, 90 degrees apart; no gas spaces.
    base kinematic_engine {
        params {
            /// specific gas constant (air)
            R: 287.05 "J/(kg K)",
            /// heat-capacity ratio (air)
            gamma: 1.4 "-",
            /// hot-plate temperature (hot water, 80 C)
            Th: 353.15 "K",
            /// cold-plate temperature (room air, 22 C)
            Tk: 295.15 "K",
            /// charge pressure: the gas at rest (theta = 0) is at this pressure
            Pmean: 101325.0 "Pa",
            /// pressure behind the power piston (the room)
            Pb: 101325.0 "Pa",
            /// smoothing scale of the upwind switch
            mdot_eps: 1.0e-7 "kg/s",
            /// flywheel inertia (flywheel, crank and linkage together)
            J: 1.5e-4 "kg m^2",
            /// viscous friction of the flywheel's bearings and linkage
            cf: 5.0e-6 "N m s",
            /// Coulomb (dry) friction torque of the bearings
            Tc: 3.0e-5 "N m",
            /// angular velocity over which the Coulomb torque and the load change sign
            w_eps: 0.5 "rad/s",
            /// load torque (a brake: `Tl tanh(omega / w_eps)`; 0 runs free)
            Tl: 0.0 "N m",
            /// displacer crank radius (half the displacer stroke)
            rd: 0.004 "m",
            /// displacer connecting rod
            Ld: 0.05 "m",
            /// power-piston crank radius (half its stroke)
            rp: 0.007 "m",
            /// power-piston connecting rod
            Lp: 0.05 "m",
            /// phase of the power-piston crank behind the displacer's (-pi/2: the piston lags
            /// by 90 degrees, the engine turns with theta increasing)
            phi: -pi / 2.0 "rad",
        }
        gas { R: R, gamma: gamma, charge: Pmean, mdot_eps: mdot_eps }
        flywheel wheel(theta, omega) {
            inertia: J,
            damper: cf,
            friction: Tc,
            omega_eps: w_eps,
            load: Tl * tanh(omega / w_eps),
        }
        // x = rd cos(theta) + sqrt(Ld^2 - rd^2 sin^2 theta) - Ld: +rd (towards the hot plate) at theta = 0
        crank displacer(x) on wheel { radius: rd, rod: Ld, phase: 0.0 }
        crank piston(y) on wheel { radius: rp, rod: Lp, phase: phi }
        free cf, Tc;
    }
}

stirling_model! {
    /// Gamma-type LTD engine: hot space under the foam displacer, cold space above it joined to
    /// the small power cylinder, the displacer's gap (the regenerator) between them; a flywheel.
    pub model GammaLtd extends kinematic_engine {
        name "gamma_ltd";
        params {
            /// displacer-chamber area (90 mm bore)
            Ad: pi / 4.0 * 0.09 * 0.09 "m^2",
            /// displacer-chamber bore
            Dd: 0.09 "m",
            /// power-piston area (12 mm bore)
            Ap: pi / 4.0 * 0.012 * 0.012 "m^2",
            /// power-piston bore
            Dp: 0.012 "m",
            /// clearance between the displacer and a plate at the end of its stroke
            ch: 0.0015 "m",
            /// dead volume of the power cylinder at mid-stroke (piston swept half plus clearance)
            Vpd: 1.2e-6 "m^3",
            /// film coefficient at the plates
            hp: 40.0 "W/(m^2 K)",
            /// film coefficient at the chamber's side wall and in the power cylinder
            hs: 10.0 "W/(m^2 K)",
            /// flow resistance of the displacer's annular gap and foam (the regenerator)
            Rf: 1.0e4 "Pa s/kg",
            /// leak past the power piston to the room (a loose piston: it lets the mean pressure
            /// settle at the room's in a few seconds while the cycle's swing passes)
            Gleak: 4.0e-10 "kg/(s Pa)",
        }
        // the hot space: between the hot plate and the displacer, `ch + rd - x` high
        cv hot {
            volume: Ad * (ch + rd),
            faces { displacer: -Ad },
            port plate { h: hp, area: Ad, wall: Th },
            // the chamber's plastic ring, its mean temperature; its exposed area follows x
            port side { h: hs, area: pi * Dd * (ch + rd - x), wall: (Th + Tk) / 2.0 },
        }
        // the cold space above the displacer, and the power cylinder under its piston
        cv cold {
            volume: Ad * (ch + rd) + Vpd,
            faces { displacer: Ad, piston: -Ap },
            port plate { h: hp, area: Ad, wall: Tk },
            port side { h: hs, area: pi * Dd * (ch + rd + x), wall: (Th + Tk) / 2.0 },
            port cylinder { h: hs, area: pi * Dp * (Vpd / Ap - y), wall: Tk },
        }
        link hot -> cold { resistance: Rf }
        // the room pushes on the power piston's outer face, and takes the leak (its volume, 1 L
        // of the room near the engine, is a nominal one: the pressure is given)
        space room { pressure: Pb, volume: 1.0e-3, temperature: Tk, faces { piston: Ap } }
        link cold -> room { conductance: Gleak }
        sensor p: P_cold "Pa";
        // what the diagnosis may find that the model leaves out (`stirling diagnose`, each at its
        // null here: docs/diagnosis.md, "Kinematic engines"): a second seal leak from the cold
        // space to the room (the displacer rod's bushing in the top plate), the foam's and the
        // gap's quadratic flow friction, and the pressure transducer's lag
        effect leak cold -> room;
        effect quadratic on link hot -> cold;
        effect lag on sensor p;
    }
}
