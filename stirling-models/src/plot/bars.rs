//! Bars per group over a common index (the diagnosis's residual by phase bin and by
//! harmonic), with an optional horizontal reference line (the noise floor).

use std::path::Path;

use plotters::prelude::*;

use super::DrawError;

/// The top of the value axis: 10 % above the highest finite bar or the floor.
fn top(groups: &[(String, Vec<f64>)], floor: Option<f64>) -> f64 {
    groups
        .iter()
        .flat_map(|g| g.1.iter())
        .copied()
        .filter(|v| v.is_finite())
        .fold(floor.unwrap_or(0.0), f64::max)
        .max(1e-12)
        * 1.1
}

/// One bar group per `(name, values)`, side by side at each index; `floor` draws a line.
pub fn bars(
    path: &Path,
    title: &str,
    xdesc: &str,
    ydesc: &str,
    groups: &[(String, Vec<f64>)],
    floor: Option<f64>,
) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let root = SVGBackend::new(path, (900, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let nb = groups.iter().map(|g| g.1.len()).max().unwrap_or(1);
    let ng = groups.len().max(1);
    let hi = top(groups, floor);
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
