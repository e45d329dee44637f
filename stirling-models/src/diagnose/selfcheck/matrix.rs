//! The confusion matrix of verdicts: rows the truth (`clean`, each effect, `outside:*`),
//! columns the verdicts (each effect, `unexplained`, `no_significant_gap`, and `error` when
//! a case failed to run), with the accuracy and the false-alarm rate on clean records.

use serde::Serialize;

use super::plan::is_right;

/// Verdict counts by truth.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Confusion {
    pub rows: Vec<String>,
    pub columns: Vec<String>,
    /// `counts[row][column]`.
    pub counts: Vec<Vec<usize>>,
    /// Cases whose verdict is the expected one.
    pub right: usize,
    pub total: usize,
    /// Clean records, and those whose verdict is not `no_significant_gap` (any verdict
    /// naming a gap is an alarm on a clean record).
    pub clean: usize,
    pub false_alarms: usize,
    /// Per class of record (`single`, `pair`, `outside`, `clean`): right and total.
    pub classes: Vec<(String, usize, usize)>,
}

/// The class of a truth label: `clean`, `outside` (`outside:NAME`), `pair` (`a+b`),
/// `single`.
pub fn class_of(label: &str) -> &'static str {
    if label == "clean" {
        "clean"
    } else if label.contains("+outside:") {
        "mixed"
    } else if label.starts_with("outside:") {
        "outside"
    } else if label.contains('+') {
        "pair"
    } else {
        "single"
    }
}

impl Confusion {
    /// The matrix of `(truth label, expected verdict, verdict)` triples; `effects` fixes the
    /// order of the effect rows and columns (rows and columns not in it are appended as met).
    pub fn of(cases: &[(String, String, String)], effects: &[String]) -> Self {
        let mut rows = vec!["clean".to_string()];
        rows.extend(effects.iter().cloned());
        let mut columns: Vec<String> = effects.to_vec();
        columns.extend(["unexplained", "no_significant_gap"].map(String::from));
        for (t, _, v) in cases {
            if !rows.contains(t) {
                rows.push(t.clone());
            }
            if !columns.contains(v) {
                columns.push(v.clone());
            }
        }
        let mut counts = vec![vec![0; columns.len()]; rows.len()];
        for (t, _, v) in cases {
            let r = rows.iter().position(|x| x == t).unwrap_or(0);
            let c = columns.iter().position(|x| x == v).unwrap_or(0);
            counts[r][c] += 1;
        }
        let clean: Vec<_> = cases.iter().filter(|(t, _, _)| t == "clean").collect();
        let classes = ["single", "pair", "outside", "mixed", "clean"]
            .iter()
            .map(|k| {
                let of: Vec<_> = cases.iter().filter(|(t, _, _)| class_of(t) == *k).collect();
                let right = of.iter().filter(|(_, e, v)| is_right(e, v)).count();
                (k.to_string(), right, of.len())
            })
            .filter(|(_, _, n)| *n > 0)
            .collect();
        Confusion {
            classes,
            rows,
            columns,
            counts,
            right: cases.iter().filter(|(_, e, v)| is_right(e, v)).count(),
            total: cases.len(),
            clean: clean.len(),
            false_alarms: clean
                .iter()
                .filter(|(_, _, v)| v != "no_significant_gap")
                .count(),
        }
    }

    /// Fraction of right verdicts (NaN without cases).
    pub fn accuracy(&self) -> f64 {
        self.right as f64 / self.total as f64
    }

    /// Fraction of clean records with an alarm (NaN without clean records).
    pub fn false_alarm_rate(&self) -> f64 {
        self.false_alarms as f64 / self.clean as f64
    }

    /// The matrix as a Markdown table (rows without cases are left out).
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "| truth \\ verdict | {} |\n|---|{}\n",
            self.columns.join(" | "),
            "---|".repeat(self.columns.len())
        );
        for (l, row) in self.rows.iter().zip(&self.counts) {
            if row.iter().sum::<usize>() == 0 {
                continue;
            }
            let cells: Vec<String> = row.iter().map(|v| v.to_string()).collect();
            s += &format!("| {l} | {} |\n", cells.join(" | "));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(truth: &str, expected: &str, verdict: &str) -> (String, String, String) {
        (truth.into(), expected.into(), verdict.into())
    }

    #[test]
    fn counts_accuracy_and_false_alarms() {
        let effects = vec!["coulomb".to_string(), "leak".to_string()];
        let cases = vec![
            t("clean", "no_significant_gap", "no_significant_gap"),
            t("clean", "no_significant_gap", "coulomb"),
            t("clean", "no_significant_gap", "unexplained"),
            t("clean", "no_significant_gap", "no_significant_gap"),
            t("coulomb", "coulomb", "coulomb"),
            t("leak", "leak", "coulomb"),
            t("outside:h_speed", "unexplained", "unexplained"),
            t("outside:h_speed", "unexplained", "error"),
        ];
        let m = Confusion::of(&cases, &effects);
        assert_eq!(m.rows, ["clean", "coulomb", "leak", "outside:h_speed"]);
        assert_eq!(
            m.columns,
            [
                "coulomb",
                "leak",
                "unexplained",
                "no_significant_gap",
                "error"
            ]
        );
        assert_eq!(m.counts[0], [1, 0, 1, 2, 0]);
        assert_eq!(m.counts[1], [1, 0, 0, 0, 0]);
        assert_eq!(m.counts[2], [1, 0, 0, 0, 0]);
        assert_eq!(m.counts[3], [0, 0, 1, 0, 1]);
        assert_eq!((m.right, m.total), (4, 8));
        // an `unexplained` on a clean record is an alarm too: it says there is a gap
        assert_eq!((m.clean, m.false_alarms), (4, 2));
        assert_eq!(m.accuracy(), 0.5);
        assert_eq!(m.false_alarm_rate(), 0.5);
        let md = m.markdown();
        assert!(md.contains("| clean | 1 | 0 | 1 | 2 | 0 |"), "{md}");
        assert!(
            md.contains("| outside:h_speed | 0 | 0 | 1 | 0 | 1 |"),
            "{md}"
        );
    }

    #[test]
    fn empty_rows_are_left_out_of_the_table() {
        let m = Confusion::of(
            &[t("coulomb", "coulomb", "coulomb")],
            &["coulomb".into(), "leak".into()],
        );
        let md = m.markdown();
        // the header names every column; no row starts with an empty truth
        let row = |l: &str| md.lines().any(|x| x.starts_with(&format!("| {l} |")));
        assert!(row("coulomb") && !row("leak") && !row("clean"), "{md}");
        assert!(m.false_alarm_rate().is_nan());
    }
}
