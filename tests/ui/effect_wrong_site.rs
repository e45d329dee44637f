use stirling::stirling_model;

stirling_model! {
    pub model Demo extends stirling::models::nsection_engine {
        effect coulomb cold -> bounce;
    }
}

fn main() {}
