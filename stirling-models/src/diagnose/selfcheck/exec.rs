//! Running the planned cases: `jobs` at once (each diagnosis also uses the rayon pool),
//! every finished case handed to the progress callback as it ends.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use stirling_dsl::Model;

use super::outcome::{run_case, Outcome};
use super::plan::{Planned, VerdictOptions};
use crate::diagnose::DiagnoseError;

/// Run `plan`; outcomes in plan order. `progress` gets each outcome with the count done.
pub fn run_all(
    opts: &VerdictOptions,
    model: &dyn Model,
    p_nom: &[f64],
    plan: &[Planned],
    progress: &(dyn Fn(&Outcome, usize, usize) + Sync),
) -> Result<Vec<Outcome>, DiagnoseError> {
    let dir = match &opts.records {
        Some(d) => {
            std::fs::create_dir_all(d).map_err(|source| DiagnoseError::Io {
                path: d.clone(),
                source,
            })?;
            d.clone()
        }
        None => super::case::scratch_dir()?,
    };
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let results: Mutex<Vec<Outcome>> = Mutex::new(Vec::with_capacity(plan.len()));
    let worker = || loop {
        let k = next.fetch_add(1, Ordering::Relaxed);
        let Some(c) = plan.get(k) else { break };
        let out = run_case(opts, model, p_nom, c, &dir);
        let n = done.fetch_add(1, Ordering::Relaxed) + 1;
        progress(&out, n, plan.len());
        results.lock().unwrap_or_else(|e| e.into_inner()).push(out);
    };
    std::thread::scope(|s| {
        for _ in 0..opts.jobs.clamp(1, plan.len().max(1)) {
            s.spawn(worker);
        }
    });
    if opts.records.is_none() {
        let _ = std::fs::remove_dir(&dir);
    }
    let mut out = results.into_inner().unwrap_or_else(|e| e.into_inner());
    out.sort_by_key(|o| o.index);
    Ok(out)
}
