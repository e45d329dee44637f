//! Static descriptions emitted with a model: parameters, bodies, states, topology.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

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

/// What the states of block `b` are: the kind's name, the unit, the meaning, and the
/// element index of its first state as `(scalars before, arrays before)` (the body's number
/// for a body's block) with whether it is a body's.
pub(crate) fn block_meaning(
    topo: &Topology,
    kind: BlockKind,
) -> (&'static str, &'static str, String, (usize, usize), bool) {
    match kind {
        BlockKind::Position(k) => (
            "Position",
            if topo.bodies[k].rotary { "rad" } else { "m" },
            if topo.bodies[k].rotary {
                format!("angle of the flywheel {}", topo.bodies[k].name)
            } else {
                format!("position of the {}", topo.bodies[k].name)
            },
            (k, 0),
            true,
        ),
        BlockKind::Velocity(k) => (
            "Velocity",
            if topo.bodies[k].rotary {
                "rad/s"
            } else {
                "m/s"
            },
            if topo.bodies[k].rotary {
                format!("angular velocity of the flywheel {}", topo.bodies[k].name)
            } else {
                format!("velocity of the {}", topo.bodies[k].name)
            },
            (k, 0),
            true,
        ),
        BlockKind::Pressure(i) => (
            "Pressure",
            "Pa",
            format!("gas pressure in CV {}", topo.cvs[i].name),
            cv_element_offset(topo, i),
            false,
        ),
        BlockKind::Mass(i) => (
            "Mass",
            "kg",
            format!("gas mass in CV {}", topo.cvs[i].name),
            cv_element_offset(topo, i),
            false,
        ),
        BlockKind::WallTemperature(w) => (
            "WallTemperature",
            "K",
            format!("temperature of wall {}", topo.walls[w].name),
            wall_element_offset(topo, w),
            false,
        ),
    }
}

/// Body of `fn states(&self) -> Vec<StateInfo>` for one closure.
pub fn states(lay: &Layout, krate: &TokenStream) -> TokenStream {
    let topo = lay.topo;
    let pushes = lay.sys.blocks.iter().map(|b| {
        let (kind, unit, what, (s, a), body) = block_meaning(topo, b.kind);
        let kind = format_ident!("{}", kind);
        let index = if body {
            quote!(#s)
        } else {
            quote!(#s + #a * n + j)
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

/// The strings of a `TopologyInfo`, as the emitted static and the run-time model
/// (`crate::compiled`) both hold them.
pub(crate) struct TopologyText {
    /// `(name, is_cv, array, faces (body, coeff, modulus), ports (name, wall, wall_ref))`.
    pub vessels: Vec<(
        String,
        bool,
        bool,
        Vec<(String, String, String)>,
        Vec<(String, String, Option<String>)>,
    )>,
    /// `(from, to, resistance, chain)`.
    pub links: Vec<(String, String, String, bool)>,
    /// `(name, array, capacity, input)`.
    pub walls: Vec<(String, bool, String, String)>,
    /// `(from, to, conductance, chain, fixed)`.
    pub conductions: Vec<(String, String, String, bool, [bool; 2])>,
    pub couplings: Vec<(String, String)>,
    /// What only the bond graph reads ([`bond_extras`]).
    pub extras: bond_extras::ExtrasText,
}

/// The strings of the topology's description.
pub(crate) fn topology_text(topo: &Topology, lay: &Layout) -> TopologyText {
    let namer = |s| lay.name(s);
    let p = Printer::new(&topo.arena, Style::Text, &namer);
    let body_name = |k: usize| topo.bodies[k].name.clone();
    // a face on a mechanism: its modulus `ds/dtheta`, printed (empty for a plain face)
    let face = |f: &crate::topology::FaceDecl| {
        let modulus = f.mechanism.map_or(String::new(), |m| {
            let m = &topo.mechanisms[m];
            format!("{}({})", p.expr(m.ratio), topo.bodies[m.body].pos)
        });
        (body_name(f.body), p.expr(f.coeff), modulus)
    };
    let mut vessels = Vec::new();
    for c in &topo.cvs {
        let faces = c.faces.iter().map(face).collect();
        let ports = c
            .ports
            .iter()
            .map(|pt| {
                let r = pt.wall_ref.map(|k| topo.walls[k].name.clone());
                (pt.name.clone(), p.expr(pt.wall), r)
            })
            .collect();
        vessels.push((c.name.clone(), true, c.array, faces, ports));
    }
    for s in &topo.spaces {
        let faces = s.faces.iter().map(face).collect();
        vessels.push((s.name.clone(), false, false, faces, Vec::new()));
    }
    let links = topo
        .links
        .iter()
        .map(|l| {
            let end = |e: &crate::topology::End| match e.vessel {
                Vessel::Cv(i) => crate::topology::frame::rename(
                    &format!("{}{}", topo.cvs[i].name, at_text(e.at)),
                    crate::topology::frame::Place::Own,
                ),
                Vessel::Space(s) => topo.spaces[s].name.clone(),
                Vessel::Wall(w) => topo.walls[w].name.clone(),
            };
            let chain = l.is_chain() || l.is_per_section();
            (end(&l.from), end(&l.to), p.expr(l.resistance), chain)
        })
        .collect();
    let walls = topo
        .walls
        .iter()
        .map(|w| (w.name.clone(), w.array, p.expr(w.capacity), p.expr(w.input)))
        .collect();
    let end = |e: &crate::topology::HeatEnd| match e {
        crate::topology::HeatEnd::Wall(e) => match e.vessel {
            Vessel::Wall(w) => (format!("{}{}", topo.walls[w].name, at_text(e.at)), false),
            // a conduction end is a wall (the check refuses anything else)
            _ => (String::new(), false),
        },
        crate::topology::HeatEnd::Fixed(t) => (p.expr(*t), true),
    };
    let conductions = topo
        .conductions
        .iter()
        .map(|c| {
            let ((f, ff), (t, tf)) = (end(&c.from), end(&c.to));
            (f, t, p.expr(c.conductance), c.is_chain(), [ff, tf])
        })
        .collect();
    let couplings = topo
        .couplings
        .iter()
        .map(|c| (body_name(c.a), body_name(c.b)))
        .collect();
    TopologyText {
        vessels,
        links,
        walls,
        conductions,
        couplings,
        extras: bond_extras::texts(topo, &p),
    }
}

/// The static `TopologyInfo`.
pub fn topology(topo: &Topology, lay: &Layout, krate: &TokenStream) -> TokenStream {
    let t = topology_text(topo, lay);
    let vessels = t.vessels.iter().map(|(name, is_cv, array, faces, ports)| {
        let faces = faces
            .iter()
            .map(|(b, c, m)| quote! { #krate::FaceInfo { body: #b, coeff: #c, modulus: #m } });
        let ports = ports.iter().map(|(n, w, r)| {
            let r = match r {
                Some(name) => quote!(Some(#name)),
                None => quote!(None),
            };
            quote! { #krate::PortInfo { name: #n, wall: #w, wall_ref: #r } }
        });
        quote! { #krate::VesselInfo { name: #name, is_cv: #is_cv, array: #array, faces: &[#(#faces),*], ports: &[#(#ports),*] } }
    });
    let links = t.links.iter().map(|(f, to, r, chain)| {
        quote! { #krate::LinkInfo { from: #f, to: #to, resistance: #r, chain: #chain } }
    });
    let walls = t.walls.iter().map(|(name, array, c, q)| {
        quote! { #krate::WallInfo { name: #name, array: #array, capacity: #c, input: #q } }
    });
    let conductions = t.conductions.iter().map(|(f, to, g, chain, [ff, tf])| {
        quote! { #krate::ConductionInfo { from: #f, to: #to, conductance: #g, chain: #chain, fixed: [#ff, #tf] } }
    });
    let bodies = topo.bodies.iter().map(|b| &b.name);
    let couplings = t.couplings.iter().map(|(a, b)| quote! { (#a, #b) });
    let (name, doc) = (&topo.name, &topo.doc);
    let extras = bond_extras::fields(&t.extras, krate);
    quote! {
        #krate::TopologyInfo {
            name: #name, doc: #doc, bodies: &[#(#bodies),*], couplings: &[#(#couplings),*],
            vessels: &[#(#vessels),*], links: &[#(#links),*],
            walls: &[#(#walls),*], conductions: &[#(#conductions),*], #extras
        }
    }
}

fn at_text(at: crate::expr::At) -> String {
    match at {
        crate::expr::At::Scalar => String::new(),
        crate::expr::At::Rel(r) => format!("[{}]", crate::topology::frame::index_text(r)),
        crate::expr::At::First => "[0]".into(),
        crate::expr::At::Last => "[n-1]".into(),
    }
}
