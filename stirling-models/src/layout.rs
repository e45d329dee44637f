//! Which state of a model is what: the state-layout query every analysis uses instead of
//! filtering [`Model::states`] by hand.

use stirling_dsl::{Model, StateKind};

/// State indices of a model by meaning, each list in state order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct StateLayout {
    /// Body positions and velocities, interleaved as in the state vector.
    pub bodies: Vec<usize>,
    pub positions: Vec<usize>,
    pub velocities: Vec<usize>,
    /// Gas states (pressures and masses), as in the state vector.
    pub gas: Vec<usize>,
    /// CV pressures, in vessel order (the hot side first in the family).
    pub pressures: Vec<usize>,
    pub masses: Vec<usize>,
    /// Wall temperatures (walls with a heat capacity), in wall order.
    pub walls: Vec<usize>,
}

impl StateLayout {
    /// The layout of `model`.
    pub fn of(model: &dyn Model) -> Self {
        let mut l = Self::default();
        for (i, s) in model.states().iter().enumerate() {
            match s.kind {
                StateKind::Position(_) => {
                    l.bodies.push(i);
                    l.positions.push(i);
                }
                StateKind::Velocity(_) => {
                    l.bodies.push(i);
                    l.velocities.push(i);
                }
                StateKind::Pressure(_) => {
                    l.gas.push(i);
                    l.pressures.push(i);
                }
                StateKind::Mass(_) => {
                    l.gas.push(i);
                    l.masses.push(i);
                }
                StateKind::WallTemperature(_) => l.walls.push(i),
            }
        }
        l
    }

    /// Position of state `i` in the gas list.
    pub fn gas_pos(&self, i: usize) -> Option<usize> {
        self.gas.iter().position(|&g| g == i)
    }

    /// The velocity state of the body whose position is state `pos`.
    pub fn velocity_of(model: &dyn Model, pos: usize) -> Option<usize> {
        let states = model.states();
        let StateKind::Position(b) = states.get(pos)?.kind else {
            return None;
        };
        states
            .iter()
            .position(|s| matches!(s.kind, StateKind::Velocity(v) if v == b))
    }

    /// The cold-side CV's pressure state (the last CV), if the model has gas.
    pub fn cold(&self) -> Option<usize> {
        self.pressures.last().copied()
    }
}
