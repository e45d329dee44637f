//! Sensor offsets, estimated from the data: a position sensor reads `q + offset`; the
//! equilibrium position is the mean over whole cycles of the motion (for a symmetric
//! oscillation about rest), so that mean is removed. The pressure offset is left to the fit
//! (a free parameter `p_offset`, see [`crate::fit`]).

/// Offsets removed from the position channels.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct PositionOffsets {
    pub x: f64,
    pub y: f64,
}

/// Mean of `v` over whole cycles: between its first and last upward crossings of its median
/// (the whole record when fewer than two crossings).
pub fn cycle_mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let med = s[s.len() / 2];
    let ups: Vec<usize> = (1..v.len())
        .filter(|&i| v[i - 1] < med && v[i] >= med)
        .collect();
    let (a, b) = if ups.len() >= 2 {
        (ups[0], ups[ups.len() - 1])
    } else {
        (0, v.len())
    };
    v[a..b].iter().sum::<f64>() / (b - a) as f64
}

/// Remove the whole-cycle mean from `x` and `y`; returns the offsets removed.
pub fn remove_position_offsets(m: &mut super::Measured) -> PositionOffsets {
    let mut out = PositionOffsets::default();
    if let Some(x) = m.x.as_mut() {
        out.x = cycle_mean(x);
        x.iter_mut().for_each(|v| *v -= out.x);
    }
    if let Some(y) = m.y.as_mut() {
        out.y = cycle_mean(y);
        y.iter_mut().for_each(|v| *v -= out.y);
    }
    out
}
