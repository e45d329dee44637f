//! The functions of one model at `n`, each instantiated ([`Instance`]) and laid out as a
//! [`Tape`] with what its outputs mean: the right-hand side (an output per state), the
//! Jacobians (an output per entry, with its position), the forces, the vessels' terms, ...
//! Each function follows the emitted code's of the same name (`crate::codegen::functions`).

use super::instance::{variant, Instance, InstanceError, Place};
use std::sync::{Arc, OnceLock};

use super::plan::{Plan, Rows, SensorPlan};
use super::runner::{Jit, Runner};
use super::tape::Tape;
use crate::codegen::rows::RowOutput;
use crate::expr::{Id, Sym};
use crate::topology::Topology;

/// A tape and where each output goes: `(row, column)` for a Jacobian entry, `(row, 0)` for a
/// value; with a [`Jit`], the tape's native code, compiled on first use.
#[derive(Clone, Debug, Default)]
pub struct Function {
    pub tape: Tape,
    pub places: Vec<(usize, usize)>,
    /// The JIT that compiles the tape, if any.
    pub(crate) jit: Option<Jit>,
    /// The compiled code (`None` inside: the JIT could not compile this tape).
    pub(crate) code: OnceLock<Option<Arc<dyn Runner>>>,
}

impl Function {
    /// The tape and its places, run by the interpreter.
    pub(crate) fn new(tape: Tape, places: Vec<(usize, usize)>) -> Function {
        Function {
            tape,
            places,
            jit: None,
            code: OnceLock::new(),
        }
    }

    /// This function with `jit` to compile its tape (on first use).
    pub(crate) fn with_jit(&self, jit: Option<Jit>) -> Function {
        Function::new(self.tape.clone(), self.places.clone()).jit_set(jit)
    }

    /// This function with its first `head` outputs (values, at `(row, 0)`) in the order of
    /// their rows and the tape split after them ([`Tape::split`]), so that native code writes
    /// them straight to the caller's rows and the outputs after them (in order) to a second
    /// slice; unchanged where the first `head` rows are not exactly `0..head`.
    pub(crate) fn split_rows(mut self, head: usize) -> Function {
        if head > self.places.len() {
            return self;
        }
        let mut order: Vec<usize> = (0..head).collect();
        order.sort_by_key(|&k| self.places[k].0);
        let rows_ok = order
            .iter()
            .enumerate()
            .all(|(r, &k)| self.places[k] == (r, 0));
        if !rows_ok {
            return self;
        }
        let outputs: Vec<u32> = order.iter().map(|&k| self.tape.outputs[k]).collect();
        self.tape.outputs.splice(0..head, outputs);
        let places: Vec<(usize, usize)> = order.iter().map(|&k| self.places[k]).collect();
        self.places.splice(0..head, places);
        self.tape.split = Some(head);
        self
    }

    fn jit_set(mut self, jit: Option<Jit>) -> Function {
        self.jit = jit;
        self
    }

    /// The native code of the tape: compiled by the JIT on the first call, `None` without a
    /// JIT or where it could not compile the tape.
    pub fn code(&self) -> Option<&Arc<dyn Runner>> {
        let jit = self.jit?;
        self.code.get_or_init(|| jit(&self.tape)).as_ref()
    }
}

/// Collects the roots of one function and where they go.
struct Outputs<'i, 'a> {
    inst: &'i mut Instance<'a>,
    roots: Vec<Id>,
    places: Vec<(usize, usize)>,
    /// Per root, its group in the tape's schedule (`Tape::scheduled`): the scalar rows 0,
    /// section `j`'s rows `j + 1`, so that the right-hand side and the Jacobian of one
    /// section are computed together.
    groups: Vec<u32>,
    /// The group of the roots pushed now.
    group: u32,
    /// Whether the groups mark sections ([`Tape::sections`]): a function of the rows.
    sections: bool,
}

impl<'i, 'a> Outputs<'i, 'a> {
    fn new(inst: &'i mut Instance<'a>) -> Self {
        Outputs {
            inst,
            roots: Vec::new(),
            places: Vec::new(),
            groups: Vec::new(),
            group: 0,
            sections: false,
        }
    }

    fn push(
        &mut self,
        id: Id,
        place: Place,
        recip: bool,
        at: (usize, usize),
    ) -> Result<(), InstanceError> {
        let r = self.inst.get(id, place, recip)?;
        self.root(r, at);
        Ok(())
    }

    fn root(&mut self, r: Id, at: (usize, usize)) {
        self.roots.push(r);
        self.places.push(at);
        self.groups.push(self.group);
    }

    fn finish(self) -> Function {
        let mut schedule: Vec<usize> = (0..self.roots.len()).collect();
        schedule.sort_by_key(|&k| self.groups[k]);
        let groups = if self.sections { &self.groups[..] } else { &[] };
        let tape = Tape::scheduled(&self.inst.out, &self.roots, &schedule, groups);
        Function::new(tape, self.places)
    }
}

/// A row output's position: `(state row, column)`; a value's column is 0.
fn position(
    inst: &Instance,
    plan: &Plan,
    o: &RowOutput,
    place: Place,
) -> Result<(usize, usize), InstanceError> {
    let b = &plan.sys.blocks[o.block];
    let at = match place {
        Place::Scalar => crate::expr::At::Scalar,
        _ => crate::expr::At::Rel(0),
    };
    let row = inst.index(b.sym, at, place)?;
    let col = match o.col {
        None => 0,
        Some(Sym::State(cb, cat)) => inst.index(cb, cat, place)?,
        Some(Sym::Param(k)) => k as usize,
        Some(other) => return Err(InstanceError::Misplaced(other)),
    };
    Ok((row, col))
}

/// The outputs of `rows` (a division as the rows' value numbering writes it).
fn rows_into(out: &mut Outputs, plan: &Plan, rows: &Rows) -> Result<(), InstanceError> {
    for o in &rows.scalar {
        let at = position(out.inst, plan, o, Place::Scalar)?;
        out.push(o.id, Place::Scalar, true, at)?;
    }
    for (b, chain) in &rows.chains {
        let row = out.inst.index(
            plan.sys.blocks[*b].sym,
            crate::expr::At::Scalar,
            Place::Scalar,
        )?;
        let d = out.inst.get(chain.d, Place::Scalar, true)?;
        for j in 0..out.inst.n() as u32 {
            for &(col, ds) in &chain.cols {
                let Sym::State(cb, cat) = col else {
                    continue;
                };
                let place = Place::Loop { j };
                let c = out.inst.index(cb, cat, place)?;
                let v = out.inst.get(ds, place, true)?;
                let e = out.inst.out.mul(d, v);
                out.root(e, (row, c));
            }
        }
    }
    let n = out.inst.n();
    for j in 0..n {
        let v = variant(j, n);
        let place = Place::Row { v, j: j as u32 };
        out.group = j as u32 + 1;
        for o in &rows.arrays[v as usize] {
            let at = position(out.inst, plan, o, place)?;
            out.push(o.id, place, true, at)?;
        }
    }
    out.group = 0;
    Ok(())
}

/// A function of the rows: `rhs`, `jac`, `pjac`, `init`, or several at once.
pub(crate) fn rows(
    inst: &mut Instance,
    plan: &Plan,
    which: &[&Rows],
) -> Result<Function, InstanceError> {
    let mut out = Outputs::new(inst);
    out.sections = out.inst.n() > 1;
    for r in which {
        rows_into(&mut out, plan, r)?;
    }
    Ok(out.finish())
}

/// Values at one place, in order (`(k, 0)` for the `k`-th).
fn values(inst: &mut Instance, ids: &[Id], place: Place) -> Result<Function, InstanceError> {
    let mut out = Outputs::new(inst);
    for (k, &id) in ids.iter().enumerate() {
        out.push(id, place, false, (k, 0))?;
    }
    Ok(out.finish())
}

/// The pressure force on every body.
pub(crate) fn forces(inst: &mut Instance, plan: &Plan) -> Result<Function, InstanceError> {
    values(inst, &plan.sys.forces, Place::Scalar)
}

/// The gradient of body `k`'s pressure force: `(column, 0)` per entry.
pub(crate) fn force_grad(
    inst: &mut Instance,
    plan: &Plan,
    k: usize,
) -> Result<Function, InstanceError> {
    let mut out = Outputs::new(inst);
    for &(s, d) in &plan.force_grads[k] {
        if let Sym::State(b, at) = s {
            let c = out.inst.index(b, at, Place::Scalar)?;
            out.push(d, Place::Scalar, false, (c, 0))?;
        }
    }
    Ok(out.finish())
}

/// `[P, V, E, Q, boundary, m, T]` of every vessel element (CV elements, then spaces).
pub(crate) fn vessels(inst: &mut Instance, plan: &Plan) -> Result<Function, InstanceError> {
    let mut out = Outputs::new(inst);
    let mut k = 0;
    for v in &plan.sys.vessels {
        let terms = [
            v.pressure,
            v.volume,
            v.energy,
            v.heat,
            v.boundary,
            v.mass,
            v.temperature,
        ];
        let places: Vec<Place> = if v.array {
            (0..out.inst.n() as u32)
                .map(|j| Place::Loop { j })
                .collect()
        } else {
            vec![Place::Scalar]
        };
        for place in places {
            for (t, &id) in terms.iter().enumerate() {
                out.push(id, place, false, (k, t))?;
            }
            k += 1;
        }
    }
    Ok(out.finish())
}

/// `[mechanical energy, mechanical power]`.
pub(crate) fn mech(inst: &mut Instance, plan: &Plan) -> Result<Function, InstanceError> {
    values(
        inst,
        &[plan.sys.mech_energy, plan.sys.mech_power],
        Place::Scalar,
    )
}

/// The declared mass of every body.
pub(crate) fn masses(inst: &mut Instance, topo: &Topology) -> Result<Function, InstanceError> {
    let ids: Vec<Id> = topo.bodies.iter().map(|b| b.mass).collect();
    values(inst, &ids, Place::Scalar)
}

/// `[sum C Tw, heat from outside into the walls]`, accumulated in the emitted code's order.
pub(crate) fn walls(inst: &mut Instance, plan: &Plan) -> Result<Function, InstanceError> {
    let sys = &plan.sys;
    let mut e = inst.out.num(0.0);
    let mut q = inst.out.num(0.0);
    let heat0 = inst.get(sys.wall_boundary_heat, Place::Scalar, false)?;
    q = inst.out.add(q, heat0);
    let scalar: Vec<_> = sys.walls.iter().filter(|w| !w.array).collect();
    for w in &scalar {
        let v = inst.get(w.energy, Place::Scalar, false)?;
        e = inst.out.add(e, v);
    }
    for w in &scalar {
        let v = inst.get(w.heat, Place::Scalar, false)?;
        q = inst.out.add(q, v);
    }
    for w in sys.walls.iter().filter(|w| w.array) {
        let heated = inst.src_const(w.heat) != Some(0.0);
        for j in 0..inst.n() as u32 {
            let v = inst.get(w.energy, Place::Loop { j }, false)?;
            e = inst.out.add(e, v);
            if heated {
                let v = inst.get(w.heat, Place::Loop { j }, false)?;
                q = inst.out.add(q, v);
            }
        }
    }
    Ok(Function::new(
        Tape::new(&inst.out, &[e, q]),
        vec![(0, 0), (1, 0)],
    ))
}

/// An expression sensor's `[value, d/dv.., d/dp..]` (the parameters' columns in `places`).
pub(crate) fn sensor(inst: &mut Instance, s: &SensorPlan) -> Result<Function, InstanceError> {
    let mut out = Outputs::new(inst);
    out.push(s.value, Place::Scalar, false, (0, 0))?;
    for (i, &d) in s.dv.iter().enumerate() {
        out.push(d, Place::Scalar, false, (1, i))?;
    }
    for &(k, d) in &s.dp {
        out.push(d, Place::Scalar, false, (2, k))?;
    }
    Ok(out.finish())
}
