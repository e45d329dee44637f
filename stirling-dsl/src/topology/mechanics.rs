//! The bodies (docs/physics.md section 1): states, face sums, pressure forces, accelerations
//! and coupling forces.

use super::assemble::Assembler;
use super::decl::Topology;
use crate::expr::{At, Func, Id, Sym};

impl Assembler<'_> {
    /// Position and velocity symbols of body `k`.
    pub(super) fn body_syms(&mut self, k: usize) -> (Id, Id) {
        let a = &mut self.t.arena;
        (
            a.sym(Sym::State(Topology::pos_block(k), At::Scalar)),
            a.sym(Sym::State(Topology::vel_block(k), At::Scalar)),
        )
    }

    /// The displacement and velocity a face moves with: the body's `(q, v)`, or a
    /// mechanism's `(s(theta), ds/dtheta omega)` (docs/physics.md section 12).
    fn face_motion(&mut self, f: &super::decl::FaceDecl) -> (Id, Id) {
        let (q, v) = self.body_syms(f.body);
        match f.mechanism {
            None => (q, v),
            Some(m) => {
                let m = &self.t.mechanisms[m];
                let (s, ratio) = (m.position, m.ratio);
                (s, self.t.arena.mul(ratio, v))
            }
        }
    }

    /// The transformer modulus of a face: 1, or a mechanism's `ds/dtheta`.
    fn face_ratio(&mut self, f: &super::decl::FaceDecl) -> Id {
        match f.mechanism {
            None => f.coeff,
            Some(m) => {
                let ratio = self.t.mechanisms[m].ratio;
                self.t.arena.mul(f.coeff, ratio)
            }
        }
    }

    /// `sum coeff * q` and `sum coeff * v` over faces (a mechanism's face: `coeff * s(theta)`
    /// and `coeff * ds/dtheta * omega`).
    pub(super) fn face_sums(&mut self, faces: &[super::decl::FaceDecl]) -> (Id, Id) {
        let (mut dv, mut vdot) = (self.t.arena.num(0.0), self.t.arena.num(0.0));
        for f in faces.iter().cloned() {
            let (q, v) = self.face_motion(&f);
            let a = &mut self.t.arena;
            let (cq, cv) = (a.mul(f.coeff, q), a.mul(f.coeff, v));
            dv = a.add(dv, cq);
            vdot = a.add(vdot, cv);
        }
        (dv, vdot)
    }

    /// Pressure force on body `k`: `sum_i a_ik P_i` over CV and space faces (on a flywheel
    /// the torque `sum_i a_ik ds_m/dtheta P_i` of the faces on its mechanisms).
    pub(super) fn force(&mut self, k: usize) -> Id {
        let mut faces = Vec::new();
        for (i, c) in self.t.cvs.iter().enumerate() {
            for f in c.faces.iter().filter(|f| f.body == k) {
                faces.push((f.clone(), self.cv[i].p));
            }
        }
        for s in &self.t.spaces {
            for f in s.faces.iter().filter(|f| f.body == k) {
                faces.push((f.clone(), s.pressure));
            }
        }
        let terms: Vec<(Id, Id)> = faces
            .into_iter()
            .map(|(f, p)| (self.face_ratio(&f), p))
            .collect();
        let name = format!("F_{}", self.t.bodies[k].name);
        let a = &mut self.t.arena;
        let products: Vec<Id> = terms.into_iter().map(|(c, p)| a.mul(c, p)).collect();
        let sum = a.sum(products);
        a.named(&name, sum)
    }

    /// `(F_pressure + F - k q - c v - cq v|v| - couplings) / m`.
    pub(super) fn acceleration(&mut self, k: usize) -> Id {
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
    pub(super) fn coupling_force(&mut self, k: usize) -> Id {
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
}
