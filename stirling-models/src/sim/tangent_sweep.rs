//! The block product of [`crate::sim::tangent::TangentFlow`] with the stage matrices factored on
//! several threads.
//!
//! The factorizations of a sweep dominate its cost (at nsection n = 1000 one refactorization of
//! the `3n x 3n` stage matrix costs as much as solving it for twenty columns) and they are
//! independent of each other: only the solves run in the order of the steps. So `W` workers factor
//! the steps (worker `w` the steps `w, w + W, ...`, each with its own refactoring LU, so the pivot
//! sequences and the numbers do not depend on timing) and hand the factors over through bounded
//! channels; the calling thread solves each step for every column as its factors arrive and drops
//! them. At most a few factorizations per worker are alive at once: the memory stays that of the
//! recorded states.

use std::sync::mpsc::{sync_channel, Receiver};

use super::monodromy::SparseStage;
use super::refactor_lu::LuSnapshot;
use super::system::ModelSystem;
use super::tangent::factor_step;
use super::SimError;

/// Factorizations a worker may have ready ahead of the solves.
const AHEAD: usize = 4;

/// The worker threads of a sweep: the machine's cores, at most 4; one means no worker.
pub fn sweep_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |c| c.get().min(4))
}

/// What the workers read of a recorded orbit (see [`crate::sim::tangent::TangentFlow`]).
pub(super) struct Recorded<'a> {
    pub(super) sys: &'a ModelSystem<'a>,
    pub(super) steps: &'a [(f64, f64)],
    pub(super) stage_x: &'a [f64],
    pub(super) scale: &'a [f64],
    pub(super) pattern: &'a [(usize, usize)],
}

/// `V <- D^-1 Phi D V` for the `k` columns of `v` with `threads` factoring workers.
pub(super) fn apply_block_parallel(
    tf: &Recorded<'_>,
    v: &mut [f64],
    k: usize,
    threads: usize,
) -> Result<(), SimError> {
    let n = tf.scale.len();
    let steps = tf.steps.len();
    let w = threads.clamp(1, steps.max(1));
    std::thread::scope(|sc| {
        let mut rx: Vec<Receiver<Result<LuSnapshot, SimError>>> = Vec::with_capacity(w);
        for id in 0..w {
            let (tx, r) = sync_channel(AHEAD);
            rx.push(r);
            sc.spawn(move || {
                let mut sparse = match SparseStage::new(n, tf.pattern) {
                    Ok(s) => s,
                    Err(e) => {
                        let _ = tx.send(Err(e));
                        return;
                    }
                };
                let mut trip = Default::default();
                for s in (id..steps).step_by(w) {
                    let done = factor_step(
                        tf.sys,
                        tf.stage_x,
                        tf.steps[s],
                        s,
                        tf.scale,
                        &mut trip,
                        &mut sparse,
                    )
                    .and_then(|()| {
                        sparse.lu.snapshot().map_err(|_| SimError::SolverFailure {
                            t: tf.steps[s].0,
                            why: "tangent step: singular stage matrix".into(),
                        })
                    });
                    let failed = done.is_err();
                    // a closed channel: the sweep stopped early
                    if tx.send(done).is_err() || failed {
                        return;
                    }
                }
            });
        }
        let mut rhs = vec![0.0; 3 * n * k];
        let mut work = Vec::new();
        for s in 0..steps {
            let lu = rx[s % w].recv().map_err(|_| SimError::SolverFailure {
                t: tf.steps[s].0,
                why: "tangent step: a factoring thread stopped".into(),
            })??;
            for (col, block) in v.chunks_exact(n).zip(rhs.chunks_exact_mut(3 * n)) {
                for i in 0..3 {
                    block[i * n..(i + 1) * n].copy_from_slice(col);
                }
            }
            lu.solve_columns(&mut rhs, k, &mut work);
            for (col, block) in v.chunks_exact_mut(n).zip(rhs.chunks_exact(3 * n)) {
                col.copy_from_slice(&block[2 * n..]);
            }
        }
        Ok(())
    })
}
