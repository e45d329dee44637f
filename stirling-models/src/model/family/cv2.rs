//! `cv2`: two gas control volumes joined by the regenerator resistance (6th order frozen, 8 full).

stirling_macros::stirling_model! {
    /// Hot space plus upper regenerator half, and cold space plus lower half, joined by `Rf`.
    pub model Cv2 extends default_engine {
        name "cv2";
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
            port regen { h: hr, area: Awr / 2.0, wall: (Th + 3.0 * Tk) / 4.0 },
        }
        link hot -> cold { resistance: Rf }
        // the seed's cold-side transducer, and a hot-side one when a rig has it
        sensor p: P_cold "Pa";
        sensor p_hot: P_hot "Pa";
    }
}
