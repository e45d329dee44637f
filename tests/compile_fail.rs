//! `stirling_model!` rejects bad declarations with errors at the user's tokens: one
//! case per error under `tests/ui/`, named after it (regenerate the `.stderr` files with
//! `TRYBUILD=overwrite cargo test --test compile_fail`, then review them).

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*.rs");
}
