// Replacing, removing and modifying items the base does not declare (typos: `bounse`,
// `Pbb`, `pistn`, a link the default engine does not have); each error points at the name.
use stirling::stirling_model;

stirling_model! {
    pub model Typos extends stirling::models::nsection_engine {
        replace cv bounse {
            volume: 2.0e-3,
            faces { displacer: Ar, piston: A - Ar },
        }
        remove param Pbb;
        modify body pistn { force: -w }
        remove link hot -> cold;
        replace params { Pmaen: 1e5 "Pa" }
    }
}

fn main() {}
