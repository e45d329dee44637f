//! The score screen of one candidate: the score test at the effect's null on the joint problem
//! ([`crate::diagnose::joint`], [`crate::diagnose::score`]). Shape parameters (the end stops'
//! travel) are inert at a zero strength, so the score test cannot see them (Davies' problem): it is
//! taken at a grid of travels (fractions of the recorded excursion), the largest statistic kept
//! with a Bonferroni factor, and the joint fit starts from that travel with the travel free.

use super::context::Context;
use super::joint::{Basis, EffectAt, EffectVar, Joint};
use super::score::{robust_score, Score};
use super::types::Assessed;
use super::types::RankEntry;
use super::DiagnoseError;
use crate::effects::EffectInfo;
use crate::fit::FittedStage;

/// Travel grid of the end stops, as fractions of the recorded excursion.
const TRAVEL_GRID: [f64; 4] = [0.6, 0.75, 0.9, 1.0];

/// Shape settings to screen: one empty setting, or the travel grid.
fn shape_grid(ctx: &Context, e: &EffectInfo) -> Vec<Vec<(&'static str, f64)>> {
    let travel: Vec<(&'static str, f64)> = [("xmax", "x"), ("ymax", "y")]
        .into_iter()
        .filter(|(q, _)| e.params.iter().any(|p| p.name == *q))
        .filter_map(|(q, ch)| ctx.excursion(ch).map(|a| (q, a)))
        .collect();
    if travel.is_empty() {
        return vec![vec![]];
    }
    if ctx.restarted && !ctx.held_travels.is_empty() {
        return vec![held_setting(ctx, &travel)];
    }
    if ctx.restarted {
        return body_grid(&travel);
    }
    TRAVEL_GRID
        .iter()
        .map(|f| travel.iter().map(|(q, a)| (*q, f * a)).collect())
        .collect()
}

/// Travels of a body's end stops on the restarted pass's grid, as fractions of its recorded
/// excursion: stops that clip a record sit just inside the largest travel it shows.
const BODY_TRAVELS: [f64; 2] = [0.9, 1.0];

/// A travel this many times the recorded excursion: stops the record never reaches.
const INERT_TRAVEL: f64 = 5.0;

/// The restarted pass's grid: each body's stops at every travel of [`BODY_TRAVELS`] or out
/// of its reach ([`INERT_TRAVEL`]), every body on its own (stops that clip the piston need
/// not clip the displacer: one travel for both tests the displacer clipped where it ran
/// free, and the score of such a setting points away from the stops); every body out of
/// reach is the null, not a setting.
fn body_grid(travel: &[(&'static str, f64)]) -> Vec<Vec<(&'static str, f64)>> {
    let mut grid: Vec<Vec<(&'static str, f64)>> = vec![vec![]];
    for &(q, a) in travel {
        let options: Vec<f64> = std::iter::once(INERT_TRAVEL)
            .chain(BODY_TRAVELS)
            .map(|f| f * a)
            .collect();
        grid = grid
            .into_iter()
            .flat_map(|g| {
                options.iter().map(move |&v| {
                    let mut g = g.clone();
                    g.push((q, v));
                    g
                })
            })
            .collect();
    }
    grid.retain(|g| {
        g.iter()
            .zip(travel)
            .any(|((_, v), (_, a))| *v < INERT_TRAVEL * a)
    });
    grid
}

/// The restarted pass's one setting when travels were seen in the measured acceleration:
/// those travels, every other body's stops out of its reach ([`INERT_TRAVEL`]).
fn held_setting(ctx: &Context, travel: &[(&'static str, f64)]) -> Vec<(&'static str, f64)> {
    travel
        .iter()
        .map(|&(q, a)| {
            let held = ctx.held_travels.iter().find(|(h, _)| *h == q);
            (q, held.map_or(INERT_TRAVEL * a, |h| h.1))
        })
        .collect()
}

/// Whether an effect has end-stop travels (shape parameters screened on a grid).
pub fn has_travel(e: &EffectInfo) -> bool {
    e.params
        .iter()
        .any(|p| p.name == "xmax" || p.name == "ymax")
}

/// The score test of `joint` at its start.
fn screen(ctx: &Context, joint: &Joint, u0: &[f64]) -> Result<Score, DiagnoseError> {
    let (r, j, blocks) = joint.residuals(u0)?;
    // the candidate's strengths are tested; its shapes are inert at the null; the accepted
    // effects' variables are nuisances like the nominal ones
    let strengths: Vec<&EffectVar> = joint.candidate().filter(|v| !v.shape).collect();
    let test: Vec<usize> = strengths.iter().map(|v| v.index).collect();
    let skip: Vec<usize> = joint
        .candidate()
        .filter(|v| v.shape)
        .map(|v| v.index)
        .collect();
    let bounded: Vec<bool> = strengths.iter().map(|v| v.bounded).collect();
    let noise = joint.noise_draws(&ctx.input_noise);
    Ok(robust_score(
        &r, &j, &test, &skip, &bounded, &blocks, ctx.lag, &noise,
    ))
}

/// A candidate after its score screen.
pub struct Screened {
    pub effect: &'static EffectInfo,
    pub score: Option<Score>,
    /// The shape setting (end-stop travels) with the largest statistic.
    pub shapes: Vec<(&'static str, f64)>,
    pub entry: RankEntry,
    /// Seconds of one evaluation of the joint problem (the screen's mean), for scheduling.
    pub eval_seconds: f64,
}

impl Screened {
    /// Whether the screen found the effect significant at `level`.
    pub fn significant(&self, level: f64) -> bool {
        self.entry.p_value < level
    }

    /// The candidate left unfitted, with the reason.
    pub fn unfitted(mut self, why: &str) -> Assessed {
        if self.entry.note.is_none() {
            self.entry.note = Some(why.into());
        }
        Assessed {
            entry: self.entry,
            eval: None,
            fit: None,
        }
    }
}

fn empty_entry(e: &EffectInfo) -> RankEntry {
    RankEntry::named(e.name)
}

/// The score screen of one candidate (over the travel grid for the end stops), at the
/// optimum of `basis` (the nominal calibration and the effects accepted so far).
pub fn screen_candidate(
    ctx: &Context,
    nominal: &[FittedStage],
    s2: &[f64],
    basis: &Basis,
    e: &'static EffectInfo,
) -> Screened {
    let clock = std::time::Instant::now();
    let mut entry = empty_entry(e);
    let grid = shape_grid(ctx, e);
    let mut best: Option<(Score, Vec<(&'static str, f64)>)> = None;
    for shapes in &grid {
        let cand = [EffectAt {
            effect: e,
            shapes: shapes.clone(),
        }];
        let sc = Joint::new(ctx.model, nominal, s2, basis, &cand, false)
            .and_then(|joint| screen(ctx, &joint, &joint.start()));
        match sc {
            Ok(sc) if best.as_ref().is_none_or(|(b, _)| sc.stat > b.stat) => {
                best = Some((sc, shapes.clone()))
            }
            Ok(_) => {}
            Err(e) => entry.note = Some(e.to_string()),
        }
    }
    let (score, shapes) = match best {
        Some((sc, shapes)) => (Some(sc), shapes),
        None => (None, Vec::new()),
    };
    if let Some(sc) = &score {
        entry.score = sc.stat;
        entry.dof = sc.dof;
        entry.p_value = (sc.p_value * grid.len() as f64).min(1.0);
        entry.note = (grid.len() > 1).then(|| {
            format!(
                "score: largest over {} end-stop travels (Bonferroni factor {})",
                grid.len(),
                grid.len()
            )
        });
    }
    entry.seconds = clock.elapsed().as_secs_f64();
    Screened {
        effect: e,
        score,
        shapes,
        eval_seconds: entry.seconds / grid.len().max(1) as f64,
        entry,
    }
}

/// The joint score test of a set of candidates (a pair tried together) on `basis`, at the
/// shape settings their single screens chose.
pub fn screen_set(
    ctx: &Context,
    nominal: &[FittedStage],
    s2: &[f64],
    basis: &Basis,
    cands: &[EffectAt],
) -> Result<Score, DiagnoseError> {
    let joint = Joint::new(ctx.model, nominal, s2, basis, cands, false)?;
    screen(ctx, &joint, &joint.start())
}
