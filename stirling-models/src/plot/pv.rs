//! PV diagram per vessel over one cycle: pressure (kPa) against volume (cm^3);
//! the enclosed area is the vessel's cycle work.

use std::path::Path;

use plotters::prelude::*;

/// One closed `(V, P)` loop per vessel, in one panel each (a grid).
pub fn pv_svg(
    path: &Path,
    title: &str,
    vessels: &[String],
    loops: &[Vec<(f64, f64)>],
    work: &[f64],
) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| format!("plot {}: {e}", path.display());
    let k = vessels.len().max(1);
    let cols = k.min(3);
    let rows = k.div_ceil(cols);
    let root =
        SVGBackend::new(path, (360 * cols as u32, 320 * rows as u32 + 40)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(&format!("{title}: PV diagrams"), ("sans-serif", 20))
        .map_err(|e| err(&e))?;
    for (i, area) in root
        .split_evenly((rows, cols))
        .into_iter()
        .enumerate()
        .take(vessels.len())
    {
        let pts: Vec<(f64, f64)> = loops[i].iter().map(|&(v, p)| (1e6 * v, 1e-3 * p)).collect();
        let span = |f: fn(&(f64, f64)) -> f64| {
            let (l, h) = pts
                .iter()
                .map(f)
                .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
            let pad = ((h - l) * 0.05).max(1e-9 * h.abs().max(1.0));
            (l - pad)..(h + pad)
        };
        let mut c = ChartBuilder::on(&area)
            .caption(
                format!(
                    "{} (W = {:.4} J)",
                    vessels[i],
                    work.get(i).copied().unwrap_or(0.0)
                ),
                ("sans-serif", 14),
            )
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(span(|p| p.0), span(|p| p.1))
            .map_err(|e| err(&e))?;
        c.configure_mesh()
            .x_desc("V (cm^3)")
            .y_desc("P (kPa)")
            .x_labels(5)
            .draw()
            .map_err(|e| err(&e))?;
        c.draw_series(LineSeries::new(pts, &BLUE))
            .map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))
}
