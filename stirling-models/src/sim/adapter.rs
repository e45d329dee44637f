//! The diffsol adapter: an [`OdeSystem`] as diffsol `OdeEquations`, handing the
//! solver the full analytic Jacobian (no colouring, no Jacobian-vector probing).

use std::cell::Cell;

use diffsol::{
    op::OpStatistics, ConstantOp, Matrix, NalgebraContext, NalgebraMat, NalgebraVec, NonLinearOp, NonLinearOpJacobian,
    OdeEquations, OdeEquationsRef, Op, UnitCallable, Vector, VectorCommon,
};

use super::system::OdeSystem;

pub(crate) type M = NalgebraMat<f64>;
pub(crate) type V = NalgebraVec<f64>;

/// A system with its initial state and call counters.
pub(crate) struct Eqn<'s> {
    pub sys: &'s dyn OdeSystem,
    pub y0: Vec<f64>,
    pub ctx: NalgebraContext,
    pub n_rhs: Cell<usize>,
    pub n_jac: Cell<usize>,
}

impl<'s> Eqn<'s> {
    pub fn new(sys: &'s dyn OdeSystem, y0: Vec<f64>) -> Self {
        Self { sys, y0, ctx: NalgebraContext::default(), n_rhs: Cell::new(0), n_jac: Cell::new(0) }
    }
}

pub(crate) struct Rhs<'a, 's>(&'a Eqn<'s>);
pub(crate) struct Init<'a, 's>(&'a Eqn<'s>);

macro_rules! impl_op {
    ($t:ident) => {
        impl Op for $t<'_, '_> {
            type T = f64;
            type V = V;
            type M = M;
            type C = NalgebraContext;
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
                0
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

impl NonLinearOp for Rhs<'_, '_> {
    fn call_inplace(&self, x: &V, t: f64, y: &mut V) {
        self.0.n_rhs.set(self.0.n_rhs.get() + 1);
        self.0.sys.rhs(t, x.inner().as_slice(), y.inner_mut().as_mut_slice());
    }
}

impl NonLinearOpJacobian for Rhs<'_, '_> {
    fn jac_mul_inplace(&self, x: &V, t: f64, v: &V, y: &mut V) {
        let n = self.0.y0.len();
        let mut j = vec![0.0; n * n];
        self.0.sys.jac(t, x.inner().as_slice(), &mut j);
        let (v, y) = (v.inner().as_slice(), y.inner_mut().as_mut_slice());
        for (i, yi) in y.iter_mut().enumerate() {
            *yi = (0..n).map(|k| j[i + n * k] * v[k]).sum();
        }
    }
    fn jacobian_inplace(&self, x: &V, t: f64, y: &mut M) {
        self.0.n_jac.set(self.0.n_jac.get() + 1);
        let data = y.inner_mut().as_mut_slice();
        data.fill(0.0);
        self.0.sys.jac(t, x.inner().as_slice(), data);
    }
}

impl ConstantOp for Init<'_, '_> {
    fn call_inplace(&self, _t: f64, y: &mut V) {
        y.inner_mut().as_mut_slice().copy_from_slice(&self.0.y0);
    }
}

impl Op for Eqn<'_> {
    type T = f64;
    type V = V;
    type M = M;
    type C = NalgebraContext;
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
        0
    }
}

impl<'a, 's> OdeEquationsRef<'a> for Eqn<'s> {
    type Rhs = Rhs<'a, 's>;
    type Init = Init<'a, 's>;
    type Root = UnitCallable<M>;
    type Mass = UnitCallable<M>;
    type Out = UnitCallable<M>;
    type Reset = UnitCallable<M>;
}

impl<'s> OdeEquations for Eqn<'s> {
    fn rhs<'a>(&'a self) -> Rhs<'a, 's> {
        Rhs(self)
    }
    fn mass(&self) -> Option<UnitCallable<M>> {
        None
    }
    fn root(&self) -> Option<UnitCallable<M>> {
        None
    }
    fn init<'a>(&'a self) -> Init<'a, 's> {
        Init(self)
    }
    fn set_params(&mut self, _p: &V) {}
    fn get_params(&self, _p: &mut V) {}
}
