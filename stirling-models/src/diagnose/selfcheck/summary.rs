//! The confusion matrix of a self-check: truth by verdict, as a table the user reads.

use std::time::Instant;

use super::{Case, SelfCheck};

/// The confusion matrix of `cases` over the effects `names`.
pub(super) fn summarize(
    model: String,
    cases: Vec<Case>,
    names: &[String],
    clock: Instant,
) -> SelfCheck {
    let mut labels = vec!["none".to_string()];
    labels.extend(names.iter().cloned());
    let mut columns: Vec<String> = names.to_vec();
    columns.push("unexplained".into());
    columns.push("no_significant_gap".into());
    let mut matrix = vec![vec![0usize; columns.len()]; labels.len()];
    for c in &cases {
        let r = labels.iter().position(|l| l == &c.truth).expect("label");
        let col = columns
            .iter()
            .position(|l| l == &c.verdict)
            .unwrap_or(columns.len() - 2);
        matrix[r][col] += 1;
    }
    let clean: Vec<&Case> = cases.iter().filter(|c| c.truth == "none").collect();
    SelfCheck {
        model,
        passed: cases.iter().filter(|c| c.pass).count(),
        total: cases.len(),
        clean: clean.len(),
        false_alarms: clean
            .iter()
            .filter(|c| c.verdict != "no_significant_gap" && c.verdict != "unexplained")
            .count(),
        cases,
        labels,
        matrix,
        columns,
        seconds: clock.elapsed().as_secs_f64(),
    }
}

/// The confusion matrix as a Markdown table.
pub fn matrix_markdown(sc: &SelfCheck) -> String {
    let mut s = format!(
        "| truth \\ verdict | {} |\n|---|{}\n",
        sc.columns.join(" | "),
        "---|".repeat(sc.columns.len())
    );
    for (l, row) in sc.labels.iter().zip(&sc.matrix) {
        s += &format!(
            "| {l} | {} |\n",
            row.iter()
                .map(|v| v.to_string())
                .collect::<Vec<_>>()
                .join(" | ")
        );
    }
    s
}
