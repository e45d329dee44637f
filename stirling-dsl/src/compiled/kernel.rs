//! [`Kernel`]: the right-hand side with the Jacobian's values of a model with its parameters
//! folded in, as a function of the state alone (what CasADi's literal-parameter C is).
//!
//! A folded [`CompiledModel`](super::CompiledModel) called through the [`Model`](crate::Model)
//! trait checks at every call that the parameters it is given are the folded ones (a changed
//! parameter is never silently ignored); that check and the dispatch cost some 6-7 ns of 49
//! at n = 2 (docs/performance.md). A
//! kernel takes no parameters, so it has nothing to check: the loop of a simulation or a
//! sweep point at one parameter vector can call it directly.

use std::sync::Arc;

use super::runner::Runner;

/// Why a kernel call wrote nothing.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("kernel of {n_states} states and {nnz} Jacobian values called with x of {x}, out of {out}, values of {values}")]
pub struct KernelError {
    pub n_states: usize,
    pub nnz: usize,
    pub x: usize,
    pub out: usize,
    pub values: usize,
}

/// The native right-hand side with the Jacobian's values at one parameter vector
/// ([`CompiledModel::kernel`](super::CompiledModel::kernel)).
#[derive(Clone, Debug)]
pub struct Kernel {
    code: Arc<dyn Runner>,
    n_states: usize,
    nnz: usize,
}

impl Kernel {
    pub(crate) fn new(code: Arc<dyn Runner>, n_states: usize, nnz: usize) -> Kernel {
        Kernel {
            code,
            n_states,
            nnz,
        }
    }

    /// The number of states.
    pub fn n_states(&self) -> usize {
        self.n_states
    }

    /// The number of the Jacobian's values (its pattern is the model's
    /// `Model::jacobian_pattern`).
    pub fn nnz(&self) -> usize {
        self.nnz
    }

    /// The right-hand side at `x` to `out` and the Jacobian's values to `values`, as the
    /// model's `Model::rhs_and_jacobian_values` at the folded parameters gives them.
    #[inline]
    pub fn rhs_and_jacobian_values(
        &self,
        x: &[f64],
        out: &mut [f64],
        values: &mut [f64],
    ) -> Result<(), KernelError> {
        if x.len() == self.n_states
            && out.len() == self.n_states
            && values.len() == self.nnz
            && self.code.run(x, &[], &[], out, values)
        {
            return Ok(());
        }
        Err(KernelError {
            n_states: self.n_states,
            nnz: self.nnz,
            x: x.len(),
            out: out.len(),
            values: values.len(),
        })
    }
}
