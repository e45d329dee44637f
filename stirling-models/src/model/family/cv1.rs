//! `cv1`: one gas control volume with three heat ports (5th order).

stirling_macros::stirling_model! {
    /// One control volume for all the gas; hot, cold and regenerator heat ports.
    pub model Cv1 extends default_engine {
        name "cv1";
        cv gas {
            volume: Vh0 + Vc0 + Vr,
            // hot face -A plus cold face (A - Ar) on the displacer
            faces { displacer: -Ar, piston: -(A - Ar) },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
            port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
            port regen { h: hr, area: Awr, wall: (Th + Tk) / 2.0 },
        }
        // the seed's pressure transducer, here on the one CV
        sensor p: P_gas "Pa";
    }
}
