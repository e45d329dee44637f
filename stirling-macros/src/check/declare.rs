//! Declarations, first pass: parameters, bodies, spaces and CVs, `let`s get their names
//! and indices before any expression uses them.

use std::collections::HashMap;

use stirling_dsl::expr::{At, Sym};
use stirling_dsl::topology::{BodyDecl, ParamDecl, Topology, Vessel};
use syn::Ident;

use super::Lower;
use crate::ast::{BodyAst, VesselAst};
use crate::expr::{convert, Scope};

impl Lower {
    pub(super) fn param(&mut self, p: &crate::ast::ParamAst) {
        if !self.declare_local(&p.name) {
            return;
        }
        let empty = HashMap::new();
        let (no_lets, no_states) = (HashMap::new(), HashMap::new());
        let scope = Scope {
            params: &empty,
            lets: &no_lets,
            states: &no_states,
            index: None,
        };
        let default = match convert(&mut self.topo.arena, &scope, &p.default) {
            Ok(id) => self.topo.arena.eval_const(id).unwrap_or(f64::NAN),
            Err(e) => {
                self.cx.errors.push(e);
                0.0
            }
        };
        let name = p.name.to_string();
        self.params
            .insert(name.clone(), self.topo.params.len() as u32);
        self.topo.params.push(ParamDecl {
            name,
            default,
            unit: p.unit.clone(),
            doc: p.doc.clone(),
        });
    }

    pub(super) fn declare_body(&mut self, b: &BodyAst) {
        let k = self.topo.bodies.len();
        self.declare(&b.name);
        for (id, blk) in [
            (&b.pos, Topology::pos_block(k)),
            (&b.vel, Topology::vel_block(k)),
        ] {
            if self.declare(id) {
                self.states
                    .insert(id.to_string(), Sym::State(blk, At::Scalar));
            }
        }
        self.bodies.insert(b.name.to_string(), k);
        let zero = self.topo.arena.num(0.0);
        self.topo.bodies.push(BodyDecl {
            name: b.name.to_string(),
            pos: b.pos.to_string(),
            vel: b.vel.to_string(),
            mass: zero,
            spring: zero,
            damper: zero,
            quad_damper: zero,
            force: zero,
        });
    }

    pub(super) fn declare_vessel(&mut self, v: &VesselAst, cv: bool) {
        if !self.declare(&v.name) {
            return;
        }
        if cv {
            self.cv_arrays.push(v.array.is_some());
        }
        let vessel = if cv {
            Vessel::Cv(
                self.vessels
                    .values()
                    .filter(|x| matches!(x, Vessel::Cv(_)))
                    .count(),
            )
        } else {
            Vessel::Space(
                self.vessels
                    .values()
                    .filter(|x| matches!(x, Vessel::Space(_)))
                    .count(),
            )
        };
        self.vessels.insert(v.name.to_string(), vessel);
    }

    pub(super) fn let_(&mut self, name: &Ident, e: &syn::Expr) {
        let id = self.expr(e, None);
        if self.declare_local(name) {
            let named = self.topo.arena.named(&name.to_string(), id);
            self.lets.insert(name.to_string(), named);
        }
    }
}
