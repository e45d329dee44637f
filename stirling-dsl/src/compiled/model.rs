//! [`CompiledModel`]: a [`Definition`] at one `n` and closure, its functions laid out as
//! tapes, behind the same [`Model`] trait as the macro's models.

use std::cell::RefCell;
use std::sync::Arc;

use super::definition::{slot, Definition};
use super::functions::{self, Function};
use super::instance::{Instance, InstanceError};
use super::runner::Jit;
use crate::expr::Style;
use crate::runtime::{
    BodyInfo, EffectSite, JacSink, Model, ModelError, ParamInfo, PowerTerms, SensorInfo, StateInfo,
    StateKind, TopologyInfo,
};
use crate::Closure;

/// Why a compiled model cannot be built.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum CompileError {
    #[error(transparent)]
    Sections(#[from] ModelError),
    /// A flaw of the assembly (never of the declaration): reported rather than a panic.
    #[error("model `{model}`: {source}")]
    Internal {
        model: &'static str,
        #[source]
        source: InstanceError,
    },
}

/// Every function of one model, as tapes.
#[derive(Clone)]
struct Functions {
    rhs: Function,
    jac: Function,
    rhs_jac: Function,
    pjac: Function,
    init: Function,
    forces: Function,
    force_grads: Vec<Function>,
    vessels: Function,
    mech: Function,
    masses: Function,
    walls: Option<Function>,
    sensors: Vec<Option<Function>>,
}

/// A model declared at run time, at one `n` and closure: each function of the [`Model`]
/// trait a register tape run by an interpreter (`crate::compiled::tape`), or as native code
/// where a JIT is installed ([`CompiledModel::with_jit`]).
pub struct CompiledModel {
    def: Arc<Definition>,
    n: usize,
    closure: Closure,
    n_states: usize,
    f: Functions,
    /// The functions with one parameter vector folded in (`CompiledModel::folded`): used
    /// when called with exactly that vector, the others otherwise.
    folded: Option<(Vec<f64>, Functions)>,
    /// The JIT compiling every tape ([`CompiledModel::with_jit`]); the interpreter without.
    jit: Option<Jit>,
}

impl std::fmt::Debug for CompiledModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CompiledModel")
            .field("name", &self.def.name())
            .field("n", &self.n)
            .field("closure", &self.closure)
            .finish_non_exhaustive()
    }
}

thread_local! {
    /// The registers of the tape being run (one buffer per thread, reused).
    static REGS: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
    /// The outputs of the native code being run (one buffer per thread, reused).
    static OUTS: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// Run `f` (its native code where a JIT compiled it, else the interpreter) and hand each
/// output with its place to `each`.
fn run(f: &Function, p: &[f64], x: &[f64], v: &[f64], mut each: impl FnMut((usize, usize), f64)) {
    if let Some(code) = f.code() {
        let ran = OUTS.with(|o| {
            let mut out = o.borrow_mut();
            out.resize(f.places.len(), 0.0);
            let (head, tail) = out.split_at_mut(f.tape.head());
            if !code.run(x, p, v, head, tail) {
                return false;
            }
            for (&at, &val) in f.places.iter().zip(out.iter()) {
                each(at, val);
            }
            true
        });
        if ran {
            return;
        }
    }
    REGS.with(|r| {
        let mut regs = r.borrow_mut();
        f.tape.run(p, x, v, &mut regs);
        for (k, &at) in f.places.iter().enumerate() {
            each(at, f.tape.output(&regs, k));
        }
    });
}

/// Whether `a` and `b` hold the same numbers bit for bit (the folded functions were computed
/// from exactly these bits). Without a branch per element, so that the check on every call of
/// a folded model costs a few instructions rather than one compare and branch per parameter
/// (element-wise `==` on the 28 parameters of `nsection` was about 5 ns of its 55 ns RHS +
/// Jacobian at n = 2).
#[inline]
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .fold(0u64, |d, (x, y)| d | (x.to_bits() ^ y.to_bits()))
            == 0
}

/// Run `f`'s native code straight into the caller's slices: its outputs before the tape's
/// split (rows `0..s`, [`Function::split_rows`]) to `head`, the others in order to `tail`.
/// `false` (nothing written) without native code, without a split or where a slice is too
/// short: the caller runs [`run`] then.
#[inline]
fn run_direct(f: &Function, p: &[f64], x: &[f64], head: &mut [f64], tail: &mut [f64]) -> bool {
    match (f.tape.split, f.code()) {
        (Some(_), Some(code)) => code.run(x, p, &[], head, tail),
        _ => false,
    }
}

impl Definition {
    /// The model at `n` sections (1 for a topology without array) and `closure`.
    pub fn model(
        self: &Arc<Self>,
        n: usize,
        closure: Closure,
    ) -> Result<CompiledModel, CompileError> {
        let name = self.name();
        if n == 0 {
            let why = "an array needs at least one section";
            return Err(ModelError::Sections {
                model: name,
                n,
                why,
            }
            .into());
        }
        if !self.has_array() && n != 1 {
            let why = "this topology has no array of CVs, so n must be 1";
            return Err(ModelError::Sections {
                model: name,
                n,
                why,
            }
            .into());
        }
        let f = self
            .functions(n, closure)
            .map_err(|source| CompileError::Internal {
                model: name,
                source,
            })?;
        let sys = &self.plans[slot(closure)].sys;
        let arrays = sys.blocks.iter().filter(|b| b.array).count();
        Ok(CompiledModel {
            def: Arc::clone(self),
            n,
            closure,
            n_states: sys.blocks.len() - arrays + arrays * n,
            f,
            folded: None,
            jit: None,
        })
    }

    fn functions(&self, n: usize, closure: Closure) -> Result<Functions, InstanceError> {
        let plan = &self.plans[slot(closure)];
        let mut inst = Instance::new(&self.topo.arena, &plan.sys, &plan.sums, n, None);
        let i = &mut inst;
        let force_grads = (0..plan.force_grads.len())
            .map(|k| functions::force_grad(i, plan, k))
            .collect::<Result<_, _>>()?;
        let sensors = self
            .sensors
            .iter()
            .map(|s| s.as_ref().map(|s| functions::sensor(i, s)).transpose())
            .collect::<Result<_, _>>()?;
        let rhs = functions::rows(i, plan, &[&plan.rhs])?;
        let head = rhs.places.len();
        Ok(Functions {
            rhs: rhs.split_rows(head),
            jac: functions::rows(i, plan, &[&plan.jac])?.split_rows(0),
            rhs_jac: functions::rows(i, plan, &[&plan.rhs, &plan.jac])?.split_rows(head),
            pjac: functions::rows(i, plan, &[&plan.pjac])?,
            init: functions::rows(i, plan, &[&plan.init])?,
            forces: functions::forces(i, plan)?,
            force_grads,
            vessels: functions::vessels(i, plan)?,
            mech: functions::mech(i, plan)?,
            masses: functions::masses(i, &self.topo)?,
            walls: (!self.topo.walls.is_empty())
                .then(|| functions::walls(i, plan))
                .transpose()?,
            sensors,
        })
    }
}

impl Functions {
    /// Every function.
    fn all(&self) -> impl Iterator<Item = &Function> {
        let one = [
            &self.rhs,
            &self.jac,
            &self.rhs_jac,
            &self.pjac,
            &self.init,
            &self.forces,
            &self.vessels,
            &self.mech,
            &self.masses,
        ];
        one.into_iter()
            .chain(&self.force_grads)
            .chain(&self.walls)
            .chain(self.sensors.iter().flatten())
    }

    /// Every function mapped by `g`.
    fn map(&self, g: impl Fn(&Function) -> Function) -> Functions {
        Functions {
            rhs: g(&self.rhs),
            jac: g(&self.jac),
            rhs_jac: g(&self.rhs_jac),
            pjac: g(&self.pjac),
            init: g(&self.init),
            forces: g(&self.forces),
            force_grads: self.force_grads.iter().map(&g).collect(),
            vessels: g(&self.vessels),
            mech: g(&self.mech),
            masses: g(&self.masses),
            walls: self.walls.as_ref().map(&g),
            sensors: self.sensors.iter().map(|s| s.as_ref().map(&g)).collect(),
        }
    }
}

impl CompiledModel {
    /// The definition it was built from.
    pub fn definition(&self) -> &Arc<Definition> {
        &self.def
    }

    /// The number of instructions of the right-hand side and of the Jacobian's tapes.
    pub fn tape_sizes(&self) -> (usize, usize) {
        (self.f.rhs.tape.ops.len(), self.f.jac.tape.ops.len())
    }

    /// This model with the parameters `p` folded in: every parameter expression of every
    /// function computed once, at `p` (what a simulation or a sweep point can use; a fit
    /// keeps the parameters as inputs). Called with `p` (the same bits) it gives what this
    /// model gives: bit for bit, except the right-hand side and the Jacobian, whose sums of
    /// products are fused multiply-adds (one rounding for two, as a C compiler contracts them;
    /// an entry moves by an ulp of its products, [`super::Tape::fold_fused`]); called with any
    /// other vector (even `-0.0` for `0.0`) it computes with the parameters as inputs, so a
    /// changed parameter is never silently ignored.
    pub fn folded(&self, p: &[f64]) -> CompiledModel {
        self.folded_by(p, self.jit)
    }

    /// [`Self::folded`], the folded tapes compiled by `jit` (e.g. `stirling_jit::cc_jit`, an
    /// optimising C compiler's code, worth its compile time only where the model runs many
    /// times at `p`); the parameter-input tapes keep this model's JIT.
    pub fn folded_by(&self, p: &[f64], jit: Option<Jit>) -> CompiledModel {
        let mut folded = self
            .f
            .map(|f| Function::new(f.tape.fold(p), f.places.clone()).with_jit(jit));
        // the simulation's work with its multiply-adds fused (`Tape::fold_fused`)
        let fused =
            |f: &Function| Function::new(f.tape.fold_fused(p), f.places.clone()).with_jit(jit);
        folded.rhs = fused(&self.f.rhs);
        folded.jac = fused(&self.f.jac);
        folded.rhs_jac = fused(&self.f.rhs_jac);
        CompiledModel {
            def: Arc::clone(&self.def),
            n: self.n,
            closure: self.closure,
            n_states: self.n_states,
            f: self.f.clone(),
            folded: Some((p.to_vec(), folded)),
            jit: self.jit,
        }
    }

    /// This model with every tape (the folded ones too) run as native code `jit` compiles
    /// from it on its first call; a tape the JIT cannot compile stays interpreted.
    pub fn with_jit(self, jit: Jit) -> CompiledModel {
        let j = Some(jit);
        CompiledModel {
            f: self.f.map(|f| f.with_jit(j)),
            folded: self.folded.map(|(q, g)| (q, g.map(|f| f.with_jit(j)))),
            jit: j,
            ..self
        }
    }

    /// This model run by the interpreter only (every tape, as without [`Self::with_jit`]).
    pub fn interpreted(self) -> CompiledModel {
        CompiledModel {
            f: self.f.map(|f| f.with_jit(None)),
            folded: self.folded.map(|(q, g)| (q, g.map(|f| f.with_jit(None)))),
            jit: None,
            ..self
        }
    }

    /// How many of the tapes run as native code so far (each is compiled on its first call;
    /// one the JIT could not compile does not count).
    pub fn native_tapes(&self) -> usize {
        let count = |g: &Functions| {
            g.all()
                .filter(|f| matches!(f.code.get(), Some(Some(_))))
                .count()
        };
        count(&self.f) + self.folded.as_ref().map_or(0, |(_, g)| count(g))
    }

    /// Whether a JIT compiles the tapes ([`Self::with_jit`]).
    pub fn has_jit(&self) -> bool {
        self.jit.is_some()
    }

    /// The parameter vector folded in, if any ([`CompiledModel::folded`]).
    pub fn folded_params(&self) -> Option<&[f64]> {
        self.folded.as_ref().map(|(q, _)| q.as_slice())
    }

    /// The right-hand side with the Jacobian's values at the folded parameters as a function
    /// of the state alone ([`Kernel`](super::Kernel): no parameters, so no check of them at
    /// each call); `None` unless this model is folded ([`Self::folded`]) and that tape runs
    /// as native code.
    pub fn kernel(&self) -> Option<super::Kernel> {
        let (_, f) = self.folded.as_ref()?;
        f.rhs_jac.tape.split?;
        let code = f.rhs_jac.code()?;
        Some(super::Kernel::new(
            Arc::clone(code),
            self.n_states,
            self.f.jac.places.len(),
        ))
    }

    /// The functions to run at `p`: the folded ones at the folded vector.
    #[inline]
    fn fns(&self, p: &[f64]) -> &Functions {
        match &self.folded {
            Some((q, f)) if same_bits(q, p) => f,
            _ => &self.f,
        }
    }

    /// The number of instructions of the right-hand side and the Jacobian's tapes at `p`
    /// (fewer where `p` is folded in).
    pub fn tape_sizes_at(&self, p: &[f64]) -> (usize, usize) {
        let f = self.fns(p);
        (f.rhs.tape.ops.len(), f.jac.tape.ops.len())
    }

    /// The tape of the right-hand side with the Jacobian (`Model::rhs_and_jacobian_values`:
    /// the right-hand side's outputs, then the Jacobian's values) at `p`.
    pub fn rhs_jacobian_tape(&self, p: &[f64]) -> &super::Tape {
        &self.fns(p).rhs_jac.tape
    }

    /// The native code of the right-hand side with the Jacobian at `p`, compiled now if it
    /// was not yet (`None`: no JIT, or it could not compile the tape).
    pub fn rhs_jacobian_code(&self, p: &[f64]) -> Option<&Arc<dyn super::Runner>> {
        self.fns(p).rhs_jac.code()
    }

    /// Each vessel element's `[P, V, E, Q, boundary, m, T]`, in order.
    fn each_vessel(&self, p: &[f64], x: &[f64], mut f: impl FnMut(usize, usize, f64)) {
        run(&self.fns(p).vessels, p, x, &[], |(k, t), v| f(k, t, v));
    }

    /// `[mechanical energy, mechanical power]`.
    fn mech(&self, p: &[f64], x: &[f64]) -> [f64; 2] {
        let mut m = [0.0; 2];
        run(&self.fns(p).mech, p, x, &[], |(k, _), v| m[k] = v);
        m
    }

    /// `[sum C Tw, heat from outside into the walls]` (zero without walls).
    fn walls(&self, p: &[f64], x: &[f64]) -> [f64; 2] {
        let mut w = [0.0; 2];
        if let Some(f) = &self.fns(p).walls {
            run(f, p, x, &[], |(k, _), v| w[k] = v);
        }
        w
    }
}

impl Model for CompiledModel {
    fn name(&self) -> &'static str {
        self.def.name()
    }
    fn n(&self) -> usize {
        self.n
    }
    fn closure(&self) -> Closure {
        self.closure
    }
    fn has_array(&self) -> bool {
        self.def.has_array()
    }
    fn params(&self) -> &'static [ParamInfo] {
        self.def.statics.params
    }
    fn bodies(&self) -> &'static [BodyInfo] {
        self.def.statics.bodies
    }
    fn n_states(&self) -> usize {
        self.n_states
    }
    fn states(&self) -> Vec<StateInfo> {
        let topo = &self.def.topo;
        let mut v = Vec::new();
        for b in &self.def.plans[slot(self.closure)].sys.blocks {
            let (kind, unit, what, (s, a), body) =
                crate::codegen::info::block_meaning(topo, b.kind);
            let count = if b.array { self.n } else { 1 };
            for j in 0..count {
                let index = if body { s } else { s + a * self.n + j };
                let kind = match kind {
                    "Position" => StateKind::Position(index),
                    "Velocity" => StateKind::Velocity(index),
                    "Pressure" => StateKind::Pressure(index),
                    "Mass" => StateKind::Mass(index),
                    _ => StateKind::WallTemperature(index),
                };
                let (name, meaning) = if b.array {
                    (format!("{}[{j}]", b.name), format!("{what}[{j}]"))
                } else {
                    (b.name.clone(), what.clone())
                };
                v.push(StateInfo {
                    name,
                    kind,
                    unit,
                    meaning,
                });
            }
        }
        v
    }
    fn vessel_names(&self) -> Vec<String> {
        let topo = &self.def.topo;
        let mut v = Vec::new();
        for c in &topo.cvs {
            if c.array {
                v.extend((0..self.n).map(|j| format!("{}[{j}]", c.name)));
            } else {
                v.push(c.name.clone());
            }
        }
        v.extend(topo.spaces.iter().map(|s| s.name.clone()));
        v
    }
    fn rhs(&self, p: &[f64], x: &[f64], _t: f64, out: &mut [f64]) {
        let f = &self.fns(p).rhs;
        if !run_direct(f, p, x, out, &mut []) {
            run(f, p, x, &[], |(r, _), v| out[r] = v);
        }
    }
    fn jacobian(&self, p: &[f64], x: &[f64], _t: f64, sink: &mut JacSink) {
        run(&self.fns(p).jac, p, x, &[], |(r, c), v| sink.add(r, c, v));
    }
    fn rhs_and_jacobian(&self, p: &[f64], x: &[f64], _t: f64, out: &mut [f64], sink: &mut JacSink) {
        let k = self.fns(p).rhs.places.len();
        let mut i = 0;
        run(&self.fns(p).rhs_jac, p, x, &[], |(r, c), v| {
            if i < k {
                out[r] = v;
            } else {
                sink.add(r, c, v);
            }
            i += 1;
        });
    }
    fn jacobian_values(&self, p: &[f64], x: &[f64], _t: f64, values: &mut [f64]) {
        let f = &self.fns(p).jac;
        if run_direct(f, p, x, &mut [], values) {
            return;
        }
        let mut i = 0;
        run(&self.fns(p).jac, p, x, &[], |_, v| {
            values[i] = v;
            i += 1;
        });
    }
    fn rhs_and_jacobian_values(
        &self,
        p: &[f64],
        x: &[f64],
        _t: f64,
        out: &mut [f64],
        values: &mut [f64],
    ) {
        if run_direct(&self.fns(p).rhs_jac, p, x, out, values) {
            return;
        }
        let k = self.fns(p).rhs.places.len();
        let mut i = 0;
        run(&self.fns(p).rhs_jac, p, x, &[], |(r, _), v| {
            if i < k {
                out[r] = v;
            } else {
                values[i - k] = v;
            }
            i += 1;
        });
    }
    fn jacobian_pattern(&self, _p: &[f64]) -> Vec<(usize, usize)> {
        self.f.jac.places.clone()
    }
    fn param_jacobian(&self, p: &[f64], x: &[f64], _t: f64, sink: &mut JacSink) {
        run(&self.fns(p).pjac, p, x, &[], |(r, c), v| sink.add(r, c, v));
    }
    fn pressure_forces(&self, p: &[f64], x: &[f64], out: &mut [f64]) {
        run(&self.fns(p).forces, p, x, &[], |(k, _), v| out[k] = v);
    }
    fn pressure_force_gradient(&self, k: usize, p: &[f64], x: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
        if let Some(f) = self.fns(p).force_grads.get(k) {
            run(f, p, x, &[], |(c, _), v| out[c] += v);
        }
    }
    fn body_masses(&self, p: &[f64], out: &mut [f64]) {
        run(&self.fns(p).masses, p, &[], &[], |(k, _), v| out[k] = v);
    }
    fn equilibrium_guess(&self, p: &[f64], out: &mut [f64]) {
        run(&self.fns(p).init, p, &[], &[], |(r, _), v| out[r] = v);
    }
    fn pv(&self, p: &[f64], x: &[f64], pressure: &mut [f64], volume: &mut [f64]) {
        self.each_vessel(p, x, |k, t, v| match t {
            0 => pressure[k] = v,
            1 => volume[k] = v,
            _ => {}
        });
    }
    fn temperatures(&self, p: &[f64], x: &[f64], out: &mut [f64]) {
        let len = out.len();
        self.each_vessel(p, x, |k, t, v| {
            if t == 6 && k < len {
                out[k] = v;
            }
        });
    }
    fn gas_mass(&self, p: &[f64], x: &[f64]) -> f64 {
        let mut total = 0.0;
        self.each_vessel(p, x, |_, t, v| {
            if t == 5 {
                total += v;
            }
        });
        total
    }
    fn energy(&self, p: &[f64], x: &[f64]) -> f64 {
        let mut total = 0.0;
        self.each_vessel(p, x, |_, t, v| {
            if t == 2 {
                total += v;
            }
        });
        let e = total + self.mech(p, x)[0];
        match self.fns(p).walls {
            Some(_) => e + self.walls(p, x)[0],
            None => e,
        }
    }
    fn power(&self, p: &[f64], x: &[f64]) -> PowerTerms {
        let (mut heat, mut boundary) = (0.0, 0.0);
        self.each_vessel(p, x, |_, t, v| match t {
            3 => heat += v,
            4 => boundary += v,
            _ => {}
        });
        if self.fns(p).walls.is_some() {
            heat += self.walls(p, x)[1];
        }
        PowerTerms {
            heat,
            boundary,
            mechanical: self.mech(p, x)[1],
        }
    }
    fn equations(&self, style: Style) -> String {
        self.def.equations(self.closure, style)
    }
    fn topology(&self) -> &'static TopologyInfo {
        self.def.statics.topology
    }
    fn sensors(&self) -> &'static [SensorInfo] {
        self.def.statics.sensors
    }
    fn sensor_output(&self, k: usize, p: &[f64], v: &[f64], dv: &mut [f64], dp: &mut [f64]) -> f64 {
        let Some(Some(f)) = self.fns(p).sensors.get(k) else {
            dv[0] = 1.0;
            return v[0];
        };
        let mut value = 0.0;
        run(f, p, &[], v, |(what, i), d| match what {
            0 => value = d,
            1 => dv[i] = d,
            _ => dp[i] = d,
        });
        value
    }
    fn effect_sites(&self) -> &'static [EffectSite] {
        self.def.statics.effect_sites
    }
    fn declared_free(&self) -> &'static [&'static str] {
        self.def.statics.free
    }
}
