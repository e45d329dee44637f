//! A definition: a lowered topology assembled for both closures, its outputs chosen and
//! differentiated ([`Plan`]), its descriptions leaked once ([`Statics`]); every model built
//! from it at some `n` and closure shares it.

use std::sync::{Arc, OnceLock};

use super::plan::{self, Plan, SensorPlan};
use super::statics::Statics;
use crate::codegen::equations::equations;
use crate::codegen::Layout;
use crate::expr::Style;
use crate::topology::{assemble, Topology};
use crate::Closure;

/// A model declared at run time (a lowered [`Topology`]), ready to be compiled at any `n` and
/// closure ([`Definition::model`]).
pub struct Definition {
    pub(crate) topo: Topology,
    /// Full, then frozen.
    pub(crate) plans: [Plan; 2],
    pub(crate) sensors: Vec<Option<SensorPlan>>,
    pub(crate) statics: Statics,
    /// The equations as text and LaTeX, per closure (printed when first asked for).
    texts: [[OnceLock<String>; 2]; 2],
}

impl std::fmt::Debug for Definition {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Definition")
            .field("name", &self.topo.name)
            .finish_non_exhaustive()
    }
}

/// The plan's position of a closure.
pub(crate) fn slot(c: Closure) -> usize {
    match c {
        Closure::Full => 0,
        Closure::Frozen => 1,
    }
}

impl Definition {
    /// Assemble `topo` for both closures and choose every output (as `stirling_model!`'s
    /// expansion does, `crate::codegen::generate`).
    pub fn new(mut topo: Topology) -> Arc<Definition> {
        let full = assemble(&mut topo, Closure::Full);
        let frozen = assemble(&mut topo, Closure::Frozen);
        let statics = Statics::new(&topo, &full);
        let mut arena = std::mem::take(&mut topo.arena);
        let plans = [Plan::new(&mut arena, full), Plan::new(&mut arena, frozen)];
        let sensors = plan::sensors(&mut arena, &topo.sensors);
        topo.arena = arena;
        Arc::new(Definition {
            topo,
            plans,
            sensors,
            statics,
            texts: Default::default(),
        })
    }

    /// The declared model name.
    pub fn name(&self) -> &'static str {
        self.statics.name
    }

    /// Whether the topology has an array (so that `n` matters).
    pub fn has_array(&self) -> bool {
        self.topo.has_array()
    }

    /// The lowered topology.
    pub fn topology(&self) -> &Topology {
        &self.topo
    }

    /// The equations of a closure as text or LaTeX.
    pub(crate) fn equations(&self, closure: Closure, style: Style) -> String {
        let k = slot(closure);
        let s = match style {
            Style::Text => 0,
            Style::Latex => 1,
        };
        self.texts[k][s]
            .get_or_init(|| {
                let lay = Layout {
                    sys: &self.plans[k].sys,
                    topo: &self.topo,
                };
                equations(&self.topo.arena, &lay, &self.topo.name, style)
            })
            .clone()
    }
}
