//! The graph's states against the generated model's ([`crate::Model::states`]).
//!
//! Each storage element holds the states its integral causality integrates:
//!
//! | graph state | element | model state |
//! |---|---|---|
//! | momentum `p = m v` of a body | `I: m` | velocity `v` (`StateKind::Velocity`) |
//! | displacement `q` of a body | `C: k` (its spring) | position (`StateKind::Position`) |
//! | internal energy `U = P V/(gamma-1)` of a CV element | the CV's `C` field | pressure (`StateKind::Pressure`), `V` being known |
//! | gas mass `m` of a CV element (linked, full closure) | the CV's `C` field | mass (`StateKind::Mass`) |
//! | heat `C Tw` stored in a wall element | `C: capacity` | wall temperature (`StateKind::WallTemperature`) |
//! | volume `V` of a CV element | the CV's `C` field | none: `V = V0 + sum a q` |
//!
//! The volume port integrates `dV/dt = sum a v`, the sum of the face flows of bodies whose
//! displacements the springs integrate too: `V - sum a q = V0` holds for all time (a
//! geometric, holonomic constraint), so the volumes are not independent states and the
//! model computes them from the positions. Every other state is one to one with a model
//! state.

use super::graph::{BondGraph, Store};
use crate::runtime::StateKind;

/// The model state a graph state is, or `None` for a CV volume (fixed by the positions).
pub fn model_state(s: Store) -> Option<StateKind> {
    match s {
        Store::Momentum(k) => Some(StateKind::Velocity(k)),
        Store::Displacement(k) => Some(StateKind::Position(k)),
        Store::Energy(k) => Some(StateKind::Pressure(k)),
        Store::Mass(k) => Some(StateKind::Mass(k)),
        Store::WallHeat(k) => Some(StateKind::WallTemperature(k)),
        Store::Volume(_) => None,
    }
}

/// The independent states of `g` as model states, in graph order.
pub fn independent_states(g: &BondGraph) -> Vec<StateKind> {
    g.states().filter_map(|(_, s)| model_state(s)).collect()
}
