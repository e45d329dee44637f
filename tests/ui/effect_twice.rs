use stirling::stirling_model;

stirling_model! {
    pub model Demo extends stirling::models::nsection_engine {
        effect coulomb on piston;
        effect coulomb on piston;
    }
}

fn main() {}
