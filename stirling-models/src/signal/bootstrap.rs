//! The bootstrap over cycles: resamples with replacement (seeded, so a diagnosis repeats
//! exactly) and the 95 % percentile interval of the resampled values.

use rand::{rngs::StdRng, Rng, SeedableRng};

/// `count` resamples of the indices `0..k`, each of `k` draws with replacement.
pub fn resamples(k: usize, count: usize, seed: u64) -> Vec<Vec<usize>> {
    let mut rng = StdRng::seed_from_u64(seed);
    (0..count)
        .map(|_| (0..k).map(|_| rng.gen_range(0..k)).collect())
        .collect()
}

/// The 2.5 % and 97.5 % percentiles of the finite values of `boot` (NaN when none is finite).
pub fn percentile_interval(mut boot: Vec<f64>) -> (f64, f64) {
    boot.retain(|v| v.is_finite());
    boot.sort_by(f64::total_cmp);
    let q = |p: f64| {
        boot.get(((boot.len() as f64 - 1.0) * p).round() as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    (q(0.025), q(0.975))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resamples_draw_within_range_and_repeat_with_the_seed() {
        let a = resamples(7, 20, 3);
        assert_eq!(a.len(), 20);
        assert!(a.iter().all(|d| d.len() == 7 && d.iter().all(|&i| i < 7)));
        assert_eq!(a, resamples(7, 20, 3));
        assert_ne!(a, resamples(7, 20, 4));
    }

    #[test]
    fn percentile_interval_of_a_uniform_grid() {
        let boot: Vec<f64> = (0..=1000).map(|i| i as f64 / 1000.0).collect();
        let (lo, hi) = percentile_interval(boot);
        assert!((lo - 0.025).abs() < 1e-12 && (hi - 0.975).abs() < 1e-12);
        let (lo, _) = percentile_interval(vec![f64::NAN, 2.0]);
        assert_eq!(lo, 2.0);
        assert!(percentile_interval(vec![f64::NAN]).0.is_nan());
    }
}
