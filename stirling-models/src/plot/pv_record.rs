//! A record's p-V loop against a model's: the measured samples as points and the model's loop
//! as a line over the same revolutions (volume \[cm^3\], gauge pressure \[kPa\]); and the
//! pressure difference (model - record) against the crank angle, folded onto one revolution,
//! with the noise level marked.

use std::path::Path;

use plotters::prelude::*;

use super::{axes, DrawError};

/// `(lo, hi)` of the finite `v`, padded by `pad` of the span at each end.
fn span(v: impl Iterator<Item = f64>, pad: f64) -> Option<(f64, f64)> {
    let (lo, hi) = v
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(x), h.max(x))
        });
    if !(lo <= hi) {
        return None;
    }
    let d = (hi - lo).max(1e-9 * hi.abs().max(1.0));
    Some((lo - pad * d, hi + pad * d))
}

/// One loop of the figure: its legend and its `(V [cm^3], p [kPa gauge])` samples.
pub struct Loop<'a> {
    pub label: &'a str,
    pub points: &'a [(f64, f64)],
}

/// The measured loop (grey points) and the model's (red line) in the (V, p) plane, with
/// arrowheads along the model's first `per_rev` samples (one revolution) showing the cycle's
/// direction (clockwise: work done by the gas).
pub fn pv_loops_svg(
    path: &Path,
    title: &str,
    measured: &Loop,
    model: &Loop,
    per_rev: usize,
) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let all = || measured.points.iter().chain(model.points);
    let (Some((v0, v1)), Some((p0, p1))) = (
        span(all().map(|q| q.0), 0.05),
        span(all().map(|q| q.1), 0.05),
    ) else {
        return Err(err(&"no finite samples to draw"));
    };
    // headroom for the legend above the loops
    let p1 = p1 + 0.25 * (p1 - p0);
    let root = SVGBackend::new(path, (760, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut c = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(v0..v1, p0..p1)
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .x_desc(axes::label("working-gas volume V", "cm^3"))
        .y_desc(axes::label("p", "kPa gauge"))
        .x_label_formatter(&axes::linear_ticks(v1 - v0))
        .y_label_formatter(&axes::linear_ticks(p1 - p0))
        .draw()
        .map_err(|e| err(&e))?;
    let grey = RGBColor(110, 110, 110);
    c.draw_series(
        measured
            .points
            .iter()
            .filter(|q| q.0.is_finite() && q.1.is_finite())
            .map(|&q| Circle::new(q, 2, grey.filled())),
    )
    .map_err(|e| err(&e))?
    .label(measured.label)
    .legend(move |(x, y)| Circle::new((x + 10, y), 3, grey.filled()));
    c.draw_series(LineSeries::new(
        model
            .points
            .iter()
            .copied()
            .filter(|q| q.0.is_finite() && q.1.is_finite()),
        RED.stroke_width(2),
    ))
    .map_err(|e| err(&e))?
    .label(model.label)
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
    // arrowheads in pixels (the axes are scaled differently), on the whole canvas
    let m = per_rev.min(model.points.len());
    for j in 0..4 {
        let i = j * m / 4 + m / 8;
        let (Some(&a), Some(&b)) = (model.points.get(i), model.points.get(i + 1)) else {
            continue;
        };
        if let Some(head) = super::pv::arrowhead(c.backend_coord(&a), c.backend_coord(&b)) {
            root.draw(&Polygon::new(head, RED.filled()))
                .map_err(|e| err(&e))?;
        }
    }
    c.configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}

/// The difference (model - record, Pa) against the crank angle \[deg, 0 to 360\]: every sample
/// as a point, its mean in `bins` equal bins as a line, and `+-noise` (Pa) as dashed lines.
pub fn difference_by_angle_svg(
    path: &Path,
    title: &str,
    angle_deg: &[f64],
    diff: &[f64],
    noise: f64,
    bins: usize,
) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    if angle_deg.len() != diff.len() {
        return Err(err(&format!(
            "{} angles against {} differences",
            angle_deg.len(),
            diff.len()
        )));
    }
    let pts: Vec<(f64, f64)> = angle_deg
        .iter()
        .zip(diff)
        .filter(|q| q.0.is_finite() && q.1.is_finite())
        .map(|(&a, &d)| (a.rem_euclid(360.0), d))
        .collect();
    let lim = pts
        .iter()
        .map(|q| q.1.abs())
        .chain(std::iter::once(noise.abs()))
        .fold(0.0f64, f64::max)
        .max(1e-9);
    // headroom for the legend
    let (lo, hi) = (-1.1 * lim, 1.8 * lim);
    let root = SVGBackend::new(path, (900, 460)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut c = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..360.0, lo..hi)
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .x_desc(axes::label("crank angle", "deg"))
        .y_desc(axes::label("p model - record", "Pa"))
        .x_labels(9)
        .x_label_formatter(&|a: &f64| format!("{a:.0}"))
        .y_label_formatter(&axes::linear_ticks(hi - lo))
        .draw()
        .map_err(|e| err(&e))?;
    let grey = RGBColor(110, 110, 110);
    c.draw_series(LineSeries::new([(0.0, 0.0), (360.0, 0.0)], BLACK.mix(0.5)))
        .map_err(|e| err(&e))?;
    c.draw_series(pts.iter().map(|&q| Circle::new(q, 2, grey.filled())))
        .map_err(|e| err(&e))?
        .label("every sample")
        .legend(move |(x, y)| Circle::new((x + 10, y), 3, grey.filled()));
    let mean = binned_mean(&pts, bins.max(1));
    c.draw_series(LineSeries::new(mean, RED.stroke_width(2)))
        .map_err(|e| err(&e))?
        .label(format!(
            "mean in {} deg bins (about {} samples each)",
            360 / bins.max(1),
            pts.len() / bins.max(1)
        ))
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
    let blue = BLUE.stroke_width(2);
    for (k, s) in [noise, -noise].into_iter().enumerate() {
        let line = DashedLineSeries::new([(0.0, s), (360.0, s)], 8, 5, blue);
        let drawn = c.draw_series(line).map_err(|e| err(&e))?;
        if k == 0 {
            drawn
                .label(format!(
                    "noise level +-{:.1} Pa (1 sd, the record's third differences)",
                    noise.abs()
                ))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue));
        }
    }
    c.configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}

/// The mean of the points' values in `bins` equal bins of 0 to 360, at the bins' centres
/// (empty bins left out).
fn binned_mean(pts: &[(f64, f64)], bins: usize) -> Vec<(f64, f64)> {
    let w = 360.0 / bins as f64;
    let mut sum = vec![(0.0, 0usize); bins];
    for &(a, d) in pts {
        let k = ((a / w) as usize).min(bins - 1);
        sum[k].0 += d;
        sum[k].1 += 1;
    }
    sum.iter()
        .enumerate()
        .filter(|(_, s)| s.1 > 0)
        .map(|(k, s)| ((k as f64 + 0.5) * w, s.0 / s.1 as f64))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_average_their_points_and_skip_empty_ones() {
        let pts = [(10.0, 1.0), (20.0, 3.0), (350.0, -2.0)];
        let m = binned_mean(&pts, 12);
        assert_eq!(m, vec![(15.0, 2.0), (345.0, -2.0)]);
    }
}
