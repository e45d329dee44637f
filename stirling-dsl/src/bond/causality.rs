//! Causality by the Sequential Causality Assignment Procedure (Karnopp, Margolis and
//! Rosenberg, *System Dynamics*, ch. 5): fix the sources' causality and propagate it through
//! the junctions and transformers; then give each storage element integral causality and
//! propagate (a storage port the propagation already fixed the other way is in derivative
//! causality: its state is not independent); then the resistors, then any bond still open.
//!
//! A bond's causality is recorded as the end whose node takes the effort as its input (the
//! causal stroke's end): a 0-junction takes its effort from exactly one bond, a 1-junction
//! takes its flow from exactly one bond (it hands the effort out there), a transformer
//! takes the effort on one side and gives it on the other.

use super::error::BondError;
use super::graph::{BondGraph, Domain, Kind, NodeId, Store};

/// A storage port in derivative causality: its state is fixed by the others.
#[derive(Clone, Debug, PartialEq)]
pub struct Derivative {
    pub node: NodeId,
    pub state: Store,
    /// What it says physically.
    pub meaning: String,
}

/// Assigns causality to every bond of `g`; the storage ports left in derivative causality.
pub fn assign(g: &mut BondGraph) -> Result<Vec<Derivative>, BondError> {
    for b in &mut g.bonds {
        b.effort_to = None;
    }
    sources(g)?;
    let derivative = storage(g)?;
    for_each_open(g, Kind::R, |g, b, r| g.bonds[b].other(r))?;
    while let Some(b) = g.bonds.iter().position(|b| b.effort_to.is_none()) {
        g.bonds[b].effort_to = Some(g.bonds[b].to);
        propagate(g)?;
    }
    Ok(derivative)
}

/// Sources: an effort source gives its effort, a flow source takes the effort.
fn sources(g: &mut BondGraph) -> Result<(), BondError> {
    for n in 0..g.nodes.len() {
        let kind = g.nodes[n].kind;
        if !matches!(kind, Kind::Se | Kind::MSe | Kind::Sf) {
            continue;
        }
        for b in g.bonds_at(n) {
            let want = if kind == Kind::Sf {
                n
            } else {
                g.bonds[b].other(n)
            };
            match g.bonds[b].effort_to {
                None => g.bonds[b].effort_to = Some(want),
                Some(e) if e == want => {}
                Some(_) => return Err(conflict(g, n)),
            }
            propagate(g)?;
        }
    }
    Ok(())
}

/// Storage in integral causality where the propagation leaves it free.
fn storage(g: &mut BondGraph) -> Result<Vec<Derivative>, BondError> {
    let mut derivative = Vec::new();
    for n in 0..g.nodes.len() {
        let kind = g.nodes[n].kind;
        if !kind.is_storage() {
            continue;
        }
        for b in g.bonds_at(n) {
            // integral: an I takes the effort (gives its flow), a C gives its effort
            let integral = if kind == Kind::I {
                n
            } else {
                g.bonds[b].other(n)
            };
            match g.bonds[b].effort_to {
                None => {
                    g.bonds[b].effort_to = Some(integral);
                    propagate(g)?;
                }
                Some(e) if e == integral => {}
                Some(_) => derivative.push(derivative_port(g, n, g.bonds[b].domain)),
            }
        }
    }
    Ok(derivative)
}

/// The state a storage port in derivative causality loses, and what that means.
fn derivative_port(g: &BondGraph, n: NodeId, domain: Domain) -> Derivative {
    let node = &g.nodes[n];
    let pick = |want: fn(&Store) -> bool| node.states.iter().copied().find(want);
    let state = match domain {
        Domain::Volume => pick(|s| matches!(s, Store::Volume(_))),
        Domain::MassFlow => pick(|s| matches!(s, Store::Mass(_))),
        _ => None,
    }
    .or_else(|| node.states.first().copied())
    .unwrap_or(Store::Energy(0));
    let meaning = match state {
        Store::Momentum(_) => "its velocity is imposed by other elements (a rigid kinematic \
            constraint): the mass adds inertia to them and its momentum is no state"
            .to_string(),
        Store::Displacement(_) => "its displacement is fixed by other storage elements: the \
            spring is in series with a constraint and its elongation is no independent state"
            .to_string(),
        Store::Volume(_) | Store::Energy(_) | Store::Mass(_) => "the gas port's effort \
            (pressure or temperature) is imposed from outside: the field's state follows \
            algebraically"
            .to_string(),
        Store::WallHeat(_) => "the wall's temperature is imposed without a resistance \
            between: its heat capacity is no independent state"
            .to_string(),
    };
    Derivative {
        node: n,
        state,
        meaning: format!("{}: {meaning}", node.text()),
    }
}

/// Gives every open bond at a node of `kind` the causality `pick(g, bond, node)` returns
/// (the node taking the effort), propagating after each.
fn for_each_open(
    g: &mut BondGraph,
    kind: Kind,
    pick: impl Fn(&BondGraph, usize, NodeId) -> NodeId,
) -> Result<(), BondError> {
    for n in 0..g.nodes.len() {
        if g.nodes[n].kind != kind {
            continue;
        }
        for b in g.bonds_at(n) {
            if g.bonds[b].effort_to.is_none() {
                g.bonds[b].effort_to = Some(pick(g, b, n));
                propagate(g)?;
            }
        }
    }
    Ok(())
}

/// Applies the junction and transformer constraints until nothing changes.
fn propagate(g: &mut BondGraph) -> Result<(), BondError> {
    loop {
        let mut changed = false;
        for n in 0..g.nodes.len() {
            changed |= match g.nodes[n].kind {
                Kind::Zero => junction(g, n, true)?,
                Kind::One => junction(g, n, false)?,
                Kind::Tf | Kind::Mtf => junction(g, n, false)?,
                _ => false,
            };
        }
        if !changed {
            return Ok(());
        }
    }
}

/// One junction's constraint. At a 0-junction exactly one bond brings the effort in
/// (`effort_to == n`); at a 1-junction (and a transformer, which passes the effort from one
/// side to the other) exactly one bond takes the effort out (`effort_to != n`).
fn junction(g: &mut BondGraph, n: NodeId, zero: bool) -> Result<bool, BondError> {
    let bonds = g.bonds_at(n);
    // the bonds of the kind there is exactly one of
    let special = |e: NodeId| (e == n) == zero;
    let set: Vec<usize> = bonds
        .iter()
        .copied()
        .filter(|&b| g.bonds[b].effort_to.is_some_and(special))
        .collect();
    let open: Vec<usize> = bonds
        .iter()
        .copied()
        .filter(|&b| g.bonds[b].effort_to.is_none())
        .collect();
    if set.len() > 1 || (set.is_empty() && open.is_empty() && !bonds.is_empty()) {
        return Err(conflict(g, n));
    }
    let (ordinary, one_special): (Pick, Pick) = if zero {
        (
            |g: &BondGraph, b: usize, n| g.bonds[b].other(n),
            |_: &BondGraph, _: usize, n| n,
        )
    } else {
        (
            |_: &BondGraph, _: usize, n| n,
            |g: &BondGraph, b: usize, n| g.bonds[b].other(n),
        )
    };
    match (set.len(), open.as_slice()) {
        (1, open) if !open.is_empty() => {
            for &b in open {
                g.bonds[b].effort_to = Some(ordinary(g, b, n));
            }
            Ok(true)
        }
        (0, [b]) => {
            g.bonds[*b].effort_to = Some(one_special(g, *b, n));
            Ok(true)
        }
        _ => Ok(false),
    }
}

/// Which end of bond `b` at node `n` takes the effort.
type Pick = fn(&BondGraph, usize, NodeId) -> NodeId;

/// A causal conflict at node `n`.
fn conflict(g: &BondGraph, n: NodeId) -> BondError {
    let node = &g.nodes[n];
    BondError::Conflict(format!("{} ({})", node.text(), node.label))
}
