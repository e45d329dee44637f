//! `schmidt`: the 4th-order isothermal model (docs/physics.md section 3, seed eqs. S12-S15).
//!
//! `P = M R / (Vh/Th + Vc/Tk + Vr/Tr)`, `Tr = (Th - Tk)/ln(Th/Tk)`, `M R = Pmean S0`.

stirling_macros::stirling_model! {
    /// The Schmidt model: isothermal spaces at one algebraic pressure.
    pub model Schmidt extends default_engine {
        name "schmidt";
        let Tr = (Th - Tk) / ln(Th / Tk);
        let MR = Pmean * (Vh0 / Th + Vc0 / Tk + Vr / Tr);
        let Vh = Vh0 - A * x;
        let Vc = Vc0 + (A - Ar) * (x - y);
        let P = MR / (Vh / Th + Vc / Tk + Vr / Tr);
        space hot { pressure: P, volume: Vh0, faces { displacer: -A } }
        space cold { pressure: P, volume: Vc0, faces { displacer: A - Ar, piston: -(A - Ar) } }
        space regenerator { pressure: P, volume: Vr }
    }
}
