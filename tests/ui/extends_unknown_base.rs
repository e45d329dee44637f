// A model extending a base that does not exist (a typo: `default_engin`); the error
// points at the base's name.
use stirling::stirling_model;

stirling_model! {
    pub model Typo extends stirling::models::default_engin {
        name "typo";
    }
}

fn main() {}
