//! The energy budget's terms (docs/physics.md section 10): per vessel its gas energy, the heat
//! from outside and the boundary power of given-pressure spaces; the mechanical energy and the
//! power of dampers, couplings and extra forces.

use super::assemble::{Assembler, RowAt};
use super::decl::Vessel;
use super::system::VesselTerms;
use crate::expr::{Func, Id};

impl Assembler<'_> {
    pub(super) fn cv_terms(&mut self, i: usize) -> VesselTerms {
        let tpl = self.cv[i];
        let gas = self.t.gas.clone().expect("checked");
        let a = &mut self.t.arena;
        let one = a.num(1.0);
        let gm1 = a.sub(gas.gamma, one);
        let pv = a.mul(tpl.p, tpl.v);
        let energy = a.div(pv, gm1);
        let zero = a.num(0.0);
        // heat exchanged with a declared wall stays inside the system
        let heat = match self.port_heat[i].iter().map(|h| h.q).collect::<Vec<_>>() {
            internal if internal.is_empty() => tpl.q,
            internal => {
                let sum = a.sum(internal);
                a.sub(tpl.q, sum)
            }
        };
        let c = &self.t.cvs[i];
        VesselTerms {
            name: c.name.clone(),
            array: c.array,
            is_cv: true,
            pressure: tpl.p,
            volume: tpl.v,
            energy,
            heat,
            boundary: zero,
            mass: tpl.m,
            temperature: tpl.t,
        }
    }

    pub(super) fn space_terms(&mut self, s: usize) -> VesselTerms {
        let sp = self.t.spaces[s].clone();
        let (dv, vdot) = self.face_sums(&sp.faces);
        let outflow = self.space_enthalpy_out(s);
        let a = &mut self.t.arena;
        let volume = a.add(sp.volume, dv);
        let work = a.mul(sp.pressure, vdot);
        let boundary = a.sub(work, outflow);
        let zero = a.num(0.0);
        let temperature = sp.temperature.unwrap_or_else(|| a.num(f64::NAN));
        VesselTerms {
            name: sp.name.clone(),
            array: false,
            is_cv: false,
            pressure: sp.pressure,
            volume,
            energy: zero,
            heat: zero,
            boundary,
            mass: zero,
            temperature,
        }
    }

    /// Enthalpy flowing from the CVs into space `s` (scalar CV ends only; checked).
    pub(super) fn space_enthalpy_out(&mut self, s: usize) -> Id {
        let links = self.t.links.clone();
        let mut terms = Vec::new();
        for l in &links {
            let into_space = l.to.vessel == Vessel::Space(s);
            if !into_space && l.from.vessel != Vessel::Space(s) {
                continue;
            }
            let f = self.flow(l, RowAt::Scalar, 0, true);
            let h = if f.summed { self.reduce(f.h) } else { f.h };
            let a = &mut self.t.arena;
            terms.push(if into_space { h } else { a.neg(h) });
        }
        self.t.arena.sum(terms)
    }

    pub(super) fn mech_energy(&mut self) -> Id {
        let mut total = self.t.arena.num(0.0);
        for k in 0..self.t.bodies.len() {
            let b = self.t.bodies[k].clone();
            let (q, v) = self.body_syms(k);
            let a = &mut self.t.arena;
            let half = a.num(0.5);
            let (v2, q2) = (a.powi(v, 2), a.powi(q, 2));
            let (mv, kq) = (a.mul(b.mass, v2), a.mul(b.spring, q2));
            let s = a.add(mv, kq);
            let e = a.mul(half, s);
            total = a.add(total, e);
        }
        total
    }

    /// `sum v (F - c v - cq v|v|) - sum c (v_a - v_b)^2`.
    pub(super) fn mech_power(&mut self) -> Id {
        let mut total = self.t.arena.num(0.0);
        for k in 0..self.t.bodies.len() {
            let b = self.t.bodies[k].clone();
            let v = self.body_syms(k).1;
            let a = &mut self.t.arena;
            let cv = a.mul(b.damper, v);
            let av = a.func(Func::Abs, v);
            let vav = a.mul(v, av);
            let qv = a.mul(b.quad_damper, vav);
            let f = a.sub(b.force, cv);
            let f = a.sub(f, qv);
            let p = a.mul(v, f);
            total = a.add(total, p);
        }
        for c in self.t.couplings.clone() {
            let (va, vb) = (self.body_syms(c.a).1, self.body_syms(c.b).1);
            let a = &mut self.t.arena;
            let dv = a.sub(va, vb);
            let d2 = a.powi(dv, 2);
            let p = a.mul(c.damper, d2);
            total = a.sub(total, p);
        }
        total
    }
}
