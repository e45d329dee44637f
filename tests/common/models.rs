//! Small test topologies, one feature each, on the default engine's numbers: the two-CV and
//! chain models extend the family's `default_engine` (docs/physics.md section 8).

use stirling::stirling_model;

stirling_model! {
    /// One gas space on one piston with one heat port (mass constant), against a bounce space.
    pub model OneCv {
        params {
            R: 287.05 "J/(kg K)",
            gamma: 1.4 "-",
            P0: 101325.0 "Pa",
            m: 0.33363 "kg",
            k: 61.482 "N/m",
            c: 7.9083 "N s/m",
            cq: 5.0 "N s^2/m^2",
            A: 2.6e-3 "m^2",
            V0: 1.5e-4 "m^3",
            Tw: 450.0 "K",
            h: 500.0 "W/(m^2 K)",
            Aw0: 0.0128 "m^2",
            D: 0.06 "m",
            eps: 1.0e-5 "kg/s",
        }
        gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
        body piston(y, w) { mass: m, spring: k, damper: c, quad_damper: cq }
        space bounce { pressure: P0, faces { piston: A } }
        cv gas { volume: V0, faces { piston: -A }, port wall { h: h, area: Aw0 + pi * D * y, wall: Tw } }
    }
}

stirling_model! {
    /// Two CVs joined by one linear link.
    pub model TwoCv extends stirling::models::default_engine {
        cv hot {
            volume: Vh0 + Vr / 2.0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
            port regen { h: hr, area: Awr / 2.0, wall: (3.0 * Th + Tk) / 4.0 },
        }
        cv cold {
            volume: Vc0 + Vr / 2.0,
            faces { displacer: A - Ar, piston: -(A - Ar) },
            port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
        }
        link hot -> cold { resistance: Rf }
    }
}

stirling_model! {
    /// Two CVs joined by one link with the quadratic flow law `dP = Rf mdot + Rq mdot |mdot|`.
    pub model TwoCvQuad extends stirling::models::default_engine {
        params {
            /// quadratic (turbulent) flow coefficient
            Rq: 1.0e7 "Pa s^2/kg^2",
        }
        cv hot {
            volume: Vh0 + Vr / 2.0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv cold {
            volume: Vc0 + Vr / 2.0,
            faces { displacer: A - Ar, piston: -(A - Ar) },
            port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
        }
        link hot -> cold { resistance: Rf, quadratic: Rq }
    }
}

stirling_model! {
    /// Hot CV `a`, an indexed chain `r[n]`, cold CV `c` (not `b`: the engine's coupling damper is the parameter `b`).
    pub model Chain extends stirling::models::default_engine {
        cv a {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        cv c {
            volume: Vc0,
            faces { displacer: A - Ar, piston: -(A - Ar) },
            port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
        }
        link a -> r[0] { resistance: Rf / (2.0 * n) }
        link r[j] -> r[j + 1] for j in 0..n - 1 { resistance: Rf / n }
        link r[n - 1] -> c { resistance: Rf / (2.0 * n) }
    }
}

stirling_model! {
    /// As [`Chain`], every link with the quadratic flow law too (`Rq` per section scaled by `n`).
    pub model ChainQuad extends stirling::models::default_engine {
        params {
            /// quadratic (turbulent) flow coefficient
            Rq: 1.0e7 "Pa s^2/kg^2",
        }
        cv a {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        cv c {
            volume: Vc0,
            faces { displacer: A - Ar, piston: -(A - Ar) },
            port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
        }
        link a -> r[0] { resistance: Rf / (2.0 * n), quadratic: Rq / (2.0 * n) }
        link r[j] -> r[j + 1] for j in 0..n - 1 { resistance: Rf / n, quadratic: Rq / n }
        link r[n - 1] -> c { resistance: Rf / (2.0 * n), quadratic: Rq / (2.0 * n) }
    }
}
