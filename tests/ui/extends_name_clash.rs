// Adding items whose names the base already declares: a second bounce space, a second
// parameter `Pb`, a second let `D`; each error points at the added name and says how to
// replace it instead.
use stirling::stirling_model;

stirling_model! {
    pub model Clash extends stirling::models::default_engine {
        params { Pb: 2e5 "Pa", Vb0: 1e-3 "m^3" }
        let D = 0.06;
        space bounce { pressure: Pb, faces { displacer: Ar, piston: A - Ar } }
        cv gas { volume: Vh0, faces { displacer: -Ar } }
    }
}

fn main() {}
