//! Start-up time response in the style of the seed's Figure 3: displacer `x`,
//! piston `y` (mm) and the pressures (kPa) against time, two stacked panels.

use std::path::Path;

use plotters::prelude::*;

/// Plot `x`, `y` (state columns `ix`, `iy`) and the `pressures` columns of `states` against `t`.
pub fn startup_svg(
    path: &Path,
    title: &str,
    t: &[f64],
    states: &[Vec<f64>],
    ix: usize,
    iy: usize,
    pressures: &[(String, usize)],
) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| format!("plot {}: {e}", path.display());
    let root = SVGBackend::new(path, (900, 700)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let (top, bottom) = root.split_vertically(350);
    let t1 = t.last().copied().unwrap_or(1.0).max(1e-12);
    let mm = |k: usize| -> Vec<(f64, f64)> {
        t.iter()
            .zip(states)
            .map(|(&t, x)| (t, 1e3 * x[k]))
            .collect()
    };
    let (xs, ys) = (mm(ix), mm(iy));
    let lim = xs.iter().chain(&ys).map(|p| p.1.abs()).fold(1e-9, f64::max) * 1.05;
    let mut c = ChartBuilder::on(&top)
        .caption(format!("{title}: start-up"), ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t1, -lim..lim)
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .x_desc("t (s)")
        .y_desc("position (mm)")
        .draw()
        .map_err(|e| err(&e))?;
    c.draw_series(LineSeries::new(xs, &BLUE))
        .map_err(|e| err(&e))?
        .label("displacer x")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
    c.draw_series(LineSeries::new(ys, &RED))
        .map_err(|e| err(&e))?
        .label("piston y")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    c.configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()
        .map_err(|e| err(&e))?;
    let series: Vec<Vec<(f64, f64)>> = pressures
        .iter()
        .map(|(_, k)| {
            t.iter()
                .zip(states)
                .map(|(&t, x)| (t, 1e-3 * x[*k]))
                .collect()
        })
        .collect();
    let (lo, hi) = series
        .iter()
        .flatten()
        .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p.1), h.max(p.1)));
    let (lo, hi) = if lo < hi {
        (lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo))
    } else {
        (lo - 1.0, lo + 1.0)
    };
    let mut c = ChartBuilder::on(&bottom)
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t1, lo..hi)
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .x_desc("t (s)")
        .y_desc("pressure (kPa)")
        .draw()
        .map_err(|e| err(&e))?;
    for (i, (s, (name, _))) in series.into_iter().zip(pressures).enumerate() {
        let color = Palette99::pick(i).to_rgba();
        c.draw_series(LineSeries::new(s, color))
            .map_err(|e| err(&e))?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
    }
    c.configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}
