//! Pole map in the style of the seed's Figure 6: closed-loop poles (crosses) and open-loop poles
//! (circles) in the complex plane, the right half plane shaded. Stiff gas poles far to the left
//! are left out of the frame (their number is printed in the caption).

use std::path::Path;

use plotters::prelude::*;

use super::DrawError;

use crate::linear::Pole;

/// The natural frequency [rad/s] up to which poles count as slow (dominant): five times the
/// largest oscillation frequency, at least 1000 rad/s; faster ones are the stiff gas poles.
pub(crate) fn slow_limit<'a>(poles: impl Iterator<Item = &'a Pole>) -> f64 {
    5.0 * poles.map(|p| p.im.abs()).fold(200.0, f64::max)
}

/// The frame `(re_min, re_max, im_max)` holding the slow poles, and the poles outside it.
pub(crate) fn frame<'a>(poles: impl Iterator<Item = &'a Pole> + Clone) -> ((f64, f64, f64), usize) {
    let im_max = poles
        .clone()
        .map(|p| p.im.abs())
        .fold(0.0, f64::max)
        .max(10.0);
    let limit = slow_limit(poles.clone());
    let inside = |p: &&Pole| p.natural_rad_s <= limit;
    let re_min = poles
        .clone()
        .filter(inside)
        .map(|p| p.re)
        .fold(-10.0, f64::min);
    let re_max = poles
        .clone()
        .filter(inside)
        .map(|p| p.re)
        .fold(10.0, f64::max);
    let out = poles.filter(|p| !inside(p)).count();
    ((re_min * 1.15, re_max * 1.3, im_max * 1.2), out)
}

/// Draw the pole map to an SVG file.
pub fn pole_map(path: &Path, title: &str, closed: &[Pole], open: &[Pole]) -> Result<(), DrawError> {
    let err = DrawError::at(path);
    let ((x0, x1, y1), out) = frame(closed.iter().chain(open));
    let root = SVGBackend::new(path, (800, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let caption = if out > 0 {
        format!("{title} ({out} stiff poles left of the frame)")
    } else {
        title.to_string()
    };
    let mut chart = splane_chart(&root, caption, 20, (x0, x1, y1), &err)?;
    let visible = |p: &&Pole| p.re >= x0 && p.im.abs() <= y1;
    chart
        .draw_series(
            open.iter()
                .filter(visible)
                .map(|p| Circle::new((p.re, p.im), 6, BLUE.stroke_width(2))),
        )
        .map_err(|e| err(e.to_string()))?
        .label("open loop")
        .legend(|(x, y)| Circle::new((x, y), 5, BLUE.stroke_width(2)));
    chart
        .draw_series(
            closed
                .iter()
                .filter(visible)
                .map(|p| Cross::new((p.re, p.im), 7, RED.stroke_width(2))),
        )
        .map_err(|e| err(e.to_string()))?
        .label("closed loop")
        .legend(|(x, y)| Cross::new((x, y), 5, RED.stroke_width(2)));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(|e| err(e.to_string()))?;
    root.present().map_err(|e| err(e.to_string()))
}

/// The s-plane chart shared by the pole map and the root locus: mesh, labels, the
/// shaded right half plane and the two axes.
pub(crate) fn splane_chart<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    caption: String,
    font: u32,
    (x0, x1, y1): (f64, f64, f64),
    err: &dyn Fn(String) -> DrawError,
) -> Result<
    ChartContext<
        'a,
        SVGBackend<'b>,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    DrawError,
> {
    let mut chart = ChartBuilder::on(root)
        .caption(caption, ("sans-serif", font))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, -y1..y1)
        .map_err(|e| err(e.to_string()))?;
    chart
        .configure_mesh()
        .x_desc("Real axis [1/s]")
        .y_desc("Imaginary axis [rad/s]")
        .draw()
        .map_err(|e| err(e.to_string()))?;
    let shade = RGBColor(255, 210, 210).filled();
    chart
        .draw_series(std::iter::once(Rectangle::new(
            [(0.0, -y1), (x1, y1)],
            shade,
        )))
        .map_err(|e| err(e.to_string()))?;
    let axis = BLACK.mix(0.5);
    chart
        .draw_series(LineSeries::new([(x0, 0.0), (x1, 0.0)], axis))
        .map_err(|e| err(e.to_string()))?;
    chart
        .draw_series(LineSeries::new([(0.0, -y1), (0.0, y1)], axis))
        .map_err(|e| err(e.to_string()))?;
    Ok(chart)
}
