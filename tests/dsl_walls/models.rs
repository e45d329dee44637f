#![allow(dead_code)]
//! Test topologies with walls that have a temperature state, on the default engine's numbers
//! (docs/physics.md section 8): a hot CV, a regenerator chain `r[n]`, a cold CV.

use stirling::stirling_model;

stirling_model! {
    /// The engine frame shared by the wall models: the family's default engine, the wall
    /// parameters, the cold CV and the regenerator links; each model declares the hot CV, the
    /// chain `r[n]` and its walls.
    base wall_engine extends stirling::models::default_engine {
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
    /// Every wall fixed: the baseline (the `Chain` of the foundation tests).
    pub model Fixed extends wall_engine {
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
    }
}

stirling_model! {
    /// A heater head of finite heat capacity `1/kh` fed by `Qin`, losing heat to the cold end.
    pub model HeadWall extends wall_engine {
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: head },
        }
        wall head { capacity: 1.0 / kh, rest: Tk + Qin / Gloss, input: Qin }
        link head -> Tk { conductance: Gloss }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
    }
}

stirling_model! {
    /// A regenerator matrix of heat capacity `Cm` with axial conduction to the fixed ends.
    pub model MatrixWall extends wall_engine {
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: matrix[j] },
        }
        wall matrix[n] { capacity: Cm / n, rest: Th - (j + 0.5) * (Th - Tk) / n }
        link matrix[j] -> matrix[j + 1] for j in 0..n - 1 { conductance: Gm * n }
        link Th -> matrix[0] { conductance: 2.0 * Gm * n }
        link matrix[n - 1] -> Tk { conductance: 2.0 * Gm * n }
    }
}

stirling_model! {
    /// Both: the matrix conducts into the head at its hot end.
    pub model HeadMatrix extends wall_engine {
        let Th0 = Tk + Qin / (Gloss + Gm);
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: head },
        }
        wall head { capacity: 1.0 / kh, rest: Th0, input: Qin }
        link head -> Tk { conductance: Gloss }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: matrix[j] },
        }
        wall matrix[n] { capacity: Cm / n, rest: Th0 - (j + 0.5) * (Th0 - Tk) / n }
        link matrix[j] -> matrix[j + 1] for j in 0..n - 1 { conductance: Gm * n }
        link head -> matrix[0] { conductance: 2.0 * Gm * n }
        link matrix[n - 1] -> Tk { conductance: 2.0 * Gm * n }
    }
}

stirling_model! {
    /// One gas space on one piston whose liner is a thermal mass cooled to the ambient.
    pub model OneWall {
        params {
            R: 287.05 "J/(kg K)",
            gamma: 1.4 "-",
            P0: 101325.0 "Pa",
            m: 0.33363 "kg",
            k: 61.482 "N/m",
            A: 2.6e-3 "m^2",
            V0: 1.5e-4 "m^3",
            Tamb: 300.0 "K",
            h: 500.0 "W/(m^2 K)",
            Aw: 0.0128 "m^2",
            /// heat capacity of the liner
            C: 50.0 "J/K",
            /// conductance from the liner to the ambient
            G: 0.5 "W/K",
            eps: 1.0e-5 "kg/s",
        }
        gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
        body piston(y, w) { mass: m, spring: k }
        space bounce { pressure: P0, faces { piston: A } }
        cv gas { volume: V0, faces { piston: -A }, port liner { h: h, area: Aw, wall: sleeve } }
        wall sleeve { capacity: C, rest: Tamb }
        link sleeve -> Tamb { conductance: G }
    }
}

stirling_model! {
    /// A regenerator matrix inside a shell: every gas section and every matrix section exchange
    /// heat with the one shell wall (per-section ports and per-section conduction), the shell
    /// cools to `Tk`, and every matrix section loses a little to `Tk` directly.
    pub model MatrixShell extends wall_engine {
        params {
            /// inverse heat capacity of the regenerator shell
            ks: 2.0e-2 "K/J",
            /// heat-transfer coefficient from the gas to the shell
            hs: 50.0 "W/(m^2 K)",
            /// shell wall area of the whole regenerator
            Aws: 0.02 "m^2",
            /// conductance from the whole matrix to the shell
            Gms: 0.05 "W/K",
            /// conductance from the whole matrix straight to the cold end
            Gma: 0.01 "W/K",
            /// conductance from the shell to the cold end
            Gs: 0.2 "W/K",
        }
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv r[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: matrix[j] },
            port shell { h: hs, area: Aws / n, wall: shell },
        }
        wall matrix[n] { capacity: Cm / n, rest: Th - (j + 0.5) * (Th - Tk) / n }
        wall shell { capacity: 1.0 / ks, rest: Tk }
        link matrix[j] -> matrix[j + 1] for j in 0..n - 1 { conductance: Gm * n }
        link Th -> matrix[0] { conductance: 2.0 * Gm * n }
        link matrix[n - 1] -> Tk { conductance: 2.0 * Gm * n }
        link matrix[j] -> shell for j in 0..n { conductance: Gms / n }
        link matrix[j] -> Tk for j in 0..n { conductance: Gma / n }
        link shell -> Tk { conductance: Gs }
    }
}
