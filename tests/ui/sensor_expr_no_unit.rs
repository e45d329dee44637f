use stirling::stirling_model;

stirling_model! {
    pub model Demo extends stirling::models::nsection_engine {
        sensor f: A * (P_cold - Pmean);
    }
}

fn main() {}
