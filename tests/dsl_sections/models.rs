#![allow(dead_code, unused_macros)]
//! Test topologies with per-section links: every regenerator section leaks into one bounce
//! space (given pressure) or one closed bounce CV; and orifice leaks.

use stirling::stirling_model;

/// The engine frame of `tests/dsl_walls/models.rs` without its bounce space.
macro_rules! leak_engine {
    ($(#[$meta:meta])* model $name:ident { $($body:tt)* }) => {
        stirling_model! {
            $(#[$meta])*
            pub model $name {
                params {
                    R: 287.05 "J/(kg K)",
                    gamma: 1.4 "-",
                    A: pi / 4.0 * 0.06 * 0.06 "m^2",
                    Ar: pi / 4.0 * 0.015 * 0.015 "m^2",
                    Vh0: 1.5e-4 "m^3",
                    Vc0: 1.2e-4 "m^3",
                    Vr: 4.0e-5 "m^3",
                    Th: 600.0 "K",
                    Tk: 300.0 "K",
                    Pmean: 101325.0 "Pa",
                    Pb: 101325.0 "Pa",
                    md: 0.08228 "kg",
                    mp: 0.33363 "kg",
                    kd: 650.74 "N/m",
                    kp: 61.482 "N/m",
                    bd: 0.48643 "N s/m",
                    bp: 7.9083 "N s/m",
                    bc: 0.1 "N s/m",
                    bqd: 0.5 "N s^2/m^2",
                    bqp: 5.0 "N s^2/m^2",
                    Awh0: 0.0128 "m^2",
                    Awc0: 0.0112 "m^2",
                    Awr: 0.0377 "m^2",
                    hh: 500.0 "W/(m^2 K)",
                    hk: 500.0 "W/(m^2 K)",
                    hr: 100.0 "W/(m^2 K)",
                    Rf: 1.0e5 "Pa s/kg",
                    mdot_eps: 1.0e-5 "kg/s",
                    /// inverse heat capacity of the heater head (0: the fixed head)
                    kh: 4.0e-3 "K/J",
                    /// conductance from the head to the cold end (the loss path at rest)
                    Gloss: 0.5 "W/K",
                    /// heat input into the head, Gloss (Th - Tk) by default
                    Qin: 150.0 "W",
                    /// heat capacity of the whole regenerator matrix
                    Cm: 25.0 "J/K",
                    /// axial conductance of the whole matrix
                    Gm: 0.03 "W/K",
                    /// leak conductance of the whole regenerator into the bounce space
                    Gl: 1.0e-8 "kg/(s Pa)",
                    /// leak resistance of the whole regenerator into a closed bounce space
                    Rl: 1.0e8 "Pa s/kg",
                    /// orifice coefficient of a leak, `mdot = Co sign(dP) sqrt|dP|` above `dP0`
                    Co: 1.0e-7 "kg/(s Pa^(1/2))",
                    /// width of the orifice's linear core
                    dP0: 100.0 "Pa",
                    Vb0: 2.0e-3 "m^3",
                    hb: 20.0 "W/(m^2 K)",
                    Awb: 0.06 "m^2",
                }
                let D = sqrt(4.0 * A / pi);
                gas { R: R, gamma: gamma, charge: Pmean, mdot_eps: mdot_eps }
                body displacer(x, v) { mass: md, spring: kd, damper: bd, quad_damper: bqd }
                body piston(y, w) { mass: mp, spring: kp, damper: bp, quad_damper: bqp }
                coupling displacer, piston { damper: bc }
                cv cold {
                    volume: Vc0,
                    faces { displacer: A - Ar, piston: -(A - Ar) },
                    port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
                }
                link hot -> r[0] { resistance: Rf / (2.0 * n) }
                link r[j] -> r[j + 1] for j in 0..n - 1 { resistance: Rf / n }
                link r[n - 1] -> cold { resistance: Rf / (2.0 * n) }
                $($body)*
            }
        }
    };
}

leak_engine! {
    /// Every section leaks into the bounce space held at `Pb`, `mdot_j = Gl/n (P_j - Pb)`.
    model LeakToSpace {
        space bounce { pressure: Pb, temperature: Tk, faces { displacer: Ar, piston: A - Ar } }
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        link r[j] -> bounce for j in 0..n { conductance: Gl / n }
    }
}

leak_engine! {
    /// Every section leaks into a closed bounce CV through `Rl n`.
    model LeakToCv {
        cv bounce {
            volume: Vb0,
            faces { displacer: Ar, piston: A - Ar },
            port wall { h: hb, area: Awb, wall: Tk },
        }
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        link r[j] -> bounce for j in 0..n { resistance: Rl * n }
    }
}

leak_engine! {
    /// The cold space leaks into the bounce space held at `Pb` through an orifice,
    /// `mdot = Co dP / (dP^2 + dP0^2)^(1/4)`.
    model OrificeToSpace {
        space bounce { pressure: Pb, temperature: Tk, faces { displacer: Ar, piston: A - Ar } }
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        link cold -> bounce { orifice: Co, dp0: dP0 }
    }
}

leak_engine! {
    /// Every section leaks into a closed bounce CV through its own orifice (`Co / n` each).
    model OrificeToCv {
        cv bounce {
            volume: Vb0,
            faces { displacer: Ar, piston: A - Ar },
            port wall { h: hb, area: Awb, wall: Tk },
        }
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        link r[j] -> bounce for j in 0..n { orifice: Co / n, dp0: dP0 }
    }
}
