//! Root locus: the poles at every parameter value of a [`Locus`], colored from blue (first
//! value) to red (last), with the right half plane shaded as in the pole map.

use std::path::Path;

use plotters::prelude::*;

use super::poles::{frame, splane_chart, DrawError};
use crate::linear::Locus;

/// Draw the root locus to an SVG file.
pub fn root_locus(path: &Path, locus: &Locus) -> Result<(), DrawError> {
    let err = DrawError::at(path);
    let ((x0, x1, y1), out) = frame(locus.points.iter().flat_map(|p| p.poles.iter()));
    let root = SVGBackend::new(path, (800, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let (first, last) = (
        locus.points.first().map_or(0.0, |p| p.value),
        locus.points.last().map_or(0.0, |p| p.value),
    );
    let mut title = format!(
        "{}: root locus over {} = {first} .. {last} (blue -> red)",
        locus.model, locus.param
    );
    if out > 0 {
        title.push_str(&format!(", {out} stiff poles off frame"));
    }
    let mut chart = splane_chart(&root, title, 18, (x0, x1, y1), &err)?;
    let k = locus.points.len().max(2) - 1;
    for (i, pt) in locus.points.iter().enumerate() {
        let t = i as f64 / k as f64;
        let color = RGBColor((255.0 * t) as u8, 0, (255.0 * (1.0 - t)) as u8);
        let visible = pt.poles.iter().filter(|p| p.re >= x0 && p.im.abs() <= y1);
        chart
            .draw_series(visible.map(|p| Circle::new((p.re, p.im), 3, color.filled())))
            .map_err(|e| err(e.to_string()))?;
    }
    root.present().map_err(|e| err(e.to_string()))
}
