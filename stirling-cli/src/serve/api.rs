//! The endpoints: the bond graph (SVG), the linear analysis (poles, the broken loop's Bode
//! data and margins, as `stirling linearize`), the limit cycle (as `simulate --limit-cycle`).

use serde_json::json;
use stirling_dsl::{bond, Model, StateKind};
use stirling_models::linear::{self, LinearOptions};
use stirling_models::sim::{self, SimOptions};

use super::query::Query;
use super::Reply;

/// Simulated time the limit cycle may take to settle (s): keeps a request short.
pub const CYCLE_T_MAX: f64 = 10.0;

/// Samples of the settling run kept (the orbit has its own uniform samples).
const SETTLE_SAMPLES: usize = 200;

/// The family members the page offers.
pub fn models() -> Reply {
    json_reply(
        &json!({ "models": ["schmidt", "cv1", "cv2", "nsection"], "max_n": super::query::MAX_N }),
    )
}

/// `GET /api/graph`: the bond graph as SVG (`stirling info MODEL --graph --svg`).
pub fn graph(q: &Query) -> Reply {
    let (model, _) = match q.load() {
        Ok(m) => m,
        Err(e) => return Reply::error(400, e),
    };
    match bond::bond_graph(model.as_ref()) {
        Ok(g) => Reply {
            status: 200,
            content_type: "image/svg+xml",
            body: g.to_svg(),
        },
        Err(e) => Reply::error(422, format!("bond graph of `{}`: {e}", model.name())),
    }
}

/// `GET /api/linear`: the report of `stirling linearize --json` and the Bode data of the
/// broken loop.
pub fn linear(q: &Query) -> Reply {
    let (model, p) = match q.load() {
        Ok(m) => m,
        Err(e) => return Reply::error(400, e),
    };
    match linear::linearize(model.as_ref(), &p, &LinearOptions::default()) {
        Ok(lin) => json_reply(&json!({
            "report": lin.report(model.as_ref()),
            "bode": lin.bode(),
        })),
        Err(e) => Reply::error(422, format!("linearizing `{}`: {e}", model.name())),
    }
}

/// `GET /api/cycle`: the limit cycle (one period of positions, p-V loops, work and power).
pub fn cycle(q: &Query) -> Reply {
    let (model, p) = match q.load() {
        Ok(m) => m,
        Err(e) => return Reply::error(400, e),
    };
    let m = model.as_ref();
    let Some(x0) = start(m, &p) else {
        return Reply::error(422, format!("`{}` has no displacer position", m.name()));
    };
    let samples = sim::uniform_samples(CYCLE_T_MAX, SETTLE_SAMPLES);
    let opts = SimOptions::default();
    let lc = match sim::limit_cycle_with(
        m,
        &p,
        &x0,
        CYCLE_T_MAX,
        &samples,
        &opts,
        sim::Shooting::Auto,
        None,
    ) {
        Ok(lc) => lc,
        Err(e) => {
            return Reply::error(
                422,
                format!(
                    "no limit cycle of `{}` within {CYCLE_T_MAX} s: {e}",
                    m.name()
                ),
            )
        }
    };
    let column = |k: StateKind| -> Vec<f64> {
        let i = m.states().iter().position(|s| s.kind == k);
        i.map_or_else(Vec::new, |i| lc.orbit.iter().map(|x| x[i]).collect())
    };
    let f = &lc.figures;
    json_reply(&json!({
        "period_s": f.period,
        "frequency_hz": f.frequency_hz,
        "x_amp": f.x_amp,
        "y_amp": f.y_amp,
        "phase_deg": f.phase_deg,
        "work_j": lc.work.total,
        "power_w": sim::indicated_power(lc.work.total, f.frequency_hz),
        "x": column(StateKind::Position(0)),
        "y": column(StateKind::Position(1)),
        "vessels": lc.work.vessels,
        "vessel_work_j": lc.work.per_vessel,
        "pv": sim::work::pv_loops(m, &p, &lc.orbit),
    }))
}

/// The start of the settling run: the equilibrium guess with the displacer moved 5 mm (the
/// default of `stirling simulate`).
fn start(m: &dyn Model, p: &[f64]) -> Option<Vec<f64>> {
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(p, &mut x);
    let i = m
        .states()
        .iter()
        .position(|s| s.kind == StateKind::Position(0))?;
    x[i] += 5e-3;
    Some(x)
}

pub(super) fn json_reply(v: &serde_json::Value) -> Reply {
    Reply {
        status: 200,
        content_type: "application/json",
        body: v.to_string(),
    }
}
