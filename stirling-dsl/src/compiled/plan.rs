//! The symbolic program of one closure: every output of every function the [`crate::Model`]
//! trait asks for, as expressions in the model's arena, before `n` is known. The outputs
//! and their derivatives are chosen by the same functions as the emitted code's
//! ([`crate::codegen::rows::outputs`], [`crate::codegen::sums`]), so the tape computes the
//! same expressions as the macro's Rust.

use crate::codegen::rows::{outputs, Output, RowOutput};
use crate::codegen::sums::{chains, gradient_sums, Chain};
use crate::expr::{Arena, Id, Sym};
use crate::topology::{Row, SensorDecl, System};

/// The outputs of a function of the rows (right-hand side, Jacobians, equilibrium guess).
pub(crate) struct Rows {
    /// Of the scalar rows, in their own frame (`Sym::Sum(k)` for a sum over the sections).
    pub scalar: Vec<RowOutput>,
    /// Of the array rows, per section variant (single, first, interior, last), in the
    /// section's frame.
    pub arrays: [Vec<RowOutput>; 4],
    /// The scalar rows' entries in the sections' columns through the sums (state Jacobian
    /// only): `(row's block, chain)`.
    pub chains: Vec<(usize, Chain)>,
}

/// An expression sensor's output and its gradient.
pub(crate) struct SensorPlan {
    pub value: Id,
    /// `d value / d read_i`, in read order.
    pub dv: Vec<Id>,
    /// `(k, d value / d p_k)` for the parameters it names.
    pub dp: Vec<(usize, Id)>,
}

/// One closure's program.
pub(crate) struct Plan {
    pub sys: System,
    /// The templates of every `Sym::Sum(k)`: the system's sums, then the sums of the
    /// derivatives the Jacobians' chain rule needs.
    pub sums: Vec<Id>,
    pub rhs: Rows,
    pub jac: Rows,
    pub pjac: Rows,
    pub init: Rows,
    /// Per body: `(state column, dF_k/dx)` of its pressure force.
    pub force_grads: Vec<Vec<(Sym, Id)>>,
}

impl Plan {
    /// The program of `sys` (assembled from `topo`), its derivatives added to `arena`.
    pub(crate) fn new(arena: &mut Arena, sys: System) -> Plan {
        let mut sums = sys.sums.clone();
        let own = &sys.sums;
        let rhs = rows(arena, &sys.rows, Output::Value, own, &mut sums);
        let jac = rows(arena, &sys.rows, Output::StateJacobian, own, &mut sums);
        let pjac = rows(arena, &sys.rows, Output::ParamJacobian, own, &mut sums);
        let init = rows(arena, &sys.init, Output::Value, own, &mut sums);
        let force_grads = force_gradients(arena, &sys.forces);
        Plan {
            sys,
            sums,
            rhs,
            jac,
            pjac,
            init,
            force_grads,
        }
    }
}

/// The outputs of `rows` for `what` (as `crate::codegen::rows::rows_body` chooses them);
/// the sums of derivatives of the system's sums `own` it needs are appended to `sums`.
fn rows(arena: &mut Arena, rows: &[Row], what: Output, own: &[Id], sums: &mut Vec<Id>) -> Rows {
    let mut scalar = Vec::new();
    let mut arrays: [Vec<(usize, Id)>; 4] = Default::default();
    for (b, r) in rows.iter().enumerate() {
        match r {
            Row::Scalar(id) => scalar.push((b, *id)),
            Row::Array(v) => (0..4).for_each(|k| arrays[k].push((b, v[k]))),
        }
    }
    let grads = (what != Output::Value && !own.is_empty()).then(|| {
        let ids: Vec<Id> = scalar.iter().map(|&(_, id)| id).collect();
        let g = gradient_sums(arena, own, &ids, what, sums.len());
        sums.extend(&g.templates);
        g
    });
    let scalar_out = outputs(arena, &scalar, what, grads.as_ref());
    let mut chain_out = Vec::new();
    if what == Output::StateJacobian && grads.is_some() {
        for &(b, id) in &scalar {
            for c in chains(arena, own, id) {
                chain_out.push((b, c));
            }
        }
    }
    let arrays = arrays.map(|rows| outputs(arena, &rows, what, None));
    Rows {
        scalar: scalar_out,
        arrays,
        chains: chain_out,
    }
}

/// Per body, the nonzero derivatives of its pressure force in the states (as
/// `crate::codegen::terms::force_gradients`).
fn force_gradients(arena: &mut Arena, forces: &[Id]) -> Vec<Vec<(Sym, Id)>> {
    forces
        .iter()
        .map(|&f| {
            let mut out = Vec::new();
            for s in arena.symbols(f) {
                if let Sym::State(..) = s {
                    let d = arena.diff(f, s);
                    if arena.as_const(d) != Some(0.0) {
                        out.push((s, d));
                    }
                }
            }
            out
        })
        .collect()
}

/// The sensors' outputs with their gradients (as `crate::codegen::sensors::sensor_output`):
/// `None` for a state sensor.
pub(crate) fn sensors(arena: &mut Arena, sensors: &[SensorDecl]) -> Vec<Option<SensorPlan>> {
    sensors
        .iter()
        .map(|s| {
            let e = s.expr.as_ref()?;
            let params: std::collections::BTreeSet<u32> = arena
                .symbols(e.value)
                .into_iter()
                .filter_map(|s| if let Sym::Param(j) = s { Some(j) } else { None })
                .collect();
            let dv = (0..e.reads.len())
                .map(|i| arena.diff(e.value, Sym::Input(i as u32)))
                .collect();
            let dp = params
                .into_iter()
                .map(|j| (j as usize, arena.diff(e.value, Sym::Param(j))))
                .collect();
            Some(SensorPlan {
                value: e.value,
                dv,
                dp,
            })
        })
        .collect()
}
