// A per-section link whose range misses a section: it must run over every section,
// `for j in 0..n`.
use stirling::stirling_model;

stirling_model! {
    pub model ShortLeak {
        params {
            R: 287.05, gamma: 1.4, A: 2.8e-3, Vh: 1.5e-4, Vr: 4e-5, Vc: 1.2e-4, Th: 600.0,
            Tk: 300.0, P0: 101325.0, m: 0.3, k: 60.0, h: 500.0, Aw: 0.01, Rf: 1e5, eps: 1e-5,
            Rl: 1e8,
        }
        gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
        body piston(y, w) { mass: m, spring: k }
        space outside { pressure: P0, faces { piston: A } }
        cv hot { volume: Vh, port hot { h: h, area: Aw, wall: Th } }
        cv regen[n] { volume: Vr / n, port wall { h: h, area: Aw / n, wall: Th - (j + 0.5) * (Th - Tk) / n } }
        cv cold { volume: Vc, faces { piston: -A }, port cold { h: h, area: Aw, wall: Tk } }
        link hot -> regen[0] { resistance: Rf }
        link regen[j] -> regen[j + 1] for j in 0..n - 1 { resistance: Rf / n }
        link regen[n - 1] -> cold { resistance: Rf }
        link regen[j] -> cold for j in 0..n - 1 { resistance: Rl * n }
    }
}

fn main() {}
