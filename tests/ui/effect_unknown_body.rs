use stirling::stirling_model;

stirling_model! {
    pub model Demo extends stirling::models::nsection_engine {
        effect coulomb on crank;
    }
}

fn main() {}
