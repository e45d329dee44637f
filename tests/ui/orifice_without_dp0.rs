// An orifice link without its regularization width `dp0`: the square-root law has no
// derivative at dP = 0, so the width of its linear core must be declared.
use stirling::stirling_model;

stirling_model! {
    pub model BareOrifice {
        params {
            R: 287.05, gamma: 1.4, A: 2.8e-3, Vh: 1.5e-4, Vc: 1.2e-4, Th: 600.0,
            Tk: 300.0, P0: 101325.0, m: 0.3, k: 60.0, h: 500.0, Aw: 0.01, Rf: 1e5, eps: 1e-5,
            Co: 1e-7,
        }
        gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
        body piston(y, w) { mass: m, spring: k }
        space outside { pressure: P0, temperature: Tk, faces { piston: A } }
        cv hot { volume: Vh, port hot { h: h, area: Aw, wall: Th } }
        cv cold { volume: Vc, faces { piston: -A }, port cold { h: h, area: Aw, wall: Tk } }
        link hot -> cold { resistance: Rf }
        link cold -> outside { orifice: Co }
    }
}

fn main() {}
