//! What can go wrong building a bond graph from a topology description.

/// A bond-graph error.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum BondError {
    /// A link or conduction end that cannot be read.
    #[error("bond graph: cannot read the end `{0}` (expected `name`, `name[j+k]`, `name[k]` or `name[n-k]`)")]
    End(String),
    /// An end naming no vessel or wall of the topology.
    #[error("bond graph: `{0}` names no vessel or wall of the topology")]
    Unknown(String),
    /// Two bonds impose the effort (at a 0-junction) or the flow (at a 1-junction): the
    /// constraints contradict each other.
    #[error("bond graph: causal conflict at {0}")]
    Conflict(String),
}
