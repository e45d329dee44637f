//! The `TopologyInfo` fields only the bond graph reads: body elements, coupling dampers and
//! the spaces' given pressures, as printed expressions.

use proc_macro2::TokenStream;
use quote::quote;

use crate::expr::Printer;
use crate::topology::Topology;

/// `body_elements: &[..], coupling_dampers: &[..], space_pressures: &[..],`.
pub fn fields(topo: &Topology, p: &Printer, krate: &TokenStream) -> TokenStream {
    let bodies = topo.bodies.iter().map(|b| {
        let [m, k, c, cq, f] = [b.mass, b.spring, b.damper, b.quad_damper, b.force].map(|e| p.expr(e));
        quote! {
            #krate::BodyElementsInfo { mass: #m, spring: #k, damper: #c, quad_damper: #cq, force: #f }
        }
    });
    let couplings = topo.couplings.iter().map(|c| p.expr(c.damper));
    let spaces = topo.spaces.iter().map(|s| p.expr(s.pressure));
    quote! {
        body_elements: &[#(#bodies),*],
        coupling_dampers: &[#(#couplings),*],
        space_pressures: &[#(#spaces),*],
    }
}
