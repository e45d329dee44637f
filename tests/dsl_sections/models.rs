#![allow(dead_code)]
//! Test topologies with per-section links: every regenerator section leaks into one bounce
//! space (given pressure) or one closed bounce CV; and orifice leaks.

use stirling::stirling_model;

stirling_model! {
    /// The engine frame of `tests/dsl_walls/models.rs` without its bounce space: the family's
    /// default engine, the leak and wall parameters, the cold CV and the regenerator links;
    /// each model declares its bounce (space or CV), the hot CV and the chain `r[n]`.
    base leak_engine extends stirling::models::default_engine {
        remove space bounce;
        params {
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
        cv cold {
            volume: Vc0,
            faces { displacer: A - Ar, piston: -(A - Ar) },
            port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
        }
        link hot -> r[0] { resistance: Rf / (2.0 * n) }
        link r[j] -> r[j + 1] for j in 0..n - 1 { resistance: Rf / n }
        link r[n - 1] -> cold { resistance: Rf / (2.0 * n) }
    }
}

stirling_model! {
    /// Every section leaks into the bounce space held at `Pb`, `mdot_j = Gl/n (P_j - Pb)`.
    pub model LeakToSpace extends leak_engine {
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

stirling_model! {
    /// Every section leaks into a closed bounce CV through `Rl n`.
    pub model LeakToCv extends leak_engine {
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

stirling_model! {
    /// The cold space leaks into the bounce space held at `Pb` through an orifice,
    /// `mdot = Co dP / (dP^2 + dP0^2)^(1/4)`.
    pub model OrificeToSpace extends leak_engine {
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

stirling_model! {
    /// Every section leaks into a closed bounce CV through its own orifice (`Co / n` each).
    pub model OrificeToCv extends leak_engine {
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
