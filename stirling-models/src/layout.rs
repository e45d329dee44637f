//! Which state of a model is what: the state-layout query every analysis uses instead of filtering
//! [`Model::states`](stirling_dsl::Model::states) by hand.

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
    /// Pressures of CVs outside the working gas ([`StateLayout::working_gas`] only; empty
    /// from [`StateLayout::of`]), in vessel order.
    pub outside: Vec<usize>,
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

    /// As [`StateLayout::of`], with the pressures split: `pressures` keeps the working gas -
    /// the CVs joined by mass-flow links to the CV the model's `p` sensor observes (else to
    /// the last CV), hot side first - and `outside` gets the others (a closed bounce space).
    /// For a model whose CVs are all linked (the family), equal to [`StateLayout::of`].
    pub fn working_gas(model: &dyn Model) -> Self {
        let mut l = Self::of(model);
        let Some(&last) = l.pressures.last() else {
            return l;
        };
        let anchor = match model.sensor_state("p") {
            Some(Some(s)) if l.pressures.contains(&s) => s,
            _ => last,
        };
        let vessels = model.vessel_names();
        let cv_of = |state: usize| match model.states()[state].kind {
            StateKind::Pressure(k) => vessel_base(&vessels[k]),
            _ => String::new(),
        };
        let chain = linked_to(model, &cv_of(anchor));
        let (keep, out): (Vec<usize>, Vec<usize>) = l
            .pressures
            .iter()
            .partition(|&&s| chain.contains(&cv_of(s)));
        l.pressures = keep;
        l.outside = out;
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

    /// The flywheels of a kinematic engine (docs/physics.md section 12): each a body whose
    /// position is an angle (rad), as `(angle, speed)` states; empty for free bodies.
    pub fn flywheels(model: &dyn Model) -> Vec<(usize, usize)> {
        model
            .states()
            .iter()
            .enumerate()
            .filter(|(_, s)| matches!(s.kind, StateKind::Position(_)) && s.unit == "rad")
            .filter_map(|(i, _)| Some((i, Self::velocity_of(model, i)?)))
            .collect()
    }

    /// The cold-side CV's pressure state (the last CV), if the model has gas.
    pub fn cold(&self) -> Option<usize> {
        self.pressures.last().copied()
    }
}

/// The CVs (base names) joined to `start` by mass-flow links, `start` included.
fn linked_to(model: &dyn Model, start: &str) -> Vec<String> {
    let links: Vec<(String, String)> = model
        .topology()
        .links
        .iter()
        .map(|l| (vessel_base(l.from), vessel_base(l.to)))
        .collect();
    let mut seen = vec![start.to_string()];
    let mut k = 0;
    while k < seen.len() {
        let at = seen[k].clone();
        for (a, b) in &links {
            for (x, y) in [(a, b), (b, a)] {
                if *x == at && !seen.contains(y) {
                    seen.push(y.clone());
                }
            }
        }
        k += 1;
    }
    seen
}

/// A vessel's name without its section index (`regen[j + 1]` -> `regen`).
fn vessel_base(s: &str) -> String {
    s.split('[').next().unwrap_or(s).trim().to_string()
}
