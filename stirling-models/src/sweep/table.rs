//! A sweep's results as CSV: one row per point, the swept values first, empty cells where
//! a figure does not exist (no cycle, a failed point).

use super::Sweep;

/// The CSV text of `s` (header, then one row per point in grid order).
pub fn csv(s: &Sweep) -> String {
    let mut out: Vec<String> = s.axes.iter().map(|a| a.name.clone()).collect();
    out.extend(
        [
            "outcome",
            "rhp",
            "growth_rate_1_s",
            "pole_hz",
            "frequency_hz",
            "x_stroke_m",
            "y_stroke_m",
            "phase_deg",
            "work_j",
            "power_w",
            "error",
        ]
        .map(String::from),
    );
    let mut text = out.join(",") + "\n";
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.10e}"));
    for r in &s.points {
        let mut row: Vec<String> = r.values.iter().map(|v| format!("{v:.10e}")).collect();
        let outcome = serde_json::to_value(r.outcome)
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_default();
        row.push(outcome);
        row.push(r.rhp.map_or(String::new(), |k| k.to_string()));
        for v in [
            r.growth_rate,
            r.pole_hz,
            r.frequency_hz,
            r.x_stroke,
            r.y_stroke,
            r.phase_deg,
            r.work_j,
            r.power_w,
        ] {
            row.push(opt(v));
        }
        // the error as one quoted CSV field
        row.push(r.error.as_ref().map_or(String::new(), |e| {
            format!("\"{}\"", e.replace('"', "'").replace('\n', " "))
        }));
        text += &(row.join(",") + "\n");
    }
    text
}
