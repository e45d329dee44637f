//! The diagnosis report: `report.md` and its figures. First the gap where a user sees it
//! (the simulated feature table before and after the leading effect, and the residual by
//! phase of the cycle in physical units), then where the driven subsystems miss (residual
//! by phase bin and by harmonic, relative to the noise), the ranking, and the held-out
//! overlays. The figures are drawn by [`crate::plot`].

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::localize::{HARMONICS, PHASE_BINS};
use super::types::Diagnosis;
use crate::data::Measured;
use crate::plot::{self, DrawError};

/// Why the report could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("cannot write {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error(transparent)]
    Draw(#[from] DrawError),
}

fn io(path: &Path) -> impl Fn(std::io::Error) -> ReportError + '_ {
    move |source| ReportError::Io {
        path: path.display().to_string(),
        source,
    }
}

/// The simulated residual by phase of the cycle, of the calibrated model and after each
/// step (without steps, after the leading fitted candidate), where measured.
fn phase_figure(d: &Diagnosis, dir: &Path) -> Result<Option<String>, DrawError> {
    let Some(g) = &d.simulation_gap else {
        return Ok(None);
    };
    // (label, gap) of every simulated "after" column: one per step, or the diagnosis's
    let afters: Vec<(String, &super::sim_gap::SimulationGap)> = if d.steps.is_empty() {
        vec![(format!("with `{}`", g.effect.as_deref().unwrap_or("-")), g)]
    } else {
        d.steps
            .iter()
            .filter_map(|st| {
                let sg = st.simulation_gap.as_ref()?;
                Some((
                    format!("after step {}: + {}", st.step, st.effects.join(" + ")),
                    sg,
                ))
            })
            .collect()
    };
    let panels: Vec<plot::phase_residual::Panel> = g
        .phase_residuals
        .iter()
        .map(|r| {
            let mut lines = vec![("calibrated model", r.before.as_slice())];
            for (label, sg) in &afters {
                let after = sg
                    .phase_residuals
                    .iter()
                    .find(|q| q.channel == r.channel)
                    .and_then(|q| q.after.as_deref());
                if let Some(a) = after {
                    lines.push((label.as_str(), a));
                }
            }
            plot::phase_residual::Panel {
                channel: &r.channel,
                lines,
            }
        })
        .collect();
    let f = "simulated_residual_phase.svg";
    plot::phase_residual::phase_residual(
        &dir.join(f),
        &format!(
            "held-out {:.2}-{:.2} s, free run: measured - model by phase of the cycle",
            g.block.0, g.block.1
        ),
        &panels,
    )?;
    Ok(Some(f.into()))
}

/// The waterfall of the held-out gap (excess error over the noise floor) through the
/// steps, with the 95 % interval of the level after each.
fn waterfall_figure(d: &Diagnosis, dir: &Path) -> Result<Option<String>, DrawError> {
    if d.steps.is_empty() {
        return Ok(None);
    }
    let start = d.gap_before.holdout_error - 1.0;
    // a step without a simulated closure (end stops named from the measured acceleration
    // alone, `diagnose::untouched`) has no level to draw
    let steps: Vec<&super::types::Step> = d.steps.iter().filter(|s| s.has_closure()).collect();
    if steps.is_empty() {
        return Ok(None);
    }
    let labels: Vec<String> = steps.iter().map(|s| s.label()).collect();
    let drops: Vec<plot::waterfall::Drop> = steps
        .iter()
        .zip(&labels)
        .map(|(s, label)| plot::waterfall::Drop {
            label,
            after: start * (1.0 - s.cumulative.value),
            low: start * (1.0 - s.cumulative.ci_high),
            high: start * (1.0 - s.cumulative.ci_low),
        })
        .collect();
    let f = "gap_waterfall.svg";
    plot::waterfall::waterfall(
        &dir.join(f),
        "held-out gap closed step by step (driven subsystems)",
        "held-out error - 1 [noise variances]",
        start,
        &drops,
    )?;
    Ok(Some(f.into()))
}

/// The driven subsystems' residual / noise by phase bin and by harmonic.
fn localization_figures(d: &Diagnosis, dir: &Path) -> Result<Vec<String>, DrawError> {
    let loc = &d.localization;
    let group = |f: &dyn Fn(&super::localize::ChannelLoc) -> Vec<f64>| -> Vec<(String, Vec<f64>)> {
        loc.channels
            .iter()
            .map(|c| (c.channel.clone(), f(c)))
            .collect()
    };
    plot::bars::bars(
        &dir.join("residual_phase.svg"),
        "driven subsystems: residual RMS / noise by phase of the cycle",
        &format!("phase of the cycle [bin of 1/{PHASE_BINS} cycle]"),
        "residual RMS / noise [-]",
        &group(&|c| c.phase_bins.clone()),
        Some(1.0),
    )?;
    plot::bars::bars(
        &dir.join("residual_harmonics.svg"),
        "driven subsystems: residual amplitude / noise level by harmonic",
        &format!(
            "harmonic 0..{} [multiple of the cycle frequency]",
            HARMONICS - 1
        ),
        "amplitude / (2 sigma / sqrt N) [-]",
        &group(&|c| c.harmonics.iter().map(|a| a / c.harmonic_noise).collect()),
        Some(1.0),
    )?;
    Ok(vec![
        "residual_phase.svg".into(),
        "residual_harmonics.svg".into(),
    ])
}

/// The driven prediction of `ch` on (the first 0.25 s of) the held-out block, before and
/// after the leading effect.
fn overlay_figure(
    d: &Diagnosis,
    data: &Measured,
    ch: &str,
    dir: &Path,
) -> Result<Option<String>, DrawError> {
    let (Some(b), Some(meas)) = (d.before.as_ref(), data.channel(ch)) else {
        return Ok(None);
    };
    let Some(ci) = b.channels.iter().position(|c| c == ch) else {
        return Ok(None);
    };
    let (t0, dt) = (data.t[0], data.dt());
    let i0 = ((d.holdout.0 - t0) / dt).round() as usize;
    let i1 = (((d.holdout.1 - t0) / dt).round() as usize + 1).min(data.t.len());
    let i1 = i1
        .min(i0 + (0.25 / dt) as usize)
        .max(i0 + 2)
        .min(data.t.len());
    let mut lines = vec![("nominal", &b.pred[ci][i0..i1])];
    if let Some((a, k)) = d
        .after
        .as_ref()
        .and_then(|a| a.channels.iter().position(|c| c == ch).map(|k| (a, k)))
    {
        lines.push(("with leading effect", &a.pred[k][i0..i1]));
    }
    let f = format!("overlay_{ch}.svg");
    plot::overlay::overlay(
        &dir.join(&f),
        &format!("held-out `{ch}` (driven): measured, nominal, with the leading effect"),
        ch,
        &data.t[i0..i1],
        &meas[i0..i1],
        &lines,
    )?;
    Ok(Some(f))
}

/// Write `report.md` and the figures into `dir`; returns the Markdown path.
pub fn write(d: &Diagnosis, data: &Measured, dir: &Path) -> Result<PathBuf, ReportError> {
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let mut figs: Vec<String> = waterfall_figure(d, dir)?.into_iter().collect();
    figs.extend(phase_figure(d, dir)?);
    figs.extend(localization_figures(d, dir)?);
    for c in &d.localization.channels {
        figs.extend(overlay_figure(d, data, &c.channel, dir)?);
    }
    let path = dir.join("report.md");
    crate::output::write_atomic(&path, markdown(d, data, &figs).as_bytes(), true)
        .map_err(|e| io(&path)(std::io::Error::other(e)))?;
    Ok(path)
}

fn markdown(d: &Diagnosis, data: &Measured, figs: &[String]) -> String {
    let mut s = String::new();
    let v = &d.verdict;
    let effect = if v.effects.len() > 1 {
        format!(" (`{}`)", v.effects.join("`, `"))
    } else {
        v.effect
            .as_ref()
            .map(|e| format!(" (`{e}`)"))
            .unwrap_or_default()
    };
    let _ = writeln!(s, "# Gap diagnosis: `{}` on `{}`\n", d.model, data.source);
    let _ = writeln!(s, "**Verdict: {}{effect}**; {}\n", v.verdict, v.reason);
    let _ = writeln!(
        s,
        "Training {:.3}:{:.3} s, held out {:.3}:{:.3} s; {} fits, {:.1} s.\n",
        d.train.0, d.train.1, d.holdout.0, d.holdout.1, d.fits, d.seconds
    );
    steps_section(&mut s, d);
    simulated_section(&mut s, d);
    driven_section(&mut s, d);
    ranking_section(&mut s, d);
    let _ = writeln!(s, "\n## Figures\n");
    for f in figs {
        let _ = writeln!(s, "![{f}]({f})");
    }
    s
}

fn steps_section(s: &mut String, d: &Diagnosis) {
    if d.steps.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "## The explanation step by step\n\nEach step refits the nominal parameters and every effect named so far jointly; closures are of the held-out excess error (1 is the noise floor), with 95 % bootstrap intervals over cycles. Figure `gap_waterfall.svg` (the steps with a simulated closure).\n\n| step | effect | closes of what remained | in all | held-out error | rms/noise by channel | parameters |\n|---|---|---|---|---|---|---|"
    );
    // a step without a simulated closure (end stops from the acceleration alone): a dash
    let iv = |i: &super::types::Interval| {
        if i.value.is_finite() {
            format!("{:.2} [{:.2}, {:.2}]", i.value, i.ci_low, i.ci_high)
        } else {
            "-".into()
        }
    };
    let err = |e: f64| {
        if e.is_finite() {
            format!("{e:.3}")
        } else {
            "-".into()
        }
    };
    for st in &d.steps {
        let ch: Vec<String> = st
            .channels
            .iter()
            .map(|c| format!("{} {:.2}", c.channel, c.ratio))
            .collect();
        let params = param_list(&st.params);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} |",
            st.step,
            st.label(),
            iv(&st.closure),
            iv(&st.cumulative),
            err(st.holdout_error),
            ch.join(", "),
            params
        );
    }
    for st in d.steps.iter().filter(|st| st.simulation_gap.is_none()) {
        if let Some(note) = &st.simulation_gap_note {
            let _ = writeln!(
                s,
                "\nStep {} (`{}`): {note}.",
                st.step,
                st.effects.join(" + ")
            );
        }
    }
    for st in &d.steps {
        if let Some(g) = &st.simulation_gap {
            let _ = writeln!(
                s,
                "\nAfter step {} (`{}`), the model simulated on its own over the held-out block ({} cycles):\n\n{}",
                st.step,
                st.effects.join(" + "),
                g.cycles,
                g.markdown()
            );
        }
    }
    if d.verdict.unexplained_remainder {
        let _ = writeln!(
            s,
            "\n**A gap remains that the library does not explain.**\n"
        );
    }
}

fn simulated_section(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(s, "## The gap in simulation (held out)\n");
    match (&d.simulation_gap, &d.simulation_gap_note) {
        (Some(g), _) => {
            let _ = writeln!(
                s,
                "The calibrated model run on its own from the measured state at {:.3} s, compared cycle by cycle with the record over {} cycles (error = model - measured, mean over the cycles, 95 % bootstrap interval over the cycles). Figure `simulated_residual_phase.svg` shows where in the cycle the waveforms differ, in m and Pa.\n\n{}",
                g.block.0,
                g.cycles,
                g.markdown()
            );
        }
        (None, Some(why)) => {
            let _ = writeln!(s, "Not measured: {why}.\n");
        }
        _ => {}
    }
}

fn driven_section(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        s,
        "\n## Where: the driven subsystems (held out)\n\n| channel | RMS | noise | RMS/noise |\n|---|---|---|---|"
    );
    for c in &d.gap_before.channels {
        let _ = writeln!(
            s,
            "| {} | {:.4e} | {:.4e} | {:.3} |",
            c.channel, c.rms, c.noise, c.ratio
        );
    }
    let _ = writeln!(
        s,
        "\n| parameter | start | calibrated | factor | prior sd |\n|---|---|---|---|---|"
    );
    for p in &d.gap_before.shifts {
        let sd = p.prior_sd.map(|z| format!("{z:+.2}")).unwrap_or("-".into());
        let _ = writeln!(
            s,
            "| {} | {:.4e} | {:.4e} | {:.3} | {sd} |",
            p.name, p.start, p.calibrated, p.factor
        );
    }
    let loc = &d.localization;
    let _ = writeln!(
        s,
        "\nSubsystems: mechanics {:.3}, gas {:.3} noise variances (dominant: {}).",
        loc.mechanics_error, loc.gas_error, loc.dominant_subsystem
    );
}

fn ranking_section(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(s, "\n## Ranking\n\n| effect | score | p | fitted | delta BIC | held-out error | closure [95 % CI] | parameters |\n|---|---|---|---|---|---|---|---|");
    let opt = |v: Option<f64>| v.map(|v| format!("{v:.3}")).unwrap_or_else(|| "-".into());
    for r in &d.ranking {
        let params = param_list(&r.params);
        let _ = writeln!(
            s,
            "| {} | {:.2} | {:.2e} | {} | {} | {} | {} [{}, {}] | {} |",
            r.effect,
            r.score,
            r.p_value,
            r.fitted,
            opt(r.delta_bic),
            opt(r.holdout_error),
            opt(r.closure_fraction),
            opt(r.ci_low),
            opt(r.ci_high),
            params
        );
    }
}

/// Estimates with their intervals, `; `-separated.
fn param_list(params: &[super::types::EffectEstimate]) -> String {
    params
        .iter()
        .map(|q| {
            if q.ci_low.is_finite() {
                format!(
                    "{} = {:.3e} [{:.3e}, {:.3e}] {}",
                    q.name, q.value, q.ci_low, q.ci_high, q.unit
                )
            } else {
                format!("{} = {:.3e} (no interval) {}", q.name, q.value, q.unit)
            }
        })
        .collect::<Vec<_>>()
        .join("; ")
}
