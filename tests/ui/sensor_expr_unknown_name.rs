use stirling::stirling_model;

stirling_model! {
    pub model Demo extends stirling::models::nsection_engine {
        sensor dp: P_cold - Pamb "Pa";
    }
}

fn main() {}
