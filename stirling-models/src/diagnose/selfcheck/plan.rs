//! The verdict self-check's case plan: every library effect at its strengths, the causes
//! outside the library, and clean records, each on noise seeds split into a tuning set (the
//! verdict thresholds are chosen there) and an evaluation set (never used for tuning).

use serde::Serialize;

use crate::diagnose::{DiagnoseError, DiagnoseOptions};
use crate::effects::{effect, effects_for};
use crate::outside::{outside, OUTSIDE};

/// Which seed set a case belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Split {
    Tune,
    Eval,
}

/// What generated a record.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Truth {
    /// The nominal model alone.
    Clean,
    /// A library effect at `strength` times its self-check unit ([`super::base_strength`]).
    Effect { name: String, strength: f64 },
    /// A cause outside the library at `strength` times its unit ([`crate::outside::OUTSIDE`]).
    Outside { name: String, strength: f64 },
    /// Two library effects at once, each at `strength` times its self-check unit.
    Pair { names: Vec<String>, strength: f64 },
    /// A library effect beside a cause outside the library, each at `strength` times its
    /// unit.
    Mixed {
        effect: String,
        outside: String,
        strength: f64,
    },
}

/// What a verdict label gets when the verdict names effects and says a gap remains that the
/// library does not explain.
pub const REMAINDER: &str = "+remainder";

/// The label of a named set, ending in [`REMAINDER`] when a gap is said to remain.
pub fn named_label(names: &[String], remainder: bool) -> String {
    let tail = if remainder { REMAINDER } else { "" };
    format!("{}{tail}", set_label(names))
}

/// Whether `verdict` is right for `expected`: one of its alternatives (` | `); a named set
/// with a remainder counts as the set unless the alternative asks for the remainder itself.
pub fn is_right(expected: &str, verdict: &str) -> bool {
    expected.split(" | ").any(|e| {
        e == verdict || (!e.ends_with(REMAINDER) && verdict.strip_suffix(REMAINDER) == Some(e))
    })
}

/// The label of a set of named effects: the names in alphabetical order, joined by `+`.
pub fn set_label(names: &[String]) -> String {
    let mut v = names.to_vec();
    v.sort();
    v.join("+")
}

impl Truth {
    /// The row label of the confusion matrix: `clean`, the effect, `outside:NAME`.
    pub fn label(&self) -> String {
        match self {
            Truth::Clean => "clean".into(),
            Truth::Effect { name, .. } => name.clone(),
            Truth::Outside { name, .. } => format!("outside:{name}"),
            Truth::Pair { names, .. } => set_label(names),
            Truth::Mixed {
                effect, outside, ..
            } => format!("{effect}+outside:{outside}"),
        }
    }

    /// The class of the record: `clean`, `single`, `pair`, `outside`, `mixed`.
    pub fn class(&self) -> &'static str {
        match self {
            Truth::Clean => "clean",
            Truth::Effect { .. } => "single",
            Truth::Pair { .. } => "pair",
            Truth::Outside { .. } => "outside",
            Truth::Mixed { .. } => "mixed",
        }
    }

    /// The right verdict: `no_significant_gap`, the effect's name, `unexplained`; beside an
    /// outside cause either `unexplained` or the library effect with the remainder left
    /// unexplained (alternatives joined by ` | `, read by [`is_right`]).
    pub fn expected(&self) -> String {
        match self {
            Truth::Clean => "no_significant_gap".into(),
            Truth::Effect { name, .. } => name.clone(),
            Truth::Outside { .. } => "unexplained".into(),
            Truth::Pair { names, .. } => set_label(names),
            Truth::Mixed { effect, .. } => format!("unexplained | {effect}{REMAINDER}"),
        }
    }

    pub fn strength(&self) -> f64 {
        match self {
            Truth::Clean => 0.0,
            Truth::Effect { strength, .. }
            | Truth::Outside { strength, .. }
            | Truth::Pair { strength, .. }
            | Truth::Mixed { strength, .. } => *strength,
        }
    }
}

/// One planned case: the truth, its seed set, the rig's noise seed and the seed of the
/// starting-parameter perturbation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Planned {
    pub index: usize,
    pub truth: Truth,
    pub split: Split,
    pub seed: u64,
    pub perturb_seed: u64,
}

/// What the verdict self-check runs (`stirling diagnose --self-check`).
#[derive(Clone, Debug)]
pub struct VerdictOptions {
    /// Model of the rig and the diagnosis (`nsection`), sections `n`.
    pub model: String,
    pub n: Option<usize>,
    /// Library effects to withhold (`None`: every effect of the model).
    pub effects: Option<Vec<String>>,
    /// Strengths of the library effects, as multiples of their self-check unit.
    pub strengths: Vec<f64>,
    /// Outside causes (`None`: all of [`OUTSIDE`]; empty: none).
    pub outside: Option<Vec<String>>,
    /// Strengths of the outside causes, as multiples of their unit.
    pub outside_strengths: Vec<f64>,
    /// Every pair of the library effects at this multiple of their units (`None`: no pairs).
    pub pair_strength: Option<f64>,
    /// Every library effect beside every outside cause, each at this multiple of its unit
    /// (`None`: none). These cases come last in the plan, so that adding them leaves every
    /// other case's index (and its seeded start) as it was.
    pub mixed_strength: Option<f64>,
    /// Noise seeds per effect / outside case in the tuning and the evaluation set.
    pub seeds: (usize, usize),
    /// Clean records in the tuning and the evaluation set (each its own seed and start).
    pub clean: (usize, usize),
    pub t_end: f64,
    pub settle: f64,
    pub rate: f64,
    /// First noise seed; the evaluation set's seeds start at `seed + 1000`.
    pub seed: u64,
    /// Largest relative perturbation of kd, kp, bd, bp, hh, hk in the diagnosis's start.
    pub perturb: f64,
    pub channels: Vec<String>,
    pub diagnose: DiagnoseOptions,
    /// Cases run at once (each diagnosis also uses the rayon pool).
    pub jobs: usize,
    /// Only the cases of these truths (their labels, [`Truth::label`]: `leak`,
    /// `end_stops+leak`, `outside:h_speed`, `clean`); `None`: every case. The kept cases keep
    /// their index in the whole plan, so their seeds and starts are those of a full run.
    pub only: Option<Vec<String>>,
    /// Keep every case's record (`case<k>.csv`) and the diagnosis's start
    /// (`case<k>.start.json`, parameters by name) in this directory, so that one case can be
    /// diagnosed again by hand (`stirling diagnose nsection --n 2 --data case<k>.csv --params
    /// case<k>.start.json`); `None`: records are removed once read.
    pub records: Option<std::path::PathBuf>,
}

impl Default for VerdictOptions {
    fn default() -> Self {
        Self {
            model: "nsection".into(),
            n: Some(2),
            effects: None,
            strengths: vec![1.0, 2.0],
            outside: None,
            outside_strengths: vec![1.0],
            pair_strength: Some(1.0),
            mixed_strength: None,
            seeds: (1, 1),
            clean: (10, 20),
            t_end: 2.0,
            settle: 0.1,
            rate: 2000.0,
            seed: 5,
            perturb: 0.08,
            channels: ["p", "x", "y"].map(String::from).to_vec(),
            diagnose: DiagnoseOptions::default(),
            jobs: 2,
            only: None,
            records: None,
        }
    }
}

/// The library effects of the plan (checked against the library).
pub fn effect_names(opts: &VerdictOptions) -> Result<Vec<String>, DiagnoseError> {
    let known = || {
        effects_for(&opts.model)
            .iter()
            .map(|e| e.name)
            .collect::<Vec<_>>()
            .join(", ")
    };
    match &opts.effects {
        None => Ok(effects_for(&opts.model)
            .iter()
            .map(|e| e.name.to_string())
            .collect()),
        Some(v) => {
            if let Some(bad) = v.iter().find(|n| effect(n).is_none()) {
                return Err(DiagnoseError::UnknownEffect {
                    name: bad.clone(),
                    known: known(),
                });
            }
            Ok(v.clone())
        }
    }
}

/// The outside causes of the plan (checked).
pub fn outside_names(opts: &VerdictOptions) -> Result<Vec<String>, DiagnoseError> {
    let names: Vec<String> = match &opts.outside {
        None => OUTSIDE.iter().map(|o| o.name.to_string()).collect(),
        Some(v) => v.clone(),
    };
    if let Some(bad) = names.iter().find(|n| outside(n).is_none()) {
        return Err(DiagnoseError::UnknownEffect {
            name: bad.clone(),
            known: OUTSIDE
                .iter()
                .map(|o| o.name)
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    Ok(names)
}

/// The cases of one seed set: effects x strengths x seeds, outside x strengths x seeds, clean.
fn split_cases(
    opts: &VerdictOptions,
    split: Split,
    effects: &[String],
    outside: &[String],
) -> Vec<(Truth, Split, u64)> {
    let (seeds, clean, base) = match split {
        Split::Tune => (opts.seeds.0, opts.clean.0, opts.seed),
        Split::Eval => (opts.seeds.1, opts.clean.1, opts.seed + 1000),
    };
    let mut out = Vec::new();
    for s in 0..seeds as u64 {
        for name in effects {
            for &m in &opts.strengths {
                out.push((
                    Truth::Effect {
                        name: name.clone(),
                        strength: m,
                    },
                    split,
                    base + s,
                ));
            }
        }
        if let Some(m) = opts.pair_strength {
            for (i, a) in effects.iter().enumerate() {
                for b in &effects[i + 1..] {
                    let names = vec![a.clone(), b.clone()];
                    out.push((Truth::Pair { names, strength: m }, split, base + s));
                }
            }
        }
        for name in outside {
            for &m in &opts.outside_strengths {
                out.push((
                    Truth::Outside {
                        name: name.clone(),
                        strength: m,
                    },
                    split,
                    base + s,
                ));
            }
        }
    }
    // clean records: seeds of their own, after the effect seeds
    out.extend((0..clean as u64).map(|k| (Truth::Clean, split, base + 500 + k)));
    out
}

/// The mixed cases of one seed set: every library effect beside every outside cause.
fn mixed_cases(
    opts: &VerdictOptions,
    split: Split,
    effects: &[String],
    outside: &[String],
) -> Vec<(Truth, Split, u64)> {
    let Some(m) = opts.mixed_strength else {
        return Vec::new();
    };
    let (seeds, base) = match split {
        Split::Tune => (opts.seeds.0, opts.seed),
        Split::Eval => (opts.seeds.1, opts.seed + 1000),
    };
    let mut out = Vec::new();
    for s in 0..seeds as u64 {
        for o in outside {
            for e in effects {
                let truth = Truth::Mixed {
                    effect: e.clone(),
                    outside: o.clone(),
                    strength: m,
                };
                out.push((truth, split, base + s));
            }
        }
    }
    out
}

/// The whole plan, tuning set first, then the mixed cases (tuning, evaluation); every case's
/// start is perturbed by its own seed.
pub fn plan(opts: &VerdictOptions) -> Result<Vec<Planned>, DiagnoseError> {
    let effects = effect_names(opts)?;
    let outside = outside_names(opts)?;
    let mut cases = split_cases(opts, Split::Tune, &effects, &outside);
    let eval = split_cases(opts, Split::Eval, &effects, &outside);
    let mixed = [Split::Tune, Split::Eval].map(|s| mixed_cases(opts, s, &effects, &outside));
    if eval.is_empty() && mixed[1].is_empty() {
        // refused before the tuning set runs, not after it
        return Err(DiagnoseError::EmptyEvaluation);
    }
    cases.extend(eval);
    cases.extend(mixed.into_iter().flatten());
    let all: Vec<Planned> = cases
        .into_iter()
        .enumerate()
        .map(|(index, (truth, split, seed))| Planned {
            index,
            truth,
            split,
            seed,
            perturb_seed: seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ index as u64,
        })
        .collect();
    match &opts.only {
        None => Ok(all),
        Some(only) => keep_only(all, only),
    }
}

/// The cases whose truth is one of `only` (labels, in any order of a set's names); an
/// unknown label is refused with the labels the plan has, and a selection without an
/// evaluation case is refused as an empty evaluation.
fn keep_only(all: Vec<Planned>, only: &[String]) -> Result<Vec<Planned>, DiagnoseError> {
    let canon = |l: &str| {
        let names: Vec<String> = l.split('+').map(|s| s.trim().to_string()).collect();
        set_label(&names)
    };
    let wanted: Vec<String> = only.iter().map(|l| canon(l)).collect();
    let mut labels: Vec<String> = Vec::new();
    for l in all.iter().map(|c| c.truth.label()) {
        if !labels.contains(&l) {
            labels.push(l);
        }
    }
    if let Some(bad) = wanted
        .iter()
        .find(|w| !labels.iter().any(|l| canon(l) == **w))
    {
        return Err(DiagnoseError::UnknownCase {
            label: bad.clone(),
            known: labels.join(", "),
        });
    }
    let kept: Vec<Planned> = all
        .into_iter()
        .filter(|c| wanted.contains(&canon(&c.truth.label())))
        .collect();
    if !kept.iter().any(|c| c.split == Split::Eval) {
        return Err(DiagnoseError::EmptyEvaluation);
    }
    Ok(kept)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_plan_meets_the_issue() {
        let p = plan(&VerdictOptions::default()).unwrap();
        let n = |f: &dyn Fn(&Planned) -> bool| p.iter().filter(|c| f(c)).count();
        assert!(p.len() >= 40, "{} records", p.len());
        assert_eq!(
            n(&|c| c.truth == Truth::Clean && c.split == Split::Eval),
            20
        );
        assert!(n(&|c| matches!(c.truth, Truth::Outside { .. })) >= 4);
        // distinct seeds and starts on the clean records
        let mut seeds: Vec<u64> = p
            .iter()
            .filter(|c| c.truth == Truth::Clean)
            .map(|c| c.seed)
            .collect();
        let mut starts: Vec<u64> = p.iter().map(|c| c.perturb_seed).collect();
        let (ls, lp) = (seeds.len(), starts.len());
        seeds.dedup();
        starts.sort();
        starts.dedup();
        assert_eq!((seeds.len(), starts.len()), (ls, lp));
        // the two seed sets share no seed
        let tune: Vec<u64> = p
            .iter()
            .filter(|c| c.split == Split::Tune)
            .map(|c| c.seed)
            .collect();
        assert!(p
            .iter()
            .filter(|c| c.split == Split::Eval)
            .all(|c| !tune.contains(&c.seed)));
    }

    #[test]
    fn mixed_cases_come_last_and_leave_the_others_as_they_were() {
        let base = plan(&VerdictOptions::default()).unwrap();
        let with = plan(&VerdictOptions {
            mixed_strength: Some(1.0),
            ..Default::default()
        })
        .unwrap();
        assert_eq!(&with[..base.len()], &base[..]);
        let mixed = &with[base.len()..];
        // every library effect beside every outside cause, on both seed sets
        assert_eq!(mixed.len(), 2 * 6 * OUTSIDE.len());
        assert!(mixed.iter().all(|c| c.truth.class() == "mixed"));
        let c = &mixed[mixed.len() - 1];
        assert_eq!(c.split, Split::Eval);
        assert_eq!(c.truth.label(), "sensor_gain+outside:spring_cubic");
        let e = c.truth.expected();
        assert!(is_right(&e, "unexplained"));
        assert!(is_right(&e, "sensor_gain+remainder"));
        assert!(!is_right(&e, "sensor_gain"), "explained away");
        assert!(!is_right(&e, "coulomb+sensor_gain+remainder"));
        // a named set with a remainder is the set for the other classes
        assert!(is_right("leak", "leak+remainder"));
        assert!(!is_right("leak", "coulomb+leak"));
    }

    #[test]
    fn an_empty_evaluation_set_is_refused_up_front() {
        let o = VerdictOptions {
            seeds: (1, 0),
            clean: (2, 0),
            ..Default::default()
        };
        assert!(matches!(plan(&o), Err(DiagnoseError::EmptyEvaluation)));
    }

    #[test]
    fn unknown_names_are_errors() {
        let o = VerdictOptions {
            outside: Some(vec!["bounce".into()]),
            ..Default::default()
        };
        assert!(plan(&o).unwrap_err().to_string().contains("bounce"));
    }

    #[test]
    fn cases_picks_truths_by_label_and_keeps_their_seeds() {
        let all = plan(&VerdictOptions::default()).unwrap();
        let only = plan(&VerdictOptions {
            only: Some(vec!["leak+end_stops".into(), "clean".into()]),
            ..Default::default()
        })
        .unwrap();
        assert!(only
            .iter()
            .all(|c| ["end_stops+leak", "clean"].contains(&c.truth.label().as_str())));
        assert_eq!(only.iter().filter(|c| c.truth == Truth::Clean).count(), 30);
        assert_eq!(only.len(), 32);
        for c in &only {
            assert_eq!(&all[c.index], c, "case {} moved", c.index);
        }
    }

    #[test]
    fn cases_refuses_an_unknown_label_and_an_empty_evaluation() {
        let e = plan(&VerdictOptions {
            only: Some(vec!["leak+leak".into()]),
            ..Default::default()
        })
        .unwrap_err();
        assert!(matches!(e, DiagnoseError::UnknownCase { .. }), "{e}");
        assert!(e.to_string().contains("end_stops+leak"), "{e}");
        let e = plan(&VerdictOptions {
            only: Some(vec!["leak".into()]),
            seeds: (1, 0),
            ..Default::default()
        })
        .unwrap_err();
        assert!(matches!(e, DiagnoseError::EmptyEvaluation), "{e}");
    }
}
