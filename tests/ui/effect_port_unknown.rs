use stirling::stirling_model;

stirling_model! {
    pub model Demo extends stirling::models::nsection_engine {
        effect heater_input on port hot.heater;
    }
}

fn main() {}
