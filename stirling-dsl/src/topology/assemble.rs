//! The energetic assembly rules (docs/physics.md sections 1, 2, 4 and 6).
//!
//! Per control volume `i` (ideal gas, `cv = R/(gamma-1)`):
//!
//! ```text
//! V_i  = V_i0 + sum_k a_ik q_k            T_i = P_i V_i / (m_i R)
//! Q_i  = sum_ports h Aw (Tw - T_i)        mdot = (P_from - P_to) / R_link
//! H    = cp mdot (s T_from + (1-s) T_to),  s = (1 + tanh(mdot / mdot_eps)) / 2
//! P_i' = ((gamma-1)(Q_i + H_in - H_out) - gamma P_i V_i') / V_i
//! m_i' = mdot_in - mdot_out
//! ```
//! and per body `m q'' = sum_i a_ik P_i + F - k q - c q' - cq q'|q'| - couplings`.

use super::decl::{LinkDecl, Topology, Vessel};
use super::frame::{place, Place};
use super::links::{end_name, end_place, enthalpy, orifice_flow, quadratic_flow, rel_min, touches};
use super::system::{BlockInfo, BlockKind, Row, System, Variant, VesselTerms, VARIANTS};
use super::walls::PortHeat;
use crate::expr::{At, Func, Id, Sym};
use crate::Closure;

/// Where a row is assembled: a scalar block, or a section variant of an array CV or wall.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum RowAt {
    Scalar,
    Array(Vessel, Variant),
}

/// Quantities of a CV in its own frame.
#[derive(Clone, Copy, Debug)]
pub(super) struct CvTemplate {
    pub(super) p: Id,
    pub(super) m: Id,
    pub(super) v: Id,
    pub(super) vdot: Id,
    pub(super) t: Id,
    pub(super) q: Id,
    pub(super) m0: Id,
}

/// Assemble the equations of `topo` under `closure`.
pub fn assemble(topo: &mut Topology, closure: Closure) -> System {
    Assembler::new(topo, closure).run()
}

pub(super) struct Assembler<'t> {
    pub(super) t: &'t mut Topology,
    closure: Closure,
    array_blocks: Vec<bool>,
    pub(super) cv: Vec<CvTemplate>,
    /// Per CV, the heat of each port that names a declared wall, in the CV's frame.
    pub(super) port_heat: Vec<Vec<PortHeat>>,
    /// Templates summed over the sections (`Sym::Sum(k)`), from per-section links.
    pub(super) sums: Vec<Id>,
}

impl<'t> Assembler<'t> {
    fn new(t: &'t mut Topology, closure: Closure) -> Self {
        let (nb, ncv) = (t.bodies.len(), t.cvs.len());
        let mut array_blocks = vec![false; 2 * nb + 2 * ncv + t.walls.len()];
        for (i, c) in t.cvs.iter().enumerate() {
            array_blocks[2 * nb + i] = c.array;
            array_blocks[2 * nb + ncv + i] = c.array;
        }
        for (w, wall) in t.walls.iter().enumerate() {
            array_blocks[Topology::wall_block(nb, ncv, w) as usize] = wall.array;
        }
        Self {
            t,
            closure,
            array_blocks,
            cv: Vec::new(),
            port_heat: Vec::new(),
            sums: Vec::new(),
        }
    }

    fn p_block(&self, i: usize) -> u32 {
        (2 * self.t.bodies.len() + i) as u32
    }

    fn m_block(&self, i: usize) -> u32 {
        (2 * self.t.bodies.len() + self.t.cvs.len() + i) as u32
    }

    fn has_mass_state(&self, i: usize) -> bool {
        self.closure == Closure::Full && self.t.cv_is_linked(i)
    }

    fn own(&self, i: usize) -> At {
        if self.t.cvs[i].array {
            At::Rel(0)
        } else {
            At::Scalar
        }
    }

    fn label(&self, i: usize, what: &str) -> String {
        let c = &self.t.cvs[i];
        if c.array {
            format!("{what}_{}[j]", c.name)
        } else {
            format!("{what}_{}", c.name)
        }
    }

    fn run(mut self) -> System {
        for i in 0..self.t.cvs.len() {
            let tpl = self.cv_template(i);
            self.cv.push(tpl);
        }
        let blocks = self.blocks();
        let rows = blocks.iter().map(|b| self.row(b)).collect();
        let init = blocks.iter().map(|b| self.init_row(b)).collect();
        let forces = (0..self.t.bodies.len()).map(|k| self.force(k)).collect();
        let mut vessels: Vec<VesselTerms> =
            (0..self.t.cvs.len()).map(|i| self.cv_terms(i)).collect();
        vessels.extend((0..self.t.spaces.len()).map(|s| self.space_terms(s)));
        let (mech_energy, mech_power) = (self.mech_energy(), self.mech_power());
        let (walls, wall_boundary_heat) = self.wall_terms();
        let array_blocks = self.array_blocks.clone();
        let sums = std::mem::take(&mut self.sums);
        System {
            closure: self.closure,
            blocks,
            rows,
            init,
            forces,
            vessels,
            mech_energy,
            mech_power,
            walls,
            wall_boundary_heat,
            sums,
            array_blocks,
        }
    }

    fn blocks(&self) -> Vec<BlockInfo> {
        let mut out = Vec::new();
        for (k, b) in self.t.bodies.iter().enumerate() {
            out.push(BlockInfo {
                sym: Topology::pos_block(k),
                name: b.pos.clone(),
                array: false,
                kind: BlockKind::Position(k),
            });
            out.push(BlockInfo {
                sym: Topology::vel_block(k),
                name: b.vel.clone(),
                array: false,
                kind: BlockKind::Velocity(k),
            });
        }
        for (i, c) in self.t.cvs.iter().enumerate() {
            let name = format!("P_{}", c.name);
            out.push(BlockInfo {
                sym: self.p_block(i),
                name,
                array: c.array,
                kind: BlockKind::Pressure(i),
            });
        }
        for (i, c) in self.t.cvs.iter().enumerate() {
            if self.has_mass_state(i) {
                let name = format!("m_{}", c.name);
                out.push(BlockInfo {
                    sym: self.m_block(i),
                    name,
                    array: c.array,
                    kind: BlockKind::Mass(i),
                });
            }
        }
        out.extend(self.wall_blocks());
        out
    }

    /// Position and velocity symbols of body `k`.
    pub(super) fn body_syms(&mut self, k: usize) -> (Id, Id) {
        let a = &mut self.t.arena;
        (
            a.sym(Sym::State(Topology::pos_block(k), At::Scalar)),
            a.sym(Sym::State(Topology::vel_block(k), At::Scalar)),
        )
    }

    /// `sum coeff * q` and `sum coeff * v` over faces.
    pub(super) fn face_sums(&mut self, faces: &[super::decl::FaceDecl]) -> (Id, Id) {
        let (mut dv, mut vdot) = (self.t.arena.num(0.0), self.t.arena.num(0.0));
        for f in faces.iter().cloned() {
            let (q, v) = self.body_syms(f.body);
            let a = &mut self.t.arena;
            let (cq, cv) = (a.mul(f.coeff, q), a.mul(f.coeff, v));
            dv = a.add(dv, cq);
            vdot = a.add(vdot, cv);
        }
        (dv, vdot)
    }

    /// The rest state of section 6: every body state zero, every wall temperature at its
    /// declared rest value (in the frame of the expression).
    fn at_rest(&mut self, id: Id) -> Id {
        let rest = self.wall_rests();
        self.t.arena.subst(id, &mut |a, s| match s {
            Sym::State(b, _) => Some(rest.get(&b).copied().unwrap_or_else(|| a.num(0.0))),
            _ => None,
        })
    }

    fn cv_template(&mut self, i: usize) -> CvTemplate {
        let c = self.t.cvs[i].clone();
        let own = self.own(i);
        let (dv, vdot_raw) = self.face_sums(&c.faces);
        let v_raw = self.t.arena.add(c.volume, dv);
        let (vl, vdl, tl, ql, m0l) = (
            self.label(i, "V"),
            self.label(i, "Vdot"),
            self.label(i, "T"),
            self.label(i, "Q"),
            self.label(i, "m0"),
        );
        let m0_raw = self.rest_mass(i, v_raw);
        let (pb, mb) = (self.p_block(i), self.m_block(i));
        let has_m = self.has_mass_state(i);
        let gas = self
            .t
            .gas
            .clone()
            .expect("checked: a model with CVs declares its gas");
        let a = &mut self.t.arena;
        let v = a.named(&vl, v_raw);
        let vdot = a.named(&vdl, vdot_raw);
        let m0 = a.named(&m0l, m0_raw);
        let p = a.sym(Sym::State(pb, own));
        let m = if has_m {
            a.sym(Sym::State(mb, own))
        } else {
            m0
        };
        let pv = a.mul(p, v);
        let mr = a.mul(m, gas.r);
        let t_raw = a.div(pv, mr);
        let t = a.named(&tl, t_raw);
        let q_raw = self.heat(i, &c.ports, t);
        let q = self.t.arena.named(&ql, q_raw);
        CvTemplate {
            p,
            m,
            v,
            vdot,
            t,
            q,
            m0,
        }
    }

    /// `sum h A (Tw - T)` of CV `i`; the terms of ports to declared walls are named
    /// `Q_cv_port` and recorded for the walls' balances.
    fn heat(&mut self, i: usize, ports: &[super::decl::PortDecl], t: Id) -> Id {
        let mut q = self.t.arena.num(0.0);
        let mut to_walls = Vec::new();
        for port in ports {
            let label = self.port_label(i, &port.name);
            let a = &mut self.t.arena;
            let ha = a.mul(port.h, port.area);
            let dt = a.sub(port.wall, t);
            let mut term = a.mul(ha, dt);
            if let Some(wall) = port.wall_ref {
                term = a.named(&label, term);
                let summed = self.t.cvs[i].array && !self.t.walls[wall].array;
                to_walls.push(PortHeat { wall, q: term, summed });
            }
            q = a.add(q, term);
        }
        self.port_heat.push(to_walls);
        q
    }

    fn port_label(&self, i: usize, port: &str) -> String {
        let c = &self.t.cvs[i];
        let j = if c.array { "[j]" } else { "" };
        format!("Q_{}_{port}{j}", c.name)
    }

    /// `m_i0 = Pcharge V_i0 / (R T_i0)`, `T_i0 = sum h Aw Tw / sum h Aw` at rest.
    fn rest_mass(&mut self, i: usize, volume: Id) -> Id {
        let ports = self.t.cvs[i].ports.clone();
        let gas = self
            .t
            .gas
            .clone()
            .expect("checked: a model with CVs declares its gas");
        let (mut num, mut den) = (self.t.arena.num(0.0), self.t.arena.num(0.0));
        for port in &ports {
            let a = &mut self.t.arena;
            let ha = a.mul(port.h, port.area);
            let haw = a.mul(ha, port.wall);
            num = a.add(num, haw);
            den = a.add(den, ha);
        }
        let (num, den, v0) = (self.at_rest(num), self.at_rest(den), self.at_rest(volume));
        let a = &mut self.t.arena;
        let t0 = a.div(num, den);
        let pv = a.mul(gas.charge, v0);
        let rt = a.mul(gas.r, t0);
        a.div(pv, rt)
    }

    pub(super) fn placed(&mut self, id: Id, at: Place) -> Id {
        place(&mut self.t.arena, id, at, &self.array_blocks)
    }

    fn row(&mut self, b: &BlockInfo) -> Row {
        match b.kind {
            BlockKind::Position(k) => Row::Scalar(self.body_syms(k).1),
            BlockKind::Velocity(k) => Row::Scalar(self.acceleration(k)),
            BlockKind::Pressure(i) | BlockKind::Mass(i) => {
                let want_p = matches!(b.kind, BlockKind::Pressure(_));
                if b.array {
                    Row::Array(
                        VARIANTS.map(|v| self.balance(i, RowAt::Array(Vessel::Cv(i), v), want_p)),
                    )
                } else {
                    Row::Scalar(self.balance(i, RowAt::Scalar, want_p))
                }
            }
            BlockKind::WallTemperature(w) => {
                if b.array {
                    Row::Array(VARIANTS.map(|v| self.wall_row(w, RowAt::Array(Vessel::Wall(w), v))))
                } else {
                    Row::Scalar(self.wall_row(w, RowAt::Scalar))
                }
            }
        }
    }

    fn init_row(&mut self, b: &BlockInfo) -> Row {
        let id = match b.kind {
            BlockKind::Position(_) | BlockKind::Velocity(_) => self.t.arena.num(0.0),
            BlockKind::Pressure(_) => self.t.gas.as_ref().expect("checked").charge,
            BlockKind::Mass(i) => self.cv[i].m0,
            BlockKind::WallTemperature(w) => self.t.walls[w].rest,
        };
        if b.array {
            Row::Array([id; 4])
        } else {
            Row::Scalar(id)
        }
    }

    /// Pressure force on body `k`: `sum_i a_ik P_i` over CV and space faces.
    fn force(&mut self, k: usize) -> Id {
        let mut terms = Vec::new();
        for (i, c) in self.t.cvs.iter().enumerate() {
            for f in c.faces.iter().filter(|f| f.body == k) {
                terms.push((f.coeff, self.cv[i].p));
            }
        }
        for s in &self.t.spaces {
            for f in s.faces.iter().filter(|f| f.body == k) {
                terms.push((f.coeff, s.pressure));
            }
        }
        let name = format!("F_{}", self.t.bodies[k].name);
        let a = &mut self.t.arena;
        let products: Vec<Id> = terms.into_iter().map(|(c, p)| a.mul(c, p)).collect();
        let sum = a.sum(products);
        a.named(&name, sum)
    }

    /// `(F_pressure + F - k q - c v - cq v|v| - couplings) / m`.
    fn acceleration(&mut self, k: usize) -> Id {
        let fp = self.force(k);
        let b = self.t.bodies[k].clone();
        let (q, v) = self.body_syms(k);
        let coupling = self.coupling_force(k);
        let a = &mut self.t.arena;
        let kq = a.mul(b.spring, q);
        let cv = a.mul(b.damper, v);
        let av = a.func(Func::Abs, v);
        let vav = a.mul(v, av);
        let qv = a.mul(b.quad_damper, vav);
        let f = a.add(fp, b.force);
        let f = a.sub(f, kq);
        let f = a.sub(f, cv);
        let f = a.sub(f, qv);
        let f = a.add(f, coupling);
        a.div(f, b.mass)
    }

    /// Force of the coupling dampers on body `k`: `c (v_other - v_k)` each.
    fn coupling_force(&mut self, k: usize) -> Id {
        let mut total = self.t.arena.num(0.0);
        for c in self.t.couplings.clone() {
            let other = match (c.a == k, c.b == k) {
                (true, _) => c.b,
                (_, true) => c.a,
                _ => continue,
            };
            let (vk, vo) = (self.body_syms(k).1, self.body_syms(other).1);
            let a = &mut self.t.arena;
            let dv = a.sub(vo, vk);
            let f = a.mul(c.damper, dv);
            total = a.add(total, f);
        }
        total
    }

    /// `P'` (`want_p`) or `m'` of CV `i` at `row`.
    fn balance(&mut self, i: usize, row: RowAt, want_p: bool) -> Id {
        let (summed, flows): (Vec<Flow>, Vec<Flow>) =
            self.flows_of(i, row).into_iter().partition(|f| f.summed);
        let tpl = self.cv[i];
        let gas = self.t.gas.clone().expect("checked");
        let pick = |f: &Flow| if want_p { f.h } else { f.mdot };
        let start = if want_p { tpl.q } else { self.t.arena.num(0.0) };
        let mut total = signed(&mut self.t.arena, start, &flows, &pick);
        if !summed.is_empty() {
            let zero = self.t.arena.num(0.0);
            let template = signed(&mut self.t.arena, zero, &summed, &pick);
            let sum = self.reduce(template);
            total = self.t.arena.add(total, sum);
        }
        let a = &mut self.t.arena;
        if !want_p {
            return total;
        }
        let one = a.num(1.0);
        let gm1 = a.sub(gas.gamma, one);
        let qh = total;
        let e = a.mul(gm1, qh);
        let gp = a.mul(gas.gamma, tpl.p);
        let w = a.mul(gp, tpl.vdot);
        let num = a.sub(e, w);
        a.div(num, tpl.v)
    }

    /// The links touching CV `i` at `row`, with their flows in the row's frame.
    fn flows_of(&mut self, i: usize, row: RowAt) -> Vec<Flow> {
        let links = self.t.links.clone();
        let mut out = Vec::new();
        for l in &links {
            for (end, into) in [(&l.from, false), (&l.to, true)] {
                if end.vessel != Vessel::Cv(i) {
                    continue;
                }
                let base = if l.is_per_section() && matches!(end.at, At::Rel(_)) {
                    // the array end of a per-section link: every section
                    matches!(row, RowAt::Array(..)).then_some(0)
                } else {
                    touches(end.at, row, rel_min(l.from.at, l.to.at))
                };
                if let Some(base) = base {
                    out.push(self.flow(l, row, base, into));
                }
            }
        }
        out
    }

    /// The flow of link `l` seen from `row`, whose own section is `base` in the link's frame.
    pub(super) fn flow(&mut self, l: &LinkDecl, row: RowAt, base: i32, into: bool) -> Flow {
        let (p_from, t_from, from_name) = self.end_state(l.from.vessel, l.from.at, row, base);
        let (p_to, t_to, to_name) = self.end_state(l.to.vessel, l.to.at, row, base);
        let shift = if l.is_chain() {
            Place::Shift(-base)
        } else {
            Place::Own
        };
        let r = self.placed(l.resistance, shift);
        let rq = l.quadratic.map(|q| self.placed(q, shift));
        let g = l.conductance.map(|g| self.placed(g, shift));
        let orifice = l
            .orifice
            .map(|(c, dp0)| (self.placed(c, shift), self.placed(dp0, shift)));
        let name = format!("{from_name}_{to_name}");
        let gas = self.t.gas.clone().expect("checked");
        let a = &mut self.t.arena;
        let dp = a.sub(p_from, p_to);
        let mdot_raw = match (g, rq) {
            _ if orifice.is_some() => {
                let (c, dp0) = orifice.expect("checked");
                orifice_flow(a, dp, c, dp0)
            }
            (Some(g), _) => a.mul(g, dp),
            (None, None) => a.div(dp, r),
            (None, Some(rq)) => quadratic_flow(a, dp, r, rq),
        };
        let mdot = a.named(&format!("mdot_{name}"), mdot_raw);
        let h_raw = enthalpy(a, mdot, t_from, t_to, &gas);
        let h = a.named(&format!("H_{name}"), h_raw);
        let summed = l.is_per_section() && row == RowAt::Scalar;
        Flow {
            mdot,
            h,
            into,
            summed,
        }
    }

    /// `Sym::Sum(k)`: the sum of `template` (in an array's frame) over the sections.
    pub(super) fn reduce(&mut self, template: Id) -> Id {
        let k = match self.sums.iter().position(|&s| s == template) {
            Some(k) => k,
            None => {
                self.sums.push(template);
                self.sums.len() - 1
            }
        };
        self.t.arena.sym(Sym::Sum(k as u32))
    }

    /// Pressure, temperature and display name of a link end seen from `row`.
    fn end_state(&mut self, vessel: Vessel, at: At, row: RowAt, base: i32) -> (Id, Id, String) {
        match vessel {
            Vessel::Space(s) => {
                let sp = &self.t.spaces[s];
                (
                    sp.pressure,
                    sp.temperature
                        .expect("checked: a linked space has a temperature"),
                    sp.name.clone(),
                )
            }
            Vessel::Wall(_) => unreachable!("checked: a mass-flow link never ends at a wall"),
            Vessel::Cv(c) => {
                let pl = end_place(vessel, at, row, base);
                let tpl = self.cv[c];
                let (p, t) = (self.placed(tpl.p, pl), self.placed(tpl.t, pl));
                let shown = match pl {
                    Place::Own => At::Rel(0),
                    Place::Shift(k) => At::Rel(k),
                    Place::First => At::First,
                    Place::Last => At::Last,
                };
                (
                    p,
                    t,
                    end_name(&self.t.cvs[c].name, self.t.cvs[c].array, shown),
                )
            }
        }
    }
}

/// One link's flow as seen by a CV balance.
pub(super) struct Flow {
    pub(super) mdot: Id,
    pub(super) h: Id,
    pub(super) into: bool,
    /// A per-section link seen from its scalar end: the flow is a template to sum over `j`.
    pub(super) summed: bool,
}

/// `start + sum(into) - sum(out)` of the picked quantity of `flows`.
fn signed(a: &mut crate::expr::Arena, start: Id, flows: &[Flow], pick: &dyn Fn(&Flow) -> Id) -> Id {
    flows.iter().fold(start, |acc, f| {
        if f.into {
            a.add(acc, pick(f))
        } else {
            a.sub(acc, pick(f))
        }
    })
}
