//! The `TopologyInfo` fields only the bond graph reads: body elements, coupling dampers and
//! the spaces' given pressures, as printed expressions.

use proc_macro2::TokenStream;
use quote::quote;

use crate::expr::Printer;
use crate::topology::Topology;

/// The printed expressions: per body `[mass, spring, damper, quad_damper, force]`, per
/// coupling its damper, per space its pressure.
#[derive(Clone, Debug, Default)]
pub(crate) struct ExtrasText {
    pub bodies: Vec<[String; 5]>,
    pub coupling_dampers: Vec<String>,
    pub space_pressures: Vec<String>,
}

/// The texts of the extras (shared by the macro's emission and the compiled models' statics).
pub(crate) fn texts(topo: &Topology, p: &Printer) -> ExtrasText {
    ExtrasText {
        bodies: topo
            .bodies
            .iter()
            .map(|b| [b.mass, b.spring, b.damper, b.quad_damper, b.force].map(|e| p.expr(e)))
            .collect(),
        coupling_dampers: topo.couplings.iter().map(|c| p.expr(c.damper)).collect(),
        space_pressures: topo.spaces.iter().map(|s| p.expr(s.pressure)).collect(),
    }
}

/// `body_elements: &[..], coupling_dampers: &[..], space_pressures: &[..],`.
pub(crate) fn fields(t: &ExtrasText, krate: &TokenStream) -> TokenStream {
    let bodies = t.bodies.iter().map(|[m, k, c, cq, f]| {
        quote! {
            #krate::BodyElementsInfo { mass: #m, spring: #k, damper: #c, quad_damper: #cq, force: #f }
        }
    });
    let couplings = &t.coupling_dampers;
    let spaces = &t.space_pressures;
    quote! {
        body_elements: &[#(#bodies),*],
        coupling_dampers: &[#(#couplings),*],
        space_pressures: &[#(#spaces),*],
    }
}
