//! A kinematic engine's record that logs the volume instead of the crank angle (`dV [cm^3]`,
//! zero at mid-stroke, as lab setups with a transducer on the power piston log it): the fit
//! reads the angle back through the model's volume (`fit::kinematic::volume`) and its 95 %
//! intervals cover the truth as the angle record's do (`tests/fit_kinematic.rs`: the same
//! engine, truth and noise on the pressure); the angle it reads follows the true one; a
//! volume in the wrong unit (mm^3 read as cm^3) is refused by name.

use std::path::Path;

use stirling::dsl::{Closure, Model};
use stirling::models::data::Measured;
use stirling::models::files;
use stirling::models::fit::kinematic::volume::angle_from_volume;
use stirling::models::fit::{self, FitError, FitOptions};
use stirling::models::rig::{measure, RigConfig};
use stirling::models::sim::indicated::volume_at_angles;

fn gamma() -> Box<dyn Model> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/engines/gamma_ltd.stirling");
    files::build(&path, 1, Closure::Full).expect("the file loads")
}

/// The truth: the defaults with the regenerator's resistance doubled and the leak tripled.
fn truth(m: &dyn Model) -> Vec<f64> {
    let mut p = m.default_params();
    p[m.param_index("Rf").unwrap()] *= 2.0;
    p[m.param_index("Gleak").unwrap()] *= 3.0;
    p
}

/// The rig's record of `p` and the true angle at 100 Hz for 10 s (after a push and 5 s of
/// settling), and the same record with the angle replaced by the volume's change from
/// mid-stroke (m^3) with `noise` (m^3) on it.
fn records(m: &dyn Model, p: &[f64], noise: f64) -> (Measured, Measured) {
    let cfg = RigConfig {
        t_end: 10.0,
        settle: 5.0,
        rate: 100.0,
        noise_p: 10.0,
        offset_p: 150.0,
        start: vec![("omega".into(), 17.7)],
        // the true angle (the rig needs a noise level for a channel in rad)
        noise: vec![("theta".into(), 1e-9)],
        channels: vec!["p".into(), "theta".into()],
        seed: 7,
        ..Default::default()
    };
    let rec = measure(m, p, &cfg).expect("the rig records the engine");
    let theta = rec.channel("theta").unwrap().to_vec();
    let v = volume_at_angles(m, p, &theta).unwrap();
    let grid: Vec<f64> = (0..3600)
        .map(|k| k as f64 * std::f64::consts::TAU / 3600.0)
        .collect();
    let table = volume_at_angles(m, p, &grid).unwrap();
    let lo = table.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = table.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut seed = 11u64;
    let mut uniform = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let dv: Vec<f64> = v
        .iter()
        .map(|v| v - 0.5 * (lo + hi) + noise * 3.46 * uniform())
        .collect();
    let mut by_volume = rec.clone();
    by_volume.others.retain(|(n, _)| n != "theta");
    by_volume.others.push(("dV".into(), dv));
    (rec, by_volume)
}

#[test]
fn a_volume_record_is_fitted_through_the_models_volume() {
    let m = gamma();
    let p = truth(m.as_ref());
    // 0.005 cm^3 of noise on a swing of about 1.6 cm^3 (a hobby transducer's)
    let (by_angle, by_volume) = records(m.as_ref(), &p, 5e-9);
    let read = angle_from_volume(m.as_ref(), &m.default_params(), &by_volume)
        .unwrap()
        .expect("the angle is read from dV");
    let truth_theta = by_angle.channel("theta").unwrap();
    // the angle follows the true one (up to whole turns at the start), worst near the
    // volume's extremes where the branches meet
    let shift =
        std::f64::consts::TAU * ((truth_theta[0] - read.theta[0]) / std::f64::consts::TAU).round();
    let mut err: Vec<f64> = read
        .theta
        .iter()
        .zip(truth_theta)
        .map(|(a, b)| (a + shift - b).abs())
        .collect();
    err.sort_by(f64::total_cmp);
    let (median, worst) = (err[err.len() / 2], err[err.len() - 1]);
    eprintln!("angle from dV: median error {median:.4} rad, worst {worst:.4} rad");
    assert!(
        median < 0.01 && worst < 0.05,
        "median {median}, worst {worst}"
    );
    let opts = FitOptions {
        free: Some(["hp", "hs", "Rf", "Gleak"].map(String::from).to_vec()),
        ..Default::default()
    };
    let id = fit::identify(m.as_ref(), &m.default_params(), &by_volume, &opts).expect("fitted");
    assert!(
        id.notes
            .iter()
            .any(|n| n.contains("read from the volume `dV`")),
        "{:?}",
        id.notes
    );
    for name in ["hp", "hs", "Rf", "Gleak"] {
        let e = id.estimate(name).expect("estimated");
        let t = p[m.param_index(name).unwrap()];
        eprintln!(
            "{name}: truth {t:.4e}, estimate {:.4e}, 95 % [{:.4e}, {:.4e}]",
            e.value, e.ci_low, e.ci_high
        );
        assert!(e.ci_low <= t && t <= e.ci_high, "{name}: {e:?} misses {t}");
        assert!(e.ci_high - e.ci_low < 2.0 * e.value.abs(), "{name}: {e:?}");
    }
}

#[test]
fn a_volume_in_the_wrong_unit_is_refused_by_name() {
    let m = gamma();
    let p = truth(m.as_ref());
    let (_, mut by_volume) = records(m.as_ref(), &p, 0.0);
    // mm^3 read as cm^3: a thousand times the swing
    for (n, v) in by_volume.others.iter_mut() {
        if n == "dV" {
            v.iter_mut().for_each(|x| *x *= 1e3);
        }
    }
    let e = angle_from_volume(m.as_ref(), &m.default_params(), &by_volume).unwrap_err();
    assert!(matches!(e, FitError::KinematicColumn { .. }), "{e:?}");
    let msg = e.to_string();
    eprintln!("{msg}");
    assert!(
        msg.contains("`dV`") && msg.contains("cm^3 a revolution"),
        "{msg}"
    );
}
