// A user's engine whose cold space puts a face on a body that was never declared
// (a typo: `pistn` for `piston`); the error points at the face.
use stirling::stirling_model;

stirling_model! {
    pub model TypoEngine {
        params {
            R: 287.05, gamma: 1.4, A: 2.8e-3, V0: 1.2e-4, Tk: 300.0, P0: 101325.0,
            m: 0.3, k: 60.0, h: 500.0, Aw: 0.01, eps: 1e-5,
        }
        gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
        body piston(y, w) { mass: m, spring: k }
        space outside { pressure: P0, faces { piston: A } }
        cv cold {
            volume: V0,
            faces { pistn: -A },
            port cold { h: h, area: Aw, wall: Tk },
        }
    }
}

fn main() {}
