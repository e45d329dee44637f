// A model extending a crate-local base by a name that was never declared (`engine_bse` for
// `engine_base`); the error points at the name.
use stirling::stirling_model;

stirling_model! {
    base engine_base extends stirling::models::default_engine {
        cv gas { volume: Vh0 + Vc0 + Vr, faces { displacer: -Ar }, port hot { h: hh, area: Awh0, wall: Th } }
    }
}

stirling_model! {
    pub model Typo extends engine_bse {
        name "typo";
    }
}

fn main() {}
