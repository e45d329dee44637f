//! The fill of the integrator's sparse LU by column order (issue 37): for `nsection` at each
//! `n`, the Newton matrix `I - c J` at the benchmarks' fairness state is factored in each
//! order of `refactor_lu::ColumnOrder` with partial pivoting, then as the integrator does it
//! (diagonal pivots in AMD's order first, partial pivoting where one fails: the row says which
//! held); printed are the matrix's entries, the factors' entries (`L` and `U`, diagonals
//! included), their ratio (the fill), and the time of one refactorization (pivots kept) and of
//! one solve, medians of repeated runs.
//!
//! Run: `cargo run --release --example lu_fill -- 10,100,1000` (default `2,10,100,1000`;
//! `--c C` the Newton matrix's `h * alpha`, default 2e-4, about one step of the simulated
//! second).

use std::time::Instant;

use faer::sparse::{SparseColMat, Triplet};
use stirling::dsl::{Closure, JacSink, Model};
use stirling::models::family::NSection;
use stirling::models::sim::refactor_lu::{ColumnOrder, RefactorLu};

#[path = "support/fairness.rs"]
mod fairness;
use fairness::{fairness_state, median};

fn newton_matrix(m: &dyn Model, p: &[f64], c: f64) -> SparseColMat<usize, f64> {
    let x = fairness_state(m, p);
    let mut trip = Vec::new();
    m.jacobian(p, &x, 0.0, &mut JacSink::Triplets(&mut trip));
    let n = m.n_states();
    let mut t: Vec<Triplet<usize, usize, f64>> = trip
        .iter()
        .map(|&(r, col, v)| Triplet::new(r, col, -c * v))
        .collect();
    t.extend((0..n).map(|i| Triplet::new(i, i, 1.0)));
    SparseColMat::try_new_from_triplets(n, n, &t).expect("a valid pattern")
}

/// Median seconds of `f` over repeated timed batches of `reps` calls.
fn time(reps: usize, mut f: impl FnMut()) -> f64 {
    let mut ts: Vec<f64> = (0..7)
        .map(|_| {
            let t = Instant::now();
            (0..reps).for_each(|_| f());
            t.elapsed().as_secs_f64() / reps as f64
        })
        .collect();
    median(&mut ts)
}

fn main() {
    let mut ns = vec![2, 10, 100, 1000];
    let mut c = 2e-4;
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--c" => {
                i += 1;
                c = args.get(i).and_then(|v| v.parse().ok()).unwrap_or_else(|| {
                    eprintln!("--c needs a number");
                    std::process::exit(2)
                });
            }
            list => {
                ns = list
                    .split(',')
                    .filter_map(|v| v.trim().parse().ok())
                    .collect();
                if ns.is_empty() {
                    eprintln!("usage: lu_fill [N,N,...] [--c C]");
                    std::process::exit(2)
                }
            }
        }
        i += 1;
    }
    println!(
        "| n | states | entries of I - cJ | order | entries of L + U | fill | refactor | solve |"
    );
    println!("|---:|---:|---:|---|---:|---:|---:|---:|");
    for n in ns {
        let m = NSection::new(n, Closure::Full).expect("n >= 1");
        let p = m.default_params();
        let a = newton_matrix(&m, &p, c);
        let reps = (20_000 / m.n_states()).max(5);
        let runs = ColumnOrder::ALL
            .iter()
            .map(|&o| (o, false))
            .chain([(ColumnOrder::Colamd, true)]);
        for (order, default) in runs {
            let mut lu = RefactorLu::with_order(a.symbolic(), order);
            if !default {
                lu = lu.partial_pivoting_only();
            }
            lu.factor(a.as_ref()).expect("a regular Newton matrix");
            let label = if default && lu.on_diagonal() {
                "default: diagonal pivots in AMD's order (held)".to_string()
            } else if default {
                "default: a diagonal pivot failed, partial pivoting in COLAMD's order".to_string()
            } else {
                format!("{order:?}, partial pivoting")
            };
            let t_factor = time(reps, || lu.factor(a.as_ref()).expect("regular"));
            let mut rhs = vec![1.0; m.n_states()];
            let t_solve = time(reps, || lu.solve(&mut rhs).expect("factored"));
            let nnz = a.compute_nnz();
            println!(
                "| {n} | {} | {nnz} | {label} | {} | {:.2} | {:.2} us | {:.2} us |",
                m.n_states(),
                lu.factor_entries(),
                lu.factor_entries() as f64 / nnz as f64,
                t_factor * 1e6,
                t_solve * 1e6
            );
        }
    }
}
