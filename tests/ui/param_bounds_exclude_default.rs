use stirling::stirling_model;

stirling_model! {
    pub model Demo extends stirling::models::nsection_engine {
        replace params { kd: 650.0 "N/m" in 700.0..800.0 }
    }
}

fn main() {}
