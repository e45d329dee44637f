//! One verdict case's record: the rig run of its truth, written to CSV and read back like
//! any measured file (only the CSV crosses over to the diagnosis), its signature (stroke,
//! frequency) and the diagnosis's perturbed start.

use std::path::Path;

use rand::{rngs::StdRng, Rng, SeedableRng};
use serde::Serialize;
use stirling_dsl::Model;

use super::plan::{Planned, Truth, VerdictOptions};
use super::verdict_settings;
use crate::data::{read_csv, write_csv, Measured};
use crate::diagnose::DiagnoseError;
use crate::outside::outside;
use crate::rig::{self, RigConfig};

/// The start of a case's diagnosis: kd, kp, bd, bp, hh, hk each moved by a uniform factor
/// in `1 +- perturb`, drawn from the case's own seed (a user's first guess).
pub fn seeded_start(model: &dyn Model, p_nom: &[f64], perturb: f64, seed: u64) -> Vec<f64> {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut p0 = p_nom.to_vec();
    for name in ["kd", "kp", "bd", "bp", "hh", "hk"] {
        let u: f64 = rng.gen_range(-1.0..=1.0);
        if let Some(i) = model.param_index(name) {
            p0[i] *= 1.0 + perturb * u;
        }
    }
    p0
}

/// The rig's configuration for case `c`.
pub fn rig_config(opts: &VerdictOptions, c: &Planned) -> RigConfig {
    let base = RigConfig {
        model: opts.model.clone(),
        n: opts.n,
        t_end: opts.t_end,
        settle: opts.settle,
        rate: opts.rate,
        seed: c.seed,
        channels: opts.channels.clone(),
        ..Default::default()
    };
    match &c.truth {
        Truth::Clean => base,
        Truth::Effect { name, strength } => RigConfig {
            effects: verdict_settings(name, *strength),
            ..base
        },
        Truth::Pair { names, strength } => RigConfig {
            effects: names
                .iter()
                .flat_map(|n| verdict_settings(n, *strength))
                .collect(),
            ..base
        },
        Truth::Mixed {
            effect,
            outside: name,
            strength,
        } => RigConfig {
            effects: verdict_settings(effect, *strength),
            ..outside_config(base, name, *strength)
        },
        Truth::Outside { name, strength } => outside_config(base, name, *strength),
    }
}

/// The rig of outside cause `name` at `strength` times its unit.
fn outside_config(base: RigConfig, name: &str, strength: f64) -> RigConfig {
    let set = outside(name)
        .map(|o| vec![format!("{}={}", o.param, strength * o.typical)])
        .unwrap_or_default();
    RigConfig {
        truth: Some(name.to_string()),
        set,
        ..base
    }
}

/// The record of case `c`, through a CSV in `dir`.
pub fn record(opts: &VerdictOptions, c: &Planned, dir: &Path) -> Result<Measured, DiagnoseError> {
    let mut cfg = rig_config(opts, c);
    let run = |cfg: &RigConfig| {
        rig::run(cfg).map_err(|source| DiagnoseError::Rig {
            truth: c.truth.label(),
            source,
        })
    };
    // the stops inside the stroke the partner (a library effect or an outside cause) leaves
    let stops_beside = match &c.truth {
        Truth::Pair { names, .. } => names.iter().any(|n| n == "end_stops"),
        Truth::Mixed { effect, .. } => effect == "end_stops",
        _ => false,
    };
    if stops_beside {
        let partner = RigConfig {
            effects: without_stops(&cfg.effects),
            ..cfg.clone()
        };
        let sig = signature(&run(&partner)?.data);
        cfg.effects = stops_inside(&cfg.effects, &sig);
    }
    through_csv(run(&cfg)?, dir, c.index, opts.records.is_some())
}

/// The rig settings without the end stops' (`kc`, `xmax`, `ymax`).
fn without_stops(set: &[String]) -> Vec<String> {
    let stops = ["kc=", "xmax=", "ymax="];
    set.iter()
        .filter(|s| !stops.iter().any(|k| s.starts_with(k)))
        .cloned()
        .collect()
}

/// The settings with the stops' travels at [`STOP_FRACTIONS`] of the amplitudes `sig` of
/// the record without them: a stop inside the stroke the partner leaves, as the single
/// stops lie inside the clean stroke. At the clean record's amplitudes (9.3 mm, 7.6 mm) the
/// travels are the single's ([`super::VERDICT_STOPS`]); beside a quadratic regenerator loss
/// that halves the stroke, stops at the clean record's travels never touch.
fn stops_inside(set: &[String], sig: &Signature) -> Vec<String> {
    let mut out: Vec<String> = set
        .iter()
        .filter(|s| !s.starts_with("xmax=") && !s.starts_with("ymax="))
        .cloned()
        .collect();
    out.push(format!("xmax={}", STOP_FRACTIONS[0] * sig.x_amp));
    out.push(format!("ymax={}", STOP_FRACTIONS[1] * sig.y_amp));
    out
}

/// The end stops' travels in a pair as fractions of the displacer's and the piston's
/// amplitudes without them: those of [`super::VERDICT_STOPS`] on the clean record.
pub const STOP_FRACTIONS: [f64; 2] = [1.08, 0.73];

/// A rig record written to `dir/case<k>.csv` and read back (the diagnosis sees only what a
/// user's CSV holds); the file is removed after reading unless `keep`.
pub fn through_csv(
    out: rig::RigOutput,
    dir: &Path,
    k: usize,
    keep: bool,
) -> Result<Measured, DiagnoseError> {
    let path = dir.join(format!("case{k}.csv"));
    write_csv(&path, &out.data, &[]).map_err(|source| DiagnoseError::Io {
        path: path.clone(),
        source,
    })?;
    drop(out);
    let data = read_csv(&path)?;
    if !keep {
        let _ = std::fs::remove_file(&path);
    }
    Ok(data)
}

/// What a record shows of its truth, on its second half: the peak amplitudes (sqrt 2 x rms
/// about the mean) of `x`, `y`, `p`, and the frequency of `x` from its upward mean
/// crossings.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Signature {
    pub x_amp: f64,
    pub y_amp: f64,
    pub p_amp: f64,
    pub freq: f64,
}

fn amplitude(v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len().max(1) as f64;
    (2.0 * v.iter().map(|a| (a - m).powi(2)).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

/// Frequency from the first and last upward crossings of the mean (NaN if fewer than two).
fn frequency(t: &[f64], v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len().max(1) as f64;
    let up: Vec<usize> = (1..v.len())
        .filter(|&i| v[i - 1] < m && v[i] >= m)
        .collect();
    match (up.first(), up.last()) {
        (Some(&a), Some(&b)) if b > a => (up.len() - 1) as f64 / (t[b] - t[a]),
        _ => f64::NAN,
    }
}

/// The signature of a record (NaN for a missing channel).
pub fn signature(d: &Measured) -> Signature {
    let h = d.t.len() / 2;
    let amp = |c: &Option<Vec<f64>>| c.as_ref().map_or(f64::NAN, |v| amplitude(&v[h..]));
    Signature {
        x_amp: amp(&d.x),
        y_amp: amp(&d.y),
        p_amp: amp(&d.p),
        freq: d
            .x
            .as_ref()
            .map_or(f64::NAN, |x| frequency(&d.t[h..], &x[h..])),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signature_of_a_sine() {
        let t: Vec<f64> = (0..4000).map(|k| k as f64 / 2000.0).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|t| 0.003 * (2.0 * std::f64::consts::PI * 13.0 * t).sin())
            .collect();
        let d = Measured {
            source: "test".into(),
            t,
            p: None,
            p_hot: None,
            x: Some(x),
            y: None,
            ..Default::default()
        };
        let s = signature(&d);
        assert!((s.x_amp / 0.003 - 1.0).abs() < 1e-3, "{}", s.x_amp);
        assert!((s.freq / 13.0 - 1.0).abs() < 1e-3, "{}", s.freq);
        assert!(s.y_amp.is_nan());
    }
}
