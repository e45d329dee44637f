//! The gas and the mechanics: `gas`, bodies, couplings, faces.

use proc_macro2::Span;
use stirling_dsl::topology::{CouplingDecl, FaceDecl, GasDecl};
use syn::Ident;

use super::Lower;
use crate::ast::{BodyAst, Field};

impl Lower {
    pub(super) fn gas(&mut self, span: Span, fields: &[Field]) {
        let f = self.fields(fields, &["R", "gamma", "charge", "mdot_eps"], "`gas`");
        let r = self.required(&f, "R", span, "`gas`", None);
        let gamma = self.required(&f, "gamma", span, "`gas`", None);
        let charge = self.required(&f, "charge", span, "`gas`", None);
        let mdot_eps = self.required(&f, "mdot_eps", span, "`gas`", None);
        self.topo.gas = Some(GasDecl {
            r,
            gamma,
            charge,
            mdot_eps,
        });
    }

    pub(super) fn body(&mut self, b: &BodyAst) {
        let Some(&k) = self.bodies.get(&b.name.to_string()) else {
            return;
        };
        if b.rotary {
            return self.flywheel(b, k);
        }
        let what = format!("body `{}`", b.name);
        let f = self.fields(
            &b.fields,
            &["mass", "spring", "damper", "quad_damper", "force"],
            &what,
        );
        let mass = self.required(&f, "mass", b.name.span(), &what, None);
        let zero = self.topo.arena.num(0.0);
        let spring = self.optional(&f, "spring", None).unwrap_or(zero);
        let damper = self.optional(&f, "damper", None).unwrap_or(zero);
        let quad_damper = self.optional(&f, "quad_damper", None).unwrap_or(zero);
        let force = self.optional(&f, "force", None).unwrap_or(zero);
        let body = &mut self.topo.bodies[k];
        (
            body.mass,
            body.spring,
            body.damper,
            body.quad_damper,
            body.force,
        ) = (mass, spring, damper, quad_damper, force);
    }

    pub(super) fn body_ref(&mut self, id: &Ident) -> Option<usize> {
        let found = self.bodies.get(&id.to_string()).copied();
        if found.is_none() {
            let mut names: Vec<&String> =
                self.bodies.keys().chain(self.mechanisms.keys()).collect();
            names.sort();
            let list = names
                .iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join(", ");
            self.cx.error(
                id.span(),
                format!("unknown body `{id}`: expected one of {list}"),
            );
        }
        found
    }

    pub(super) fn coupling(&mut self, c: &crate::ast::CouplingAst) {
        let (a, b) = (self.body_ref(&c.a), self.body_ref(&c.b));
        for (id, k) in [(&c.a, a), (&c.b, b)] {
            if k.is_some_and(|k| self.topo.bodies[k].rotary) {
                self.cx.error(id.span(), format!("`{id}` is a flywheel: a coupling damper joins two bodies on one axis (a flywheel's friction is its `damper` and `friction`)"));
            }
        }
        let f = self.fields(&c.fields, &["damper"], "`coupling`");
        let damper = self.required(&f, "damper", c.a.span(), "`coupling`", None);
        if let (Some(a), Some(b)) = (a, b) {
            self.topo.couplings.push(CouplingDecl { a, b, damper });
        }
    }

    pub(super) fn faces(&mut self, faces: &[Field], owner: &str) -> Vec<FaceDecl> {
        let mut out = Vec::new();
        for f in faces {
            if self.refused_mechanisms.contains(&f.name.to_string()) {
                continue;
            }
            let mechanism = self.mechanisms.get(&f.name.to_string()).copied();
            let body = match mechanism {
                Some(m) => Some(self.topo.mechanisms[m].body),
                None => self.body_ref(&f.name),
            };
            let coeff = self.static_expr(
                &f.value,
                None,
                &format!("the face coefficient of `{owner}` on `{}`", f.name),
            );
            let Some(body) = body else { continue };
            if mechanism.is_none() && self.topo.bodies[body].rotary {
                self.cx.error(f.name.span(), format!("`{}` is a flywheel: a face acts on a body or on a crank or linkage driven by it (`crank piston(y) on {} {{ .. }}`)", f.name, f.name));
                continue;
            }
            out.push(FaceDecl {
                body,
                coeff,
                mechanism,
            });
        }
        out
    }
}
