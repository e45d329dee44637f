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
        let mut constant = |e: &syn::Expr| match convert(&mut self.topo.arena, &scope, e) {
            Ok(id) => self.topo.arena.eval_const(id).unwrap_or(f64::NAN),
            Err(e) => {
                self.cx.errors.push(e);
                0.0
            }
        };
        let default = constant(&p.default);
        let bounds = p.bounds.as_ref().map(|r| {
            let lo = r.start.as_deref().map_or(f64::NAN, &mut constant);
            let hi = r.end.as_deref().map_or(f64::NAN, &mut constant);
            (lo, hi)
        });
        if let (Some((lo, hi)), Some(r)) = (bounds, &p.bounds) {
            let name = &p.name;
            let span = syn::spanned::Spanned::span(r);
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                self.cx.error(span, format!("`{name}`: the bounds must be finite numbers, the lower below the upper (`in lo..hi`), got {lo}..{hi}"));
            } else if !(lo..=hi).contains(&default) {
                self.cx.error(
                    span,
                    format!("`{name}`: its default {default} is outside its bounds {lo}..{hi}"),
                );
            }
        }
        let name = p.name.to_string();
        self.params
            .insert(name.clone(), self.topo.params.len() as u32);
        self.topo.params.push(ParamDecl {
            name,
            default,
            unit: p.unit.clone(),
            doc: p.doc.clone(),
            bounds,
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
            rotary: b.rotary,
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
