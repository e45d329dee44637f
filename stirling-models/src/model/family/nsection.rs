//! `nsection`: hot space, `n` regenerator sections, cold space (n+6 frozen, 2n+8 full).

stirling_macros::stirling_model! {
    /// The default engine with the `nsection` gas: hot space, `n` regenerator sections with a
    /// linear wall profile, cold space (exported: `stirling::models::nsection_engine`).
    pub base nsection_engine extends default_engine {
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
        // the seed's cold-side transducer, and a hot-side one when a rig has it
        sensor p: P_cold "Pa";
        sensor p_hot: P_hot "Pa";
    }
}

stirling_macros::stirling_model! {
    /// Hot space, `n` regenerator sections with a linear wall profile, cold space.
    pub model NSection extends nsection_engine {
        name "nsection";
    }
}
