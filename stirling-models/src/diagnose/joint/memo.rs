//! What building a joint problem computes again and again within one pass of a diagnosis,
//! computed once.
//!
//! Every candidate's screen (over the end stops' travels too) and every fit builds a
//! [`Joint`](super::Joint), and two of its parts are whole runs of the gas stage with
//! sensitivities that do not depend on the candidate:
//! - the first-order link of a gas-stage effect into stage 1 (`effect_vars::link`): the
//!   derivative of the pressure differences by the effect's strength at the nominal optimum,
//!   a function of the effect's parameter alone;
//! - the rebase at the basis's optimum (`Joint::rebase`): the differences, and the
//!   derivatives of the linked strengths, at the basis's variables, where the candidate sits
//!   at its null and so leaves the run as the basis's.
//!
//! On the two-effect record of docs/diagnosis.md they were a fifth of the diagnosis's CPU time
//! (`perf`: `EffectVars::of` 12 %, the rebase 8 %). A [`Memo`] lives in a
//! [`Basis`](super::Basis), which belongs to one calibration (a pass), so the link's key is the
//! parameter's name; the rebase's key also holds the basis's variables bit for bit, its
//! effects with their shapes, and the gas stage's variables (the run's sensitivity columns
//! take part in its step control, so a run with other columns differs at the tolerance): a
//! basis that moves never reads another's entry, and a kept run is bit for bit the one the
//! reader would have made, whichever candidate made it first.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use crate::fit::sensitivity::Signal;
use crate::fit::FitError;

/// The computed parts, shared by the clones of one basis.
#[derive(Clone, Default)]
pub struct Memo {
    links: Arc<Mutex<HashMap<String, Vec<Signal>>>>,
    rebased: Arc<Mutex<HashMap<String, Vec<Signal>>>>,
}

impl std::fmt::Debug for Memo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Memo").finish_non_exhaustive()
    }
}

/// Look `key` up in `map`, else compute it (outside the lock: candidates on both cores may
/// compute the same entry once each, never wait for each other) and keep it.
fn cached(
    map: &Mutex<HashMap<String, Vec<Signal>>>,
    key: String,
    compute: impl FnOnce() -> Result<Vec<Signal>, FitError>,
) -> Result<Vec<Signal>, FitError> {
    if let Some(v) = map.lock().ok().and_then(|m| m.get(&key).cloned()) {
        return Ok(v);
    }
    let v = compute()?;
    if let Ok(mut m) = map.lock() {
        m.insert(key, v.clone());
    }
    Ok(v)
}

impl Memo {
    /// The link derivative of the effect parameter `name` (see the module's text).
    pub fn link(
        &self,
        name: &str,
        compute: impl FnOnce() -> Result<Vec<Signal>, FitError>,
    ) -> Result<Vec<Signal>, FitError> {
        cached(&self.links, name.to_string(), compute)
    }

    /// The kept signals `what` (the differences `dp`, or a linked variable's derivatives by
    /// its name) of the rebase at the basis `basis` (a key of its variables and effects,
    /// [`basis_key`]).
    pub fn rebased(&self, basis: &str, what: &str) -> Option<Vec<Signal>> {
        let m = self.rebased.lock().ok()?;
        m.get(&format!("{basis}|{what}")).cloned()
    }

    /// Keep the signals `what` of the rebase at the basis `basis`.
    pub fn keep_rebased(&self, basis: &str, what: &str, v: &[Signal]) {
        if let Ok(mut m) = self.rebased.lock() {
            m.insert(format!("{basis}|{what}"), v.to_vec());
        }
    }
}

/// The key of a basis: its variables bit for bit and its effects with their shapes.
pub fn basis_key(x: &[f64], effects: &[super::EffectAt]) -> String {
    let bits: Vec<String> = x.iter().map(|v| format!("{:x}", v.to_bits())).collect();
    let fx: Vec<String> = effects
        .iter()
        .map(|a| format!("{}{:?}", a.effect.name, a.shapes))
        .collect();
    format!("{}#{}", bits.join(","), fx.join(";"))
}
