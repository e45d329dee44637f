//! Checks of an identification against the truth that generated its record: every free
//! parameter's interval covers the truth and is not vacuous, and the calibrated model's free
//! run matches the held-out amplitudes.

use stirling::models::fit::free_run::CycleFeatures;
use stirling::models::fit::Identification;

/// Each of `free` (with its true value) is estimated with an interval that covers the truth
/// and is narrower than `width` times it.
pub fn assert_recovered<'a>(
    id: &Identification,
    free: impl IntoIterator<Item = (&'a str, f64)>,
    width: f64,
) {
    for (name, truth) in free {
        let e = id.estimate(name).unwrap();
        eprintln!(
            "{name}: {:.5e} [{:.5e}, {:.5e}], truth {truth:.5e}",
            e.value, e.ci_low, e.ci_high
        );
        assert!(
            e.covers(truth),
            "{name}: truth {truth} outside [{}, {}]",
            e.ci_low,
            e.ci_high
        );
        // an honest interval, not a vacuous one
        assert!(
            e.ci_high - e.ci_low < width * truth,
            "{name}: interval too wide"
        );
    }
}

/// The free run's amplitude of each of `channels` within `tol` (relative) of the record's.
pub fn assert_free_run_amplitudes(id: &Identification, channels: &[&str], tol: f64) {
    let fr = id
        .free_run
        .as_ref()
        .expect("free run on the held-out block");
    let (m, s) = (
        fr.measured.as_ref().unwrap(),
        fr.simulated.as_ref().unwrap(),
    );
    for &ch in channels {
        let amp = |c: &CycleFeatures| c.amplitude.iter().find(|a| a.0 == ch).expect("channel").1;
        let rel = (amp(s) - amp(m)) / amp(m);
        assert!(
            rel.abs() < tol,
            "{ch}: free-run amplitude off by {:.2} %",
            100.0 * rel
        );
    }
}
