//! The descriptions a [`crate::Model`] hands out as `&'static` (parameters, bodies, sensors,
//! effect sites, the topology): a compiled model owns them by leaking one allocation each,
//! once per loaded definition (not per `n` or closure), which lives as long as the process.
//! A program that loads a few files leaks a few kilobytes; one that loads files in a loop
//! leaks that much per load.

use crate::codegen::info::topology_text;
use crate::codegen::Layout;
use crate::runtime::{
    BodyElementsInfo, BodyInfo, ConductionInfo, EffectSite, FaceInfo, LinkInfo, ParamInfo,
    PortInfo, SensorInfo, TopologyInfo, VesselInfo, WallInfo,
};
use crate::topology::{System, Topology};

/// The leaked descriptions of one definition.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Statics {
    pub name: &'static str,
    pub params: &'static [ParamInfo],
    pub bodies: &'static [BodyInfo],
    pub sensors: &'static [SensorInfo],
    pub effect_sites: &'static [EffectSite],
    pub topology: &'static TopologyInfo,
    pub free: &'static [&'static str],
}

fn s(text: &str) -> &'static str {
    Box::leak(text.to_string().into_boxed_str())
}

fn list<T>(items: Vec<T>) -> &'static [T] {
    Box::leak(items.into_boxed_slice())
}

impl Statics {
    /// The descriptions of `topo` (`sys`: either closure's system, for the printed names).
    pub(crate) fn new(topo: &Topology, sys: &System) -> Statics {
        let params = topo
            .params
            .iter()
            .map(|p| ParamInfo {
                name: s(&p.name),
                default: p.default,
                unit: s(&p.unit),
                doc: s(&p.doc),
                bounds: p.bounds,
            })
            .collect();
        let bodies = topo
            .bodies
            .iter()
            .map(|b| BodyInfo {
                name: s(&b.name),
                pos: s(&b.pos),
                vel: s(&b.vel),
            })
            .collect();
        let sensors = topo
            .sensors
            .iter()
            .map(|x| {
                let (expr, reads) = match &x.expr {
                    Some(e) => (crate::codegen::sensors::text(topo, e), e.reads.clone()),
                    None => (String::new(), vec![x.state.clone()]),
                };
                SensorInfo {
                    name: s(&x.name),
                    state: s(&x.state),
                    expr: s(&expr),
                    reads: list(reads.iter().map(|r| s(r)).collect()),
                    unit: s(&x.unit),
                }
            })
            .collect();
        let effect_sites = topo
            .effects
            .iter()
            .map(|e| EffectSite {
                effect: s(&e.effect),
                at: s(&e.at),
                params: list(e.params.iter().map(|p| s(p)).collect()),
            })
            .collect();
        Statics {
            name: s(&topo.name),
            params: list(params),
            bodies: list(bodies),
            sensors: list(sensors),
            effect_sites: list(effect_sites),
            topology: Box::leak(Box::new(topology(topo, sys))),
            free: list(topo.free.iter().map(|f| s(f)).collect()),
        }
    }
}

/// The topology's description, as the emitted `TopologyInfo` holds it.
fn topology(topo: &Topology, sys: &System) -> TopologyInfo {
    let t = topology_text(topo, &Layout { sys, topo });
    let vessels = t
        .vessels
        .into_iter()
        .map(|(name, is_cv, array, faces, ports)| VesselInfo {
            name: s(&name),
            is_cv,
            array,
            faces: list(
                faces
                    .iter()
                    .map(|(b, c, m)| FaceInfo {
                        body: s(b),
                        coeff: s(c),
                        modulus: s(m),
                    })
                    .collect(),
            ),
            ports: list(
                ports
                    .iter()
                    .map(|(n, w, r)| PortInfo {
                        name: s(n),
                        wall: s(w),
                        wall_ref: r.as_deref().map(s),
                    })
                    .collect(),
            ),
        })
        .collect();
    let links = t
        .links
        .iter()
        .map(|(f, to, r, chain)| LinkInfo {
            from: s(f),
            to: s(to),
            resistance: s(r),
            chain: *chain,
        })
        .collect();
    let walls = t
        .walls
        .iter()
        .map(|(name, array, c, q)| WallInfo {
            name: s(name),
            array: *array,
            capacity: s(c),
            input: s(q),
        })
        .collect();
    let conductions = t
        .conductions
        .iter()
        .map(|(f, to, g, chain, fixed)| ConductionInfo {
            from: s(f),
            to: s(to),
            conductance: s(g),
            chain: *chain,
            fixed: *fixed,
        })
        .collect();
    TopologyInfo {
        name: s(&topo.name),
        doc: s(&topo.doc),
        bodies: list(topo.bodies.iter().map(|b| s(&b.name)).collect()),
        couplings: list(t.couplings.iter().map(|(a, b)| (s(a), s(b))).collect()),
        vessels: list(vessels),
        links: list(links),
        walls: list(walls),
        conductions: list(conductions),
        body_elements: list(
            t.extras
                .bodies
                .iter()
                .map(|[m, k, c, cq, f]| BodyElementsInfo {
                    mass: s(m),
                    spring: s(k),
                    damper: s(c),
                    quad_damper: s(cq),
                    force: s(f),
                })
                .collect(),
        ),
        coupling_dampers: list(t.extras.coupling_dampers.iter().map(|d| s(d)).collect()),
        space_pressures: list(t.extras.space_pressures.iter().map(|d| s(d)).collect()),
    }
}
