//! The gas of one CV in its own frame (docs/physics.md sections 1, 2 and 6): volume,
//! temperature, the heat of its ports, the rest mass.

use super::assemble::{Assembler, CvTemplate};
use super::walls::PortHeat;
use crate::expr::{Id, Sym};

impl Assembler<'_> {
    /// The rest state of section 6: every body state zero, every wall temperature at its
    /// declared rest value (in the frame of the expression).
    pub(super) fn at_rest(&mut self, id: Id) -> Id {
        let rest = self.wall_rests();
        self.t.arena.subst(id, &mut |a, s| match s {
            Sym::State(b, _) => Some(rest.get(&b).copied().unwrap_or_else(|| a.num(0.0))),
            _ => None,
        })
    }

    pub(super) fn cv_template(&mut self, i: usize) -> CvTemplate {
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
    pub(super) fn heat(&mut self, i: usize, ports: &[super::decl::PortDecl], t: Id) -> Id {
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
                to_walls.push(PortHeat {
                    wall,
                    q: term,
                    summed,
                });
            }
            q = a.add(q, term);
        }
        self.port_heat.push(to_walls);
        q
    }

    pub(super) fn port_label(&self, i: usize, port: &str) -> String {
        let c = &self.t.cvs[i];
        let j = if c.array { "[j]" } else { "" };
        format!("Q_{}_{port}{j}", c.name)
    }

    /// `m_i0 = Pcharge V_i0 / (R T_i0)`, `T_i0 = sum h Aw Tw / sum h Aw` at rest.
    pub(super) fn rest_mass(&mut self, i: usize, volume: Id) -> Id {
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
}
