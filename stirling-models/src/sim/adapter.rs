//! The diffsol adapter: an [`OdeSystem`](crate::sim::OdeSystem) as diffsol `OdeEquations`, handing
//! the solver the full analytic Jacobian (no colouring, no Jacobian-vector probing).
//!
//! Two linear-algebra backends share one adapter ([`Backend`](crate::sim::adapter::Backend)):
//! - dense: `NalgebraMat` + `NalgebraLU`, the Jacobian written column-major;
//! - sparse: `FaerSparseMat` + `FaerSparseLU`, the pattern from
//!   [`OdeSystem::sparsity`] (united with the entries present at the initial
//!   state), the values scattered from [`OdeSystem::jac_triplets`] (entries at one
//!   position accumulate).

use std::cell::{Cell, RefCell};

use diffsol::{
    op::OpStatistics, ConstantOp, FaerContext, FaerSparseMat, FaerVec, Matrix, NalgebraContext,
    NalgebraMat, NalgebraVec, NonLinearOp, NonLinearOpJacobian, OdeEquations, OdeEquationsRef, Op,
    UnitCallable, Vector, VectorCommon,
};
use faer::sparse::{Pair, SymbolicSparseColMat};

use super::sens::SensSystem;
use super::system::OdeSystem;

/// A diffsol matrix type the adapter can fill.
pub(crate) trait Backend: Matrix<T = f64> + 'static {
    fn new_ctx() -> Self::C;
    fn slice(v: &Self::V) -> &[f64];
    fn slice_mut(v: &mut Self::V) -> &mut [f64];
    /// The Jacobian pattern for this backend (`None` for dense storage).
    fn pattern(sys: &dyn OdeSystem, x0: &[f64]) -> Option<Self::Sparsity>;
    /// Overwrite `m` with `df/dx` at `(t, x)`.
    fn fill(eqn: &Eqn<'_, Self>, t: f64, x: &[f64], m: &mut Self);
}

pub(crate) type DenseM = NalgebraMat<f64>;
pub(crate) type SparseM = FaerSparseMat<f64>;

impl Backend for DenseM {
    fn new_ctx() -> NalgebraContext {
        NalgebraContext::default()
    }
    fn slice(v: &NalgebraVec<f64>) -> &[f64] {
        v.inner().as_slice()
    }
    fn slice_mut(v: &mut NalgebraVec<f64>) -> &mut [f64] {
        v.inner_mut().as_mut_slice()
    }
    fn pattern(_: &dyn OdeSystem, _: &[f64]) -> Option<Self::Sparsity> {
        None
    }
    fn fill(eqn: &Eqn<'_, Self>, t: f64, x: &[f64], m: &mut Self) {
        let data = m.inner_mut().as_mut_slice();
        data.fill(0.0);
        eqn.sys.jac(t, x, data);
    }
}

impl Backend for SparseM {
    fn new_ctx() -> FaerContext {
        FaerContext::default()
    }
    fn slice(v: &FaerVec<f64>) -> &[f64] {
        v.inner().col_as_slice(0)
    }
    fn slice_mut(v: &mut FaerVec<f64>) -> &mut [f64] {
        v.inner_mut().col_as_slice_mut(0)
    }
    fn pattern(sys: &dyn OdeSystem, x0: &[f64]) -> Option<Self::Sparsity> {
        let n = sys.dim();
        let mut rc = sys
            .sparsity()
            .unwrap_or_else(|| (0..n).flat_map(|c| (0..n).map(move |r| (r, c))).collect());
        let mut trip = Vec::new();
        sys.jac_triplets(0.0, x0, &mut trip);
        rc.extend(trip.iter().map(|&(r, c, _)| (r, c)));
        rc.extend((0..n).map(|i| (i, i)));
        rc.sort_unstable();
        rc.dedup();
        let pairs: Vec<Pair<usize, usize>> = rc.into_iter().map(|(r, c)| Pair::new(r, c)).collect();
        Some(
            SymbolicSparseColMat::try_new_from_indices(n, n, &pairs)
                .expect("a valid Jacobian pattern")
                .0,
        )
    }
    fn fill(eqn: &Eqn<'_, Self>, t: f64, x: &[f64], m: &mut Self) {
        let mut trip = eqn.trip.borrow_mut();
        trip.clear();
        eqn.sys.jac_triplets(t, x, &mut trip);
        let (sym, vals) = m.inner_mut()[0].parts_mut();
        vals.fill(0.0);
        scatter(sym.col_ptr(), sym.row_idx(), vals, &trip);
    }
}

/// Add triplets into CSC values (sorted rows per column). Panics on an entry
/// outside the pattern: the structural pattern must cover every Jacobian entry.
pub(crate) fn scatter(
    col_ptr: &[usize],
    row_idx: &[usize],
    vals: &mut [f64],
    trip: &[(usize, usize, f64)],
) {
    for &(r, c, v) in trip {
        let (a, b) = (col_ptr[c], col_ptr[c + 1]);
        match row_idx[a..b].binary_search(&r) {
            Ok(k) => vals[a + k] += v,
            Err(_) => {
                if v != 0.0 {
                    panic!("Jacobian entry ({r}, {c}) lies outside the structural sparsity pattern")
                }
            }
        }
    }
}

/// A system with its initial state and call counters.
pub(crate) struct Eqn<'s, M: Backend> {
    pub sys: &'s dyn OdeSystem,
    /// The forward sensitivities diffsol integrates alongside (staggered), if any.
    pub sens: Option<&'s dyn SensSystem>,
    pub y0: Vec<f64>,
    pub ctx: M::C,
    pub sparsity: Option<M::Sparsity>,
    pub n_rhs: Cell<usize>,
    pub n_jac: Cell<usize>,
    trip: RefCell<Vec<(usize, usize, f64)>>,
    /// `df/dx` as triplets at the `(t, x)` of the last Jacobian-vector product: the
    /// sensitivity corrector multiplies every column by the Jacobian at one state per step.
    jmul: RefCell<(f64, Vec<f64>, Vec<(usize, usize, f64)>)>,
}

impl<'s, M: Backend> Eqn<'s, M> {
    pub fn new(sys: &'s dyn OdeSystem, y0: Vec<f64>) -> Self {
        let sparsity = M::pattern(sys, &y0);
        Self {
            sys,
            sens: None,
            y0,
            ctx: M::new_ctx(),
            sparsity,
            n_rhs: Cell::new(0),
            n_jac: Cell::new(0),
            trip: RefCell::new(Vec::new()),
            jmul: RefCell::new((f64::NAN, Vec::new(), Vec::new())),
        }
    }

    /// [`Eqn::new`] with forward sensitivities.
    pub fn with_sens(sys: &'s dyn OdeSystem, sens: &'s dyn SensSystem, y0: Vec<f64>) -> Self {
        Self {
            sens: Some(sens),
            ..Self::new(sys, y0)
        }
    }

    /// Number of sensitivity columns (diffsol's parameters).
    fn n_sens(&self) -> usize {
        self.sens.map_or(0, |s| s.n_sens())
    }
}

pub(crate) struct Rhs<'a, 's, M: Backend>(pub(crate) &'a Eqn<'s, M>);
pub(crate) struct Init<'a, 's, M: Backend>(pub(crate) &'a Eqn<'s, M>);

macro_rules! impl_op {
    ($t:ident) => {
        impl<M: Backend> Op for $t<'_, '_, M> {
            type T = f64;
            type V = M::V;
            type M = M;
            type C = M::C;
            fn context(&self) -> &Self::C {
                &self.0.ctx
            }
            fn nstates(&self) -> usize {
                self.0.y0.len()
            }
            fn nout(&self) -> usize {
                self.0.y0.len()
            }
            fn nparams(&self) -> usize {
                self.0.n_sens()
            }
            fn statistics(&self) -> OpStatistics {
                let mut s = OpStatistics::default();
                s.number_of_calls = self.0.n_rhs.get();
                s.number_of_matrix_evals = self.0.n_jac.get();
                s
            }
        }
    };
}
impl_op!(Rhs);
impl_op!(Init);

impl<M: Backend> NonLinearOp for Rhs<'_, '_, M> {
    fn call_inplace(&self, x: &M::V, t: f64, y: &mut M::V) {
        self.0.n_rhs.set(self.0.n_rhs.get() + 1);
        self.0.sys.rhs(t, M::slice(x), M::slice_mut(y));
    }
}

impl<M: Backend> NonLinearOpJacobian for Rhs<'_, '_, M> {
    /// `y = J(x) v` for every lane of `v` (the sensitivity corrector passes all columns at
    /// once, `n` entries a lane); `J` is kept for repeated products at one `(t, x)`.
    fn jac_mul_inplace(&self, x: &M::V, t: f64, v: &M::V, y: &mut M::V) {
        let x = M::slice(x);
        let mut cache = self.0.jmul.borrow_mut();
        let (tc, xc, trip) = &mut *cache;
        if *tc != t || xc.as_slice() != x {
            trip.clear();
            self.0.sys.jac_triplets(t, x, trip);
            (*tc, *xc) = (t, x.to_vec());
        }
        let n = self.0.y0.len();
        let (v, y) = (M::slice(v), M::slice_mut(y));
        y.fill(0.0);
        for o in (0..v.len()).step_by(n.max(1)) {
            for &(r, c, a) in trip.iter() {
                y[o + r] += a * v[o + c];
            }
        }
    }
    fn jacobian_inplace(&self, x: &M::V, t: f64, y: &mut M) {
        self.0.n_jac.set(self.0.n_jac.get() + 1);
        M::fill(self.0, t, M::slice(x), y);
    }
    fn jacobian_sparsity(&self) -> Option<M::Sparsity> {
        self.0.sparsity.clone()
    }
}

impl<M: Backend> ConstantOp for Init<'_, '_, M> {
    fn call_inplace(&self, _t: f64, y: &mut M::V) {
        M::slice_mut(y).copy_from_slice(&self.0.y0);
    }
}

impl<M: Backend> Op for Eqn<'_, M> {
    type T = f64;
    type V = M::V;
    type M = M;
    type C = M::C;
    fn context(&self) -> &Self::C {
        &self.ctx
    }
    fn nstates(&self) -> usize {
        self.y0.len()
    }
    fn nout(&self) -> usize {
        self.y0.len()
    }
    fn nparams(&self) -> usize {
        self.n_sens()
    }
}

impl<'a, 's, M: Backend> OdeEquationsRef<'a> for Eqn<'s, M> {
    type Rhs = Rhs<'a, 's, M>;
    type Init = Init<'a, 's, M>;
    type Root = UnitCallable<M>;
    type Mass = UnitCallable<M>;
    type Out = UnitCallable<M>;
    type Reset = UnitCallable<M>;
}

impl<'s, M: Backend> OdeEquations for Eqn<'s, M> {
    fn rhs<'a>(&'a self) -> Rhs<'a, 's, M> {
        Rhs(self)
    }
    fn mass(&self) -> Option<UnitCallable<M>> {
        None
    }
    fn root(&self) -> Option<UnitCallable<M>> {
        None
    }
    fn init<'a>(&'a self) -> Init<'a, 's, M> {
        Init(self)
    }
    fn set_params(&mut self, _p: &M::V) {}
    fn get_params(&self, _p: &mut M::V) {}
}
