use stirling::stirling_model;

stirling_model! {
    pub model Demo extends stirling::models::nsection_engine {
        sensor q: kd * x + P_cold[2] "N";
    }
}

fn main() {}
