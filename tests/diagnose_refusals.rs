//! A record that cannot carry a diagnosis is refused with the reason, never given a verdict:
//! an engine that stops during the record (its held-out motion buried in the noise).

use stirling::models::data::Measured;
use stirling::models::diagnose::{diagnose, nominal_model, DiagnoseError, DiagnoseOptions};

/// Seeded Gaussian noise (Box-Muller on a small LCG: the test needs no statistics, only
/// reproducible noise).
fn noise(seed: u64, sigma: f64) -> impl FnMut() -> f64 {
    let mut s = seed;
    let mut uniform = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    move || sigma * (-2.0 * uniform().ln()).sqrt() * (2.0 * std::f64::consts::PI * uniform()).cos()
}

/// A 2 s record at 1 kHz of a 13.4 Hz motion of amplitude `amp(t)` (x in m, y in m, p in Pa).
fn record(amp: impl Fn(f64) -> f64) -> Measured {
    let t: Vec<f64> = (0..2000).map(|k| k as f64 * 1e-3).collect();
    let w = 2.0 * std::f64::consts::PI * 13.4;
    let (mut nx, mut ny, mut np) = (noise(1, 2e-5), noise(2, 2e-5), noise(3, 50.0));
    let x = t
        .iter()
        .map(|&s| 8e-3 * amp(s) * (w * s).sin() + nx())
        .collect();
    let y = t
        .iter()
        .map(|&s| 7e-3 * amp(s) * (w * s - 1.4).sin() + ny())
        .collect();
    let p = t
        .iter()
        .map(|&s| 101_325.0 + 6e3 * amp(s) * (w * s + 0.3).sin() + np())
        .collect();
    Measured {
        source: "stopping.csv".into(),
        t,
        p: Some(p),
        p_hot: None,
        x: Some(x),
        y: Some(y),
        ..Default::default()
    }
}

#[test]
fn an_engine_that_stops_is_refused_with_the_reason() {
    let (model, p0) = nominal_model("nsection", Some(2)).unwrap();
    // running for the first half, then decaying to rest within a few cycles
    let data = record(|t| {
        if t < 1.0 {
            1.0
        } else {
            (-(t - 1.0) / 0.05).exp()
        }
    });
    let err = diagnose(model.as_ref(), &p0, &data, &DiagnoseOptions::default()).unwrap_err();
    match &err {
        DiagnoseError::NoMotion {
            channel,
            rms,
            noise,
            ..
        } => {
            assert_eq!(*channel, "x");
            assert!(*rms < 5.0 * noise, "rms {rms:.3e} noise {noise:.3e}");
        }
        other => panic!("expected a refusal for no motion, got {other}"),
    }
    let text = err.to_string();
    assert!(
        text.contains("stopping.csv") && text.contains("motion dies out"),
        "{text}"
    );
}
