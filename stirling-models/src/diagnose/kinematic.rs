//! The diagnosis of a kinematic engine (a flywheel driving cranks, docs/physics.md section
//! 12; method and measurements: docs/diagnosis.md, "Kinematic engines"). The record gives the
//! pressure `p` and the flywheel's angle; the calibration is the kinematic fit
//! ([`crate::fit::kinematic`]: the gas driven by the measured angle, the film coefficients,
//! the pressure offset and the gas's initial masses fitted). The free-piston diagnosis runs
//! on that one driven stage for the gap before, where, and the sensor effects (score, joint
//! fit); each model effect the engine names is fitted by the kinematic fit itself with its
//! strength freed (`kinematic_refit.rs`), and all are judged on the held-out block by the
//! free-piston verdict's rule.
//!
//! What does not carry over: the second pass with stage 1 restarted (the end stops of a
//! free body; no stage 1 runs), the simulated gap (its cycles are counted on the displacer's
//! position `x`, which a kinematic record does not carry; its note says so), steps after the
//! first. The flywheel's friction and load act on no driven row; they are checked against the
//! file's by the kinematic fit's torque balance (`kinematic_flywheel.rs`), and the verdict's
//! reason ends with that check.

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};
use std::time::Instant;

use stirling_dsl::Model;

use super::kinematic_refit::{held_out, is_model_effect, refit, HeldOut, Refit};
use super::kinematic_verdict::{passes, rank, verdict};
use super::types::{ChannelError, Diagnosis, Interval, RankEntry, Step};
use super::{DiagnoseError, DiagnoseOptions};
use crate::data::Measured;
use crate::effects::{EffectInfo, EffectParam, EffectTarget};
use crate::fit::classify::classify;
use crate::fit::FitOptions;
use crate::layout::StateLayout;
use crate::signal::noise_sigma;

/// The units of the parameters a kinematic diagnosis calibrates when no `--free` is given:
/// the film coefficients, the estimates a kit engine's geometry does not give (its dimensions,
/// temperatures and gas constants are read or measured; its leak is what the `leak` effect
/// tests). Not the regenerator's flow resistance: its pressure drop is a few Pa against a
/// 10 Pa transducer, so a free `Rf` is not identified and its fit settles on its floor when
/// the gas misses something (a gamma LTD record with 5x the nominal leak: `Rf` at 300
/// against 1e4, the leak fitted at half its truth, its interval missing it; with `Rf` held,
/// the leak came out at 1.98e-9 for 2e-9).
pub const CALIBRATED_UNITS: [&str; 1] = ["W/(m^2 K)"];

/// What a kinematic verdict adds when the file's flywheel has no friction parameter to
/// check (`kinematic_flywheel.rs`): a `no_significant_gap` is then the gas's alone.
pub const FLYWHEEL_UNTESTED: &str = "; the flywheel's friction and load are not tested (the file gives its flywheel no friction parameter to check): the verdict is the gas's, driven by the measured angle";

/// Diagnose the kinematic engine `model` from `p0` (its effects at their nulls) on a record
/// with the pressure `p` and the flywheel's angle.
pub(super) fn diagnose(
    model: &dyn Model,
    p0: &[f64],
    data: &Measured,
    opts: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let clock = Instant::now();
    // a record too coarse for the cycle is refused by its rate, before the blocks' motion
    // check takes its aliased pressure for a still engine
    crate::fit::kinematic::angle::check_rate(model, data).map_err(DiagnoseError::Record)?;
    let free = match &opts.fit.free {
        Some(f) => f.clone(),
        None => default_free(model, p0)?,
    };
    let cands = super::candidates::candidates(model, &opts.effects)?;
    let (model_effects, sensor): (Vec<&EffectInfo>, Vec<&EffectInfo>) =
        cands.iter().copied().partition(|e| is_model_effect(e));
    // the shared diagnosis: the calibration, the gap before, where, and the sensor effects
    // (scored and fitted on the driven stage as on a free-piston engine)
    let mut o = opts.clone();
    o.fit.free = Some(free.clone());
    o.effects = Some(sensor.iter().map(|e| e.name.to_string()).collect());
    let mut d = super::run::diagnose_once(model, p0, data, &o, &[])?;
    // the model effects, each by the kinematic fit with its strength freed
    let fit_opts = FitOptions {
        train: Some(d.train),
        holdout: Some(d.holdout),
        prior: opts.prior,
        free: Some(free.clone()),
        free_run: None,
        multiple_shooting: None,
        input_noise_draws: 0,
        ..opts.fit.clone()
    };
    let (id0, _) = crate::fit::identify_stages(model, p0, data, &fit_opts)?;
    let nominal = held_out(&id0, data, d.holdout)?;
    let mut refits: Vec<Refit> = Vec::new();
    for e in &model_effects {
        let r = refit(
            model,
            p0,
            data,
            (&free, &fit_opts),
            e,
            (&nominal, d.holdout),
            (opts.bootstrap, opts.seed),
        );
        if let Some(progress) = opts.progress {
            progress(&format!(
                "{}: fitted with the gas parameters ({:.1} s): p = {:.2e}, held-out BIC {:+.1}",
                e.name,
                r.entry.seconds,
                r.entry.p_value,
                r.entry.delta_bic.unwrap_or(f64::NAN)
            ));
        }
        refits.push(r);
    }
    d.fits += 1 + refits.len();
    let mut ranking: Vec<RankEntry> = refits.iter().map(|r| r.entry.clone()).collect();
    ranking.append(&mut d.ranking);
    let level = opts.alpha / cands.len().max(1) as f64;
    rank(&mut ranking, level);
    let named = ranking
        .iter()
        .find(|r| passes(r, level))
        .map(|r| r.effect.clone());
    let gap = nominal.mean();
    let held = named
        .as_ref()
        .and_then(|n| refits.iter().find(|r| &r.entry.effect == n))
        .and_then(|r| r.held.as_ref());
    d.verdict = verdict(
        &ranking,
        named.as_deref(),
        level,
        (gap, nominal.err.len()),
        held,
    );
    // the flywheel's friction, which the driven gas cannot see (`kinematic_flywheel.rs`)
    match super::kinematic_flywheel::check(model, p0, data, &fit_opts, level) {
        Ok(Some(f)) => {
            d.verdict.reason.push_str(&f.sentence());
            d.flywheel = Some(f);
        }
        Ok(None) => d.verdict.reason.push_str(FLYWHEEL_UNTESTED),
        Err(e) => d.verdict.reason.push_str(&format!(
            "; the flywheel's friction could not be checked against the file's ({e})"
        )),
    }
    if let (Some(name), Some(h)) = (&named, held) {
        let row = ranking.iter().find(|r| &r.effect == name).expect("named");
        d.steps = vec![step(row, h, data, &ranking)];
        d.remainder = Vec::new();
    } else if named.is_none() {
        d.steps.clear();
    }
    d.ranking = ranking;
    d.simulation_gap = None;
    d.simulation_gap_note = Some(
        "not computed on a kinematic engine: the free run's cycles are counted on the \
         displacer's position `x`, which its record does not carry (the driven fit is \
         judged on the held-out block instead)"
            .into(),
    );
    for s in &mut d.steps {
        s.simulation_gap = None;
        s.simulation_gap_note.clone_from(&d.simulation_gap_note);
    }
    d.seconds = clock.elapsed().as_secs_f64();
    Ok(d)
}

/// The one step of a named model effect.
fn step(row: &RankEntry, held: &HeldOut, data: &Measured, ranking: &[RankEntry]) -> Step {
    let noise = data.p.as_deref().map_or(f64::NAN, noise_sigma);
    let closure = Interval {
        value: row.closure_fraction.unwrap_or(f64::NAN),
        ci_low: row.ci_low.unwrap_or(f64::NAN),
        ci_high: row.ci_high.unwrap_or(f64::NAN),
    };
    Step {
        step: 1,
        effects: vec![row.effect.clone()],
        p_value: row.p_value,
        delta_bic: row.delta_bic.unwrap_or(f64::NAN),
        params: row.params.clone(),
        closure,
        cumulative: closure,
        holdout_error: held.mean(),
        channels: vec![ChannelError {
            channel: "p".into(),
            rms: held.rms,
            noise,
            ratio: held.rms / noise,
        }],
        simulation_gap: None,
        simulation_gap_note: None,
        ranking: ranking.to_vec(),
        seconds: row.seconds,
        after_stops: false,
        from_reset: false,
        one_run: false,
        evidence: super::types::Evidence::Steps,
        superseded: None,
        eval: None,
    }
}

/// The parameters of `model` whose unit is one of `units`, nonzero at `p0` (not an effect's
/// null), that act on the gas alone (`mechanics` false) or on the mechanics alone (true).
pub(super) fn acting_params(
    model: &dyn Model,
    p0: &[f64],
    units: &[&str],
    mechanics: bool,
) -> Vec<String> {
    model
        .params()
        .iter()
        .zip(p0)
        .filter(|(i, &v)| units.contains(&i.unit) && v > 0.0)
        .map(|(i, _)| i.name.to_string())
        .filter(|n| match classify(model, p0, std::slice::from_ref(n)) {
            Ok((m, g)) if mechanics => !m.is_empty() && g.is_empty(),
            Ok((m, g)) => m.is_empty() && !g.is_empty(),
            Err(_) => false,
        })
        .collect()
}

/// The parameters the calibration frees by default: the gas parameters whose unit is one of
/// [`CALIBRATED_UNITS`] and whose value is not an effect's null (0).
pub fn default_free(model: &dyn Model, p0: &[f64]) -> Result<Vec<String>, DiagnoseError> {
    let free = acting_params(model, p0, &CALIBRATED_UNITS, false);
    if free.is_empty() {
        return Err(DiagnoseError::KinematicFree {
            model: model.name().into(),
        });
    }
    Ok(free)
}

/// The candidates of a kinematic engine among `pool` (what the engine names, and the sensor
/// effects): the position gains dropped (a kinematic record measures no position), the
/// library's `sensor_lag` dropped when the engine names a lag with its parameter, and each
/// model effect's typical strength (the joint fit's step and its second start) taken from the
/// engine's own parameter of that unit when it has one (the gamma LTD's leak `Gleak`, 4e-10
/// kg/(s Pa), against the library's 2e-8 for a free-piston engine's seals: from 2e-8 the joint
/// fit of a leak ended near 1e-9 on every record, clean or not). An engine of free bodies
/// gets `pool` as it is.
pub(super) fn candidate_pool(
    model: &dyn Model,
    pool: Vec<&'static EffectInfo>,
) -> Vec<&'static EffectInfo> {
    if StateLayout::flywheels(model).is_empty() {
        return pool;
    }
    let declared_lag = |e: &EffectInfo| {
        e.name != "sensor_lag"
            && e.target == EffectTarget::Sensor
            && e.params.iter().any(|q| q.name == "tau_p")
    };
    let has_lag = pool.iter().any(|e| declared_lag(e));
    pool.iter()
        .filter(|e| e.name != "sensor_gain" && !(has_lag && e.name == "sensor_lag"))
        .map(|&e| {
            if e.target != EffectTarget::Model {
                return e;
            }
            let params = own_typicals(model, e);
            if params
                .iter()
                .zip(e.params)
                .all(|(a, b)| a.typical == b.typical)
            {
                return e;
            }
            rescaled(e, params)
        })
        .collect()
}

/// The effect's parameters with each strength's typical value taken from the model's own
/// parameter of the same unit (the first with a positive default).
fn own_typicals(model: &dyn Model, e: &EffectInfo) -> Vec<EffectParam> {
    e.params
        .iter()
        .map(|q| {
            let own = model.params().iter().find(|i| {
                q.null.is_some() && i.name != q.name && i.unit == q.unit && i.default > 0.0
            });
            EffectParam {
                typical: own.map_or(q.typical, |i| i.default),
                ..*q
            }
        })
        .collect()
}

/// `e` with `params`, made `'static` once per distinct content (the library's effects are
/// `'static`; a process that diagnoses many engines keeps one copy of each rescaling, keyed
/// by the effect and its typical values bit for bit, so two engines of one name but other
/// defaults never share a stale one).
fn rescaled(e: &'static EffectInfo, params: Vec<EffectParam>) -> &'static EffectInfo {
    static CACHE: OnceLock<Mutex<HashMap<String, &'static EffectInfo>>> = OnceLock::new();
    let bits: Vec<String> = params
        .iter()
        .map(|q| format!("{:x}", q.typical.to_bits()))
        .collect();
    let key = format!("{}#{}", e.name, bits.join(","));
    let cache = CACHE.get_or_init(Default::default);
    let mut cache = cache.lock().unwrap_or_else(|e| e.into_inner());
    cache.entry(key).or_insert_with(|| {
        let info = EffectInfo {
            params: Box::leak(params.into_boxed_slice()),
            ..*e
        };
        &*Box::leak(Box::new(info))
    })
}
