//! A waterfall of the diagnosis's gap: the nominal model's held-out excess error, what each
//! step of the explanation closed (a floating bar from the level before it to the level
//! after it, with the 95 % interval of the level after), and what remains.

use std::path::Path;

use plotters::prelude::*;

use super::DrawError;

/// One step: its label and the level after it with its 95 % interval.
pub struct Drop<'a> {
    pub label: &'a str,
    pub after: f64,
    pub low: f64,
    pub high: f64,
}

/// The waterfall from `start` (the nominal gap) through `steps`, ending in a bar of what
/// remains; levels below zero are drawn at zero.
pub fn waterfall(
    path: &Path,
    title: &str,
    ydesc: &str,
    start: f64,
    steps: &[Drop],
) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let root = SVGBackend::new(path, (900, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let n = steps.len() + 2;
    let hi = steps
        .iter()
        .map(|s| s.high)
        .chain([start])
        .filter(|v| v.is_finite())
        .fold(1e-12, f64::max)
        * 1.1;
    let labels: Vec<String> = std::iter::once("nominal model".to_string())
        .chain(steps.iter().map(|s| format!("+ {}", s.label)))
        .chain(["remains".to_string()])
        .collect();
    let mut c = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((0..n - 1).into_segmented(), 0.0..hi)
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .y_desc(ydesc)
        .disable_x_mesh()
        .x_label_formatter(&|v| match v {
            SegmentValue::CenterOf(i) => labels.get(*i).cloned().unwrap_or_default(),
            _ => String::new(),
        })
        .draw()
        .map_err(|e| err(&e))?;
    let bar = |i: usize, lo: f64, top: f64, color: RGBAColor| {
        let mut r = Rectangle::new(
            [
                (SegmentValue::Exact(i), lo.max(0.0)),
                (SegmentValue::Exact(i + 1), top.max(0.0)),
            ],
            color.filled(),
        );
        r.set_margin(0, 0, 12, 12);
        r
    };
    let mut bars = vec![bar(0, 0.0, start, RGBColor(120, 120, 120).to_rgba())];
    let mut level = start;
    for (k, s) in steps.iter().enumerate() {
        bars.push(bar(k + 1, s.after, level, Palette99::pick(k).to_rgba()));
        level = s.after;
    }
    bars.push(bar(n - 1, 0.0, level, RGBColor(200, 60, 60).to_rgba()));
    c.draw_series(bars).map_err(|e| err(&e))?;
    // the interval of the level after each step: a whisker across the bar's middle
    let whisker = |k: usize, s: &Drop| {
        PathElement::new(
            vec![
                (SegmentValue::CenterOf(k + 1), s.low.max(0.0)),
                (SegmentValue::CenterOf(k + 1), s.high.max(0.0)),
            ],
            BLACK.stroke_width(2),
        )
    };
    c.draw_series(steps.iter().enumerate().map(|(k, s)| whisker(k, s)))
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}
