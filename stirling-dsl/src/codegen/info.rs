//! Static descriptions emitted with a model: parameters, bodies, states, topology.

use proc_macro2::TokenStream;
use quote::quote;

use super::layout::Layout;
use crate::expr::{Printer, Style};
use crate::topology::{BlockKind, Topology, Vessel};

mod bond_extras;

/// `&[ParamInfo { .. }, ..]`.
pub fn params(topo: &Topology, krate: &TokenStream) -> TokenStream {
    let items = topo.params.iter().map(|p| {
        let (name, default, unit, doc) = (&p.name, p.default, &p.unit, &p.doc);
        let bounds = match p.bounds {
            Some((lo, hi)) => quote!(Some((#lo, #hi))),
            None => quote!(None),
        };
        quote! { #krate::ParamInfo { name: #name, default: #default, unit: #unit, doc: #doc, bounds: #bounds } }
    });
    quote! { &[#(#items),*] }
}

/// `&[BodyInfo { .. }, ..]`.
pub fn bodies(topo: &Topology, krate: &TokenStream) -> TokenStream {
    let items = topo.bodies.iter().map(|b| {
        let (name, pos, vel) = (&b.name, &b.pos, &b.vel);
        quote! { #krate::BodyInfo { name: #name, pos: #pos, vel: #vel } }
    });
    quote! { &[#(#items),*] }
}

/// `&[SensorInfo { .. }, ..]`.
pub fn sensors(topo: &Topology, krate: &TokenStream) -> TokenStream {
    let items = topo.sensors.iter().map(|s| {
        let (name, state, unit) = (&s.name, &s.state, &s.unit);
        let (expr, reads) = match &s.expr {
            Some(e) => (super::sensors::text(topo, e), e.reads.clone()),
            None => (String::new(), vec![s.state.clone()]),
        };
        quote! {
            #krate::SensorInfo {
                name: #name, state: #state, expr: #expr, reads: &[#(#reads),*], unit: #unit
            }
        }
    });
    quote! { &[#(#items),*] }
}

/// `&[EffectSite { .. }, ..]`.
pub fn effect_sites(topo: &Topology, krate: &TokenStream) -> TokenStream {
    let items = topo.effects.iter().map(|e| {
        let (effect, at, params) = (&e.effect, &e.at, &e.params);
        quote! { #krate::EffectSite { effect: #effect, at: #at, params: &[#(#params),*] } }
    });
    quote! { &[#(#items),*] }
}

/// Vessel-element offset of CV `i`: `(scalars before, arrays before)`.
fn cv_element_offset(topo: &Topology, i: usize) -> (usize, usize) {
    let before = &topo.cvs[..i];
    (
        before.iter().filter(|c| !c.array).count(),
        before.iter().filter(|c| c.array).count(),
    )
}

/// Wall-element offset of wall `w`: `(scalars before, arrays before)`.
fn wall_element_offset(topo: &Topology, w: usize) -> (usize, usize) {
    let before = &topo.walls[..w];
    (
        before.iter().filter(|x| !x.array).count(),
        before.iter().filter(|x| x.array).count(),
    )
}

/// Body of `fn states(&self) -> Vec<StateInfo>` for one closure.
pub fn states(lay: &Layout, krate: &TokenStream) -> TokenStream {
    let topo = lay.topo;
    let pushes = lay.sys.blocks.iter().map(|b| {
        let (kind, unit, what, elem) = match b.kind {
            BlockKind::Position(k) => (quote!(Position), "m", format!("position of the {}", topo.bodies[k].name), Some(k)),
            BlockKind::Velocity(k) => (quote!(Velocity), "m/s", format!("velocity of the {}", topo.bodies[k].name), Some(k)),
            BlockKind::Pressure(i) => (quote!(Pressure), "Pa", format!("gas pressure in CV {}", topo.cvs[i].name), None),
            BlockKind::Mass(i) => (quote!(Mass), "kg", format!("gas mass in CV {}", topo.cvs[i].name), None),
            BlockKind::WallTemperature(w) => (quote!(WallTemperature), "K", format!("temperature of wall {}", topo.walls[w].name), None),
        };
        let (s, a) = match b.kind {
            BlockKind::Pressure(i) | BlockKind::Mass(i) => cv_element_offset(topo, i),
            BlockKind::WallTemperature(w) => wall_element_offset(topo, w),
            _ => (0, 0),
        };
        let index = match elem {
            Some(k) => quote!(#k),
            None => quote!(#s + #a * n + j),
        };
        let name = &b.name;
        let (name_expr, meaning_expr, range) = if b.array {
            (quote!(format!("{}[{}]", #name, j)), quote!(format!("{}[{}]", #what, j)), quote!(0..n))
        } else {
            (quote!(#name.to_string()), quote!(#what.to_string()), quote!(0..1usize))
        };
        quote! {
            for j in #range {
                v.push(#krate::StateInfo { name: #name_expr, kind: #krate::StateKind::#kind(#index), unit: #unit, meaning: #meaning_expr });
            }
        }
    });
    quote! {
        let n = self.n;
        let mut v = Vec::new();
        #(#pushes)*
        v
    }
}

/// Names of the vessel elements (CV elements, then spaces).
pub fn vessel_names(topo: &Topology) -> TokenStream {
    let cvs = topo.cvs.iter().map(|c| {
        let name = &c.name;
        if c.array {
            quote! { for j in 0..self.n { v.push(format!("{}[{}]", #name, j)); } }
        } else {
            quote! { v.push(#name.to_string()); }
        }
    });
    let spaces = topo.spaces.iter().map(|s| &s.name);
    quote! {
        let mut v = Vec::new();
        #(#cvs)*
        #(v.push(#spaces.to_string());)*
        v
    }
}

/// The static `TopologyInfo`.
pub fn topology(topo: &Topology, lay: &Layout, krate: &TokenStream) -> TokenStream {
    let namer = |s| lay.name(s);
    let p = Printer::new(&topo.arena, Style::Text, &namer);
    let body_name = |k: usize| topo.bodies[k].name.clone();
    let face = |f: &crate::topology::FaceDecl| {
        let (b, c) = (body_name(f.body), p.expr(f.coeff));
        quote! { #krate::FaceInfo { body: #b, coeff: #c } }
    };
    let mut vessels = Vec::new();
    for c in &topo.cvs {
        let faces = c.faces.iter().map(face);
        let ports = c.ports.iter().map(|pt| {
            let (n, w) = (&pt.name, p.expr(pt.wall));
            let r = match pt.wall_ref {
                Some(k) => {
                    let name = &topo.walls[k].name;
                    quote!(Some(#name))
                }
                None => quote!(None),
            };
            quote! { #krate::PortInfo { name: #n, wall: #w, wall_ref: #r } }
        });
        let (name, array) = (&c.name, c.array);
        vessels.push(quote! { #krate::VesselInfo { name: #name, is_cv: true, array: #array, faces: &[#(#faces),*], ports: &[#(#ports),*] } });
    }
    for s in &topo.spaces {
        let faces = s.faces.iter().map(face);
        let name = &s.name;
        vessels.push(quote! { #krate::VesselInfo { name: #name, is_cv: false, array: false, faces: &[#(#faces),*], ports: &[] } });
    }
    let links = topo.links.iter().map(|l| {
        let end = |e: &crate::topology::End| match e.vessel {
            Vessel::Cv(i) => crate::topology::frame::rename(
                &format!("{}{}", topo.cvs[i].name, at_text(e.at)),
                crate::topology::frame::Place::Own,
            ),
            Vessel::Space(s) => topo.spaces[s].name.clone(),
            Vessel::Wall(w) => topo.walls[w].name.clone(),
        };
        let (f, t, r, chain) = (
            end(&l.from),
            end(&l.to),
            p.expr(l.resistance),
            l.is_chain() || l.is_per_section(),
        );
        quote! { #krate::LinkInfo { from: #f, to: #t, resistance: #r, chain: #chain } }
    });
    let (walls, conductions) = wall_infos(topo, &p, krate);
    let bodies = topo.bodies.iter().map(|b| &b.name);
    let couplings = topo.couplings.iter().map(|c| {
        let (a, b) = (body_name(c.a), body_name(c.b));
        quote! { (#a, #b) }
    });
    let (name, doc) = (&topo.name, &topo.doc);
    let extras = bond_extras::fields(topo, &p, krate);
    quote! {
        #krate::TopologyInfo {
            name: #name, doc: #doc, bodies: &[#(#bodies),*], couplings: &[#(#couplings),*],
            vessels: &[#(#vessels),*], links: &[#(#links),*],
            walls: &[#(#walls),*], conductions: &[#(#conductions),*], #extras
        }
    }
}

/// The `WallInfo`s and `ConductionInfo`s of `topo`.
fn wall_infos(
    topo: &Topology,
    p: &Printer,
    krate: &TokenStream,
) -> (Vec<TokenStream>, Vec<TokenStream>) {
    let walls = topo.walls.iter().map(|w| {
        let (name, array) = (&w.name, w.array);
        let (c, q) = (p.expr(w.capacity), p.expr(w.input));
        quote! { #krate::WallInfo { name: #name, array: #array, capacity: #c, input: #q } }
    });
    let end = |e: &crate::topology::HeatEnd| match e {
        crate::topology::HeatEnd::Wall(e) => match e.vessel {
            Vessel::Wall(w) => (format!("{}{}", topo.walls[w].name, at_text(e.at)), false),
            _ => unreachable!("a conduction end is a wall"),
        },
        crate::topology::HeatEnd::Fixed(t) => (p.expr(*t), true),
    };
    let conductions = topo.conductions.iter().map(|c| {
        let ((f, ff), (t, tf)) = (end(&c.from), end(&c.to));
        let (g, chain) = (p.expr(c.conductance), c.is_chain());
        quote! { #krate::ConductionInfo { from: #f, to: #t, conductance: #g, chain: #chain, fixed: [#ff, #tf] } }
    });
    (walls.collect(), conductions.collect())
}

fn at_text(at: crate::expr::At) -> String {
    match at {
        crate::expr::At::Scalar => String::new(),
        crate::expr::At::Rel(r) => format!("[{}]", crate::topology::frame::index_text(r)),
        crate::expr::At::First => "[0]".into(),
        crate::expr::At::Last => "[n-1]".into(),
    }
}
