//! Small test topologies, one feature each, on the default engine's numbers.

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

/// The engine frame shared by the two-CV and chain models (docs/physics.md section 8).
macro_rules! test_engine {
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
                    /// quadratic (turbulent) flow coefficient, used by the `*Quad` models
                    Rq: 1.0e7 "Pa s^2/kg^2",
                    mdot_eps: 1.0e-5 "kg/s",
                }
                let D = sqrt(4.0 * A / pi);
                gas { R: R, gamma: gamma, charge: Pmean, mdot_eps: mdot_eps }
                body displacer(x, v) { mass: md, spring: kd, damper: bd, quad_damper: bqd }
                body piston(y, w) { mass: mp, spring: kp, damper: bp, quad_damper: bqp }
                coupling displacer, piston { damper: bc }
                space bounce { pressure: Pb, faces { displacer: Ar, piston: A - Ar } }
                $($body)*
            }
        }
    };
}

test_engine! {
    /// Two CVs joined by one linear link.
    model TwoCv {
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

test_engine! {
    /// Two CVs joined by one link with the quadratic flow law `dP = Rf mdot + Rq mdot |mdot|`.
    model TwoCvQuad {
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

test_engine! {
    /// Hot CV `a`, an indexed chain `r[n]`, cold CV `b`.
    model Chain {
        cv a {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        cv b {
            volume: Vc0,
            faces { displacer: A - Ar, piston: -(A - Ar) },
            port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
        }
        link a -> r[0] { resistance: Rf / (2.0 * n) }
        link r[j] -> r[j + 1] for j in 0..n - 1 { resistance: Rf / n }
        link r[n - 1] -> b { resistance: Rf / (2.0 * n) }
    }
}

test_engine! {
    /// As [`Chain`], every link with the quadratic flow law too (`Rq` per section scaled by `n`).
    model ChainQuad {
        cv a {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        cv b {
            volume: Vc0,
            faces { displacer: A - Ar, piston: -(A - Ar) },
            port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
        }
        link a -> r[0] { resistance: Rf / (2.0 * n), quadratic: Rq / (2.0 * n) }
        link r[j] -> r[j + 1] for j in 0..n - 1 { resistance: Rf / n, quadratic: Rq / n }
        link r[n - 1] -> b { resistance: Rf / (2.0 * n), quadratic: Rq / (2.0 * n) }
    }
}
