use stirling::stirling_model;

stirling_model! {
    pub model Demo extends stirling::models::nsection_engine {
        effect quadratic on link hot -> cold;
    }
}

fn main() {}
