//! The alternator engine's start-up record for the diagnosis tests
//! (`tests/custom_topology.rs`, `tests/custom_effects_diagnosis.rs`): effects withheld, a
//! start perturbed as a user's first guess would be.
#![allow(dead_code)]

use stirling::dsl::Model;

/// A 2 s start-up record of `m` (its own sensors `p`, `x`, `y`, `p_bounce`: the alternator
/// engine's members) with the model settings `set` (parameters by name) and the
/// sensor settings `sensor` withheld, and a start perturbed from the nominal parameters.
pub fn start_up_record<M: Model + Clone>(
    m: M,
    set: &[(&str, f64)],
    sensor: &[(&str, f64)],
) -> (M, Vec<f64>, stirling::models::data::Measured) {
    use stirling::models::effects::EffectSettings;
    use stirling::models::rig::{measure_with, RigConfig};
    let nominal = stirling::models::effects::nominal_params(&m);
    let mut truth = nominal.clone();
    for &(k, v) in set {
        truth[m.param_index(k).unwrap()] = v;
    }
    let cfg = RigConfig {
        t_end: 2.0,
        rate: 1000.0,
        seed: 5,
        channels: ["p", "x", "y", "p_bounce"].map(String::from).to_vec(),
        ..Default::default()
    };
    let fx = EffectSettings {
        sensor: sensor.iter().map(|&(k, v)| (k.to_string(), v)).collect(),
        ..Default::default()
    };
    let rec = measure_with(&m, &truth, &fx, &cfg).expect("measured");
    let mut p0 = nominal;
    for (name, f) in [
        ("kd", 1.08),
        ("kp", 0.93),
        ("bd", 1.07),
        ("bp", 0.94),
        ("hh", 1.06),
        ("hk", 0.95),
    ] {
        p0[m.param_index(name).unwrap()] *= f;
    }
    (m, p0, rec)
}
