//! A two-parameter sweep as a map: each cell coloured by the limit cycle's power where the
//! engine runs (light to dark red), grey where it stays at rest, blue where it is unstable
//! at rest but no cycle with positive work was found, black where the point failed; the
//! stability boundary (rest stable on one side, unstable on the other) drawn between cells.

use std::path::Path;

use plotters::prelude::*;

use super::{axes, DrawError};

/// One cell: its outcome and, where the engine runs, its power (W).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cell {
    Runs(f64),
    Stable,
    UnstableNoCycle,
    Failed,
}

/// The map: `cells[i][j]` at `(xs[i], ys[j])`, with each axis's label (name and unit).
pub struct Map<'a> {
    pub xs: &'a [f64],
    pub ys: &'a [f64],
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub cells: &'a [Vec<Cell>],
}

/// Light yellow to dark red over `t` in [0, 1].
fn heat(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let mix = |a: f64, b: f64| (a + (b - a) * t).round() as u8;
    RGBColor(mix(255.0, 140.0), mix(237.0, 10.0), mix(160.0, 10.0))
}

/// The colour of a cell, power scaled by `pmax`.
fn color(c: Cell, pmax: f64) -> RGBColor {
    match c {
        Cell::Runs(p) => heat(p / pmax.max(1e-300)),
        Cell::Stable => RGBColor(200, 200, 200),
        Cell::UnstableNoCycle => RGBColor(110, 150, 230),
        Cell::Failed => BLACK,
    }
}

/// Cell edges around the values `v` (midpoints; the ends half a step out).
fn edges(v: &[f64]) -> Vec<f64> {
    let n = v.len();
    if n == 1 {
        let h = (0.05 * v[0].abs()).max(0.5);
        return vec![v[0] - h, v[0] + h];
    }
    let mut e = vec![v[0] - 0.5 * (v[1] - v[0])];
    e.extend(v.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    e.push(v[n - 1] + 0.5 * (v[n - 1] - v[n - 2]));
    e
}

/// Draw the map to `path` (SVG).
pub fn sweep_map(path: &Path, title: &str, m: &Map) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let (ex, ey) = (edges(m.xs), edges(m.ys));
    let pmax = m
        .cells
        .iter()
        .flatten()
        .filter_map(|c| match c {
            Cell::Runs(p) => Some(*p),
            _ => None,
        })
        .fold(0.0f64, f64::max);
    let root = SVGBackend::new(path, (900, 640)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let caption = format!("{title} (power: 0 to {pmax:.3} W, light to dark)");
    let mut c = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(ex[0]..ex[ex.len() - 1], ey[0]..ey[ey.len() - 1])
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .disable_mesh()
        .x_desc(m.x_label)
        .y_desc(m.y_label)
        .x_label_formatter(&axes::linear_ticks(ex[ex.len() - 1] - ex[0]))
        .y_label_formatter(&axes::linear_ticks(ey[ey.len() - 1] - ey[0]))
        .draw()
        .map_err(|e| err(&e))?;
    let rects = m.cells.iter().enumerate().flat_map(|(i, row)| {
        let (ex, ey) = (&ex, &ey);
        row.iter().enumerate().map(move |(j, &cell)| {
            let fill = color(cell, pmax).filled();
            Rectangle::new([(ex[i], ey[j]), (ex[i + 1], ey[j + 1])], fill)
        })
    });
    c.draw_series(rects).map_err(|e| err(&e))?;
    c.draw_series(
        boundary(m, &ex, &ey)
            .into_iter()
            .map(|seg| PathElement::new(seg, BLACK.stroke_width(3))),
    )
    .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}

/// Whether a cell is unstable at rest (`None`: failed, no side).
fn unstable(c: Cell) -> Option<bool> {
    match c {
        Cell::Runs(_) | Cell::UnstableNoCycle => Some(true),
        Cell::Stable => Some(false),
        Cell::Failed => None,
    }
}

/// The segments between neighbouring cells on opposite sides of the stability boundary.
fn boundary(m: &Map, ex: &[f64], ey: &[f64]) -> Vec<Vec<(f64, f64)>> {
    let mut segs = Vec::new();
    let differ =
        |a: Cell, b: Cell| matches!((unstable(a), unstable(b)), (Some(x), Some(y)) if x != y);
    for (i, row) in m.cells.iter().enumerate() {
        for (j, &cell) in row.iter().enumerate() {
            if i + 1 < m.cells.len() && differ(cell, m.cells[i + 1][j]) {
                segs.push(vec![(ex[i + 1], ey[j]), (ex[i + 1], ey[j + 1])]);
            }
            if j + 1 < row.len() && differ(cell, row[j + 1]) {
                segs.push(vec![(ex[i], ey[j + 1]), (ex[i + 1], ey[j + 1])]);
            }
        }
    }
    segs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_boundary_separates_stable_from_unstable_cells() {
        let cells = vec![
            vec![Cell::Stable, Cell::Stable],
            vec![Cell::Stable, Cell::Runs(1.0)],
        ];
        let m = Map {
            xs: &[0.0, 1.0],
            ys: &[0.0, 1.0],
            x_label: "a",
            y_label: "b",
            cells: &cells,
        };
        let (ex, ey) = (edges(m.xs), edges(m.ys));
        assert_eq!(ex, vec![-0.5, 0.5, 1.5]);
        // the running cell (1, 1) borders (0, 1) and (1, 0): two segments
        let segs = boundary(&m, &ex, &ey);
        assert_eq!(segs.len(), 2, "{segs:?}");
    }
}
