//! The diagnosis report: Markdown plus SVG figures (residual by cycle phase, residual
//! harmonics, before/after overlay of the leading effect on the held-out block).

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;

use super::localize::{HARMONICS, PHASE_BINS};
use super::types::Diagnosis;
use crate::data::Measured;

fn bars(
    path: &Path,
    title: &str,
    xdesc: &str,
    ydesc: &str,
    groups: &[(String, Vec<f64>)],
    floor: Option<f64>,
) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| format!("plot {}: {e}", path.display());
    let root = SVGBackend::new(path, (900, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let nb = groups.iter().map(|g| g.1.len()).max().unwrap_or(1);
    let ng = groups.len().max(1);
    let hi = groups
        .iter()
        .flat_map(|g| g.1.iter())
        .copied()
        .filter(|v| v.is_finite())
        .fold(floor.unwrap_or(0.0), f64::max)
        .max(1e-12)
        * 1.1;
    let mut c = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..nb as f64, 0.0..hi)
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .x_desc(xdesc)
        .y_desc(ydesc)
        .disable_x_mesh()
        .draw()
        .map_err(|e| err(&e))?;
    let w = 0.8 / ng as f64;
    for (gi, (name, v)) in groups.iter().enumerate() {
        let color = Palette99::pick(gi).to_rgba();
        c.draw_series(
            v.iter()
                .enumerate()
                .filter(|(_, y)| y.is_finite())
                .map(|(i, &y)| {
                    let x0 = i as f64 + 0.1 + gi as f64 * w;
                    Rectangle::new([(x0, 0.0), (x0 + w, y)], color.filled())
                }),
        )
        .map_err(|e| err(&e))?
        .label(name.clone())
        .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 15, y + 5)], color.filled()));
    }
    if let Some(f) = floor {
        c.draw_series(LineSeries::new(
            vec![(0.0, f), (nb as f64, f)],
            BLACK.stroke_width(1),
        ))
        .map_err(|e| err(&e))?
        .label("noise floor")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
    }
    c.configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}

fn overlay(path: &Path, d: &Diagnosis, data: &Measured, ch: &str) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| format!("plot {}: {e}", path.display());
    let (Some(b), Some(meas)) = (d.before.as_ref(), data.channel(ch)) else {
        return Ok(());
    };
    let Some(ci) = b.channels.iter().position(|c| c == ch) else {
        return Ok(());
    };
    let t0 = data.t[0];
    let dt = data.dt();
    let i0 = ((d.holdout.0 - t0) / dt).round() as usize;
    let i1 = (((d.holdout.1 - t0) / dt).round() as usize + 1).min(data.t.len());
    let i1 = i1.min(i0 + (0.25 / dt) as usize).max(i0 + 2);
    let pts = |v: &[f64]| -> Vec<(f64, f64)> {
        (i0..i1)
            .filter(|&i| v[i].is_finite())
            .map(|i| (data.t[i], v[i]))
            .collect()
    };
    let m = pts(meas);
    let before = pts(&b.pred[ci]);
    let after = d.after.as_ref().and_then(|a| {
        a.channels
            .iter()
            .position(|c| c == ch)
            .map(|k| pts(&a.pred[k]))
    });
    let (lo, hi) = m
        .iter()
        .chain(&before)
        .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p.1), h.max(p.1)));
    let pad = 0.05 * (hi - lo).max(1e-12);
    let root = SVGBackend::new(path, (900, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut c = ChartBuilder::on(&root)
        .caption(
            format!("held-out `{ch}`: measured, nominal, with the leading effect"),
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(70)
        .build_cartesian_2d(data.t[i0]..data.t[i1 - 1], (lo - pad)..(hi + pad))
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .x_desc(crate::plot::axes::label("t", "s"))
        .y_desc(crate::plot::axes::channel_label(ch))
        .draw()
        .map_err(|e| err(&e))?;
    c.draw_series(m.iter().map(|&p| Circle::new(p, 1, BLACK.filled())))
        .map_err(|e| err(&e))?
        .label("measured")
        .legend(|(x, y)| Circle::new((x + 10, y), 2, BLACK.filled()));
    c.draw_series(LineSeries::new(before, &BLUE))
        .map_err(|e| err(&e))?
        .label("nominal")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
    if let Some(a) = after {
        c.draw_series(LineSeries::new(a, &RED))
            .map_err(|e| err(&e))?
            .label("with leading effect")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    }
    c.configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}

/// Write `report.md` and the figures into `dir`; returns the Markdown path.
pub fn write(d: &Diagnosis, data: &Measured, dir: &Path) -> Result<std::path::PathBuf, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let loc = &d.localization;
    let phase: Vec<(String, Vec<f64>)> = loc
        .channels
        .iter()
        .map(|c| (c.channel.clone(), c.phase_bins.clone()))
        .collect();
    bars(
        &dir.join("residual_phase.svg"),
        "residual RMS / noise by phase of the cycle",
        &format!("phase of the cycle [bin of 1/{PHASE_BINS} cycle]"),
        "residual RMS / noise [-]",
        &phase,
        Some(1.0),
    )?;
    let harm: Vec<(String, Vec<f64>)> = loc
        .channels
        .iter()
        .map(|c| {
            (
                c.channel.clone(),
                c.harmonics.iter().map(|a| a / c.harmonic_noise).collect(),
            )
        })
        .collect();
    bars(
        &dir.join("residual_harmonics.svg"),
        "residual amplitude / noise level by harmonic",
        &format!(
            "harmonic 0..{} [multiple of the cycle frequency]",
            HARMONICS - 1
        ),
        "amplitude / (2 sigma / sqrt N) [-]",
        &harm,
        Some(1.0),
    )?;
    let mut figs = vec![
        "residual_phase.svg".to_string(),
        "residual_harmonics.svg".to_string(),
    ];
    for c in &loc.channels {
        let f = format!("overlay_{}.svg", c.channel);
        overlay(&dir.join(&f), d, data, &c.channel)?;
        figs.push(f);
    }
    let mut s = String::new();
    let _ = writeln!(s, "# Gap diagnosis: `{}` on `{}`\n", d.model, data.source);
    let v = &d.verdict;
    let _ = writeln!(
        s,
        "**Verdict: {}{}**; {}\n",
        v.verdict,
        v.effect
            .as_ref()
            .map(|e| format!(" (`{e}`)"))
            .unwrap_or_default(),
        v.reason
    );
    let _ = writeln!(
        s,
        "Training {:.3}:{:.3} s, held out {:.3}:{:.3} s; {} fits, {:.1} s.\n",
        d.train.0, d.train.1, d.holdout.0, d.holdout.1, d.fits, d.seconds
    );
    let _ = writeln!(
        s,
        "## Gap before (held out)\n\n| channel | RMS | noise | RMS/noise |\n|---|---|---|---|"
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
        let _ = writeln!(
            s,
            "| {} | {:.4e} | {:.4e} | {:.3} | {} |",
            p.name,
            p.start,
            p.calibrated,
            p.factor,
            p.prior_sd.map(|z| format!("{z:+.2}")).unwrap_or("-".into())
        );
    }
    let _ = writeln!(
        s,
        "\nSubsystems: mechanics {:.3}, gas {:.3} noise variances (dominant: {}).\n",
        loc.mechanics_error, loc.gas_error, loc.dominant_subsystem
    );
    let f = &loc.features;
    let _ = writeln!(s, "| feature | measured | free run |\n|---|---|---|");
    let fr = f.free_run.clone().unwrap_or_default();
    for (n, a, b) in [
        ("frequency (Hz)", f.measured.frequency_hz, fr.frequency_hz),
        ("x amplitude (m)", f.measured.x_amp, fr.x_amp),
        ("y amplitude (m)", f.measured.y_amp, fr.y_amp),
        ("p amplitude (Pa)", f.measured.p_amp, fr.p_amp),
        (
            "phase x-y (deg)",
            f.measured.phase_x_y_deg,
            fr.phase_x_y_deg,
        ),
        ("growth rate (1/s)", f.measured.growth_rate, fr.growth_rate),
        ("cycle work (J)", f.measured.cycle_work, fr.cycle_work),
    ] {
        let _ = writeln!(s, "| {n} | {a:.4e} | {b:.4e} |");
    }
    let _ = writeln!(s, "\n## Ranking\n\n| effect | score | p | fitted | delta BIC | held-out error | closure [95 % CI] | parameters |\n|---|---|---|---|---|---|---|---|");
    for r in &d.ranking {
        let opt = |v: Option<f64>| v.map(|v| format!("{v:.3}")).unwrap_or_else(|| "-".into());
        let params: Vec<String> = r
            .params
            .iter()
            .map(|q| {
                format!(
                    "{} = {:.3e} [{:.3e}, {:.3e}] {}",
                    q.name, q.value, q.ci_low, q.ci_high, q.unit
                )
            })
            .collect();
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
            params.join("; ")
        );
    }
    let _ = writeln!(s, "\n## Figures\n");
    for f in &figs {
        let _ = writeln!(s, "![{f}]({f})");
    }
    let path = dir.join("report.md");
    std::fs::write(&path, s).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(path)
}
