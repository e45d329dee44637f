use stirling::stirling_model;

stirling_model! {
    pub model Demo extends stirling::models::nsection_engine {
        effect lag on sensor p_crank;
    }
}

fn main() {}
