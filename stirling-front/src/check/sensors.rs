//! `sensor name: STATE "unit";`: the observed state must be one the model declares (a body's
//! position or velocity, a CV's pressure or mass, a wall's temperature; an array's element
//! needs an index, a scalar's none). `sensor name: EXPR "unit";`: an expression of such
//! states and the parameters (a pressure difference, `P_cold - P_bounce`; an alternator's
//! voltage, `Kv * w`); every other name is refused, and the unit is required. Whether an index is below `n`, and whether a mass state
//! exists in the chosen closure, is known at run time only (`Model::sensor_state`).

use std::collections::HashMap;

use stirling_dsl::expr::Sym;
use stirling_dsl::topology::{SensorDecl, SensorExpr, Vessel};
use syn::Expr;

use super::Lower;
use crate::ast::SensorAst;
use crate::expr::{convert, Scope};

/// A plain state read: `NAME` or `NAME[k]` (an integer literal index).
fn state_read(e: &Expr) -> Option<(&syn::Ident, Option<&syn::LitInt>)> {
    match e {
        Expr::Path(p) => Some((p.path.get_ident()?, None)),
        Expr::Index(ix) => {
            let Expr::Path(p) = &*ix.expr else {
                return None;
            };
            let Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Int(k),
                ..
            }) = &*ix.index
            else {
                return None;
            };
            Some((p.path.get_ident()?, Some(k)))
        }
        _ => None,
    }
}

impl Lower {
    /// `free a, b;`: each a declared parameter, once.
    pub(super) fn free(&mut self, names: &[syn::Ident]) {
        for id in names {
            let name = id.to_string();
            if !self.is_param(&name) {
                self.cx.error(id.span(), format!("`free {name}`: no parameter `{name}`; `free` lists the parameters a fit frees by default"));
            } else if self.topo.free.contains(&name) {
                self.cx.error(id.span(), format!("`free`: `{name}` twice"));
            } else {
                self.topo.free.push(name);
            }
        }
    }

    pub(super) fn sensor(&mut self, s: &SensorAst) {
        let name = s.name.to_string();
        if name == "t" {
            self.cx.error(
                s.name.span(),
                "`t` is the time column; name the sensor otherwise",
            );
            return;
        }
        if self.topo.sensors.iter().any(|d| d.name == name) {
            self.cx
                .error(s.name.span(), format!("duplicate sensor `{name}`"));
            return;
        }
        let decl = match state_read(&s.expr) {
            Some((id, index)) if !self.is_param(&id.to_string()) => {
                self.state_sensor(&name, id, index, s.unit.as_ref())
            }
            _ => self.expr_sensor(&name, s),
        };
        if let Some(d) = decl {
            self.topo.sensors.push(d);
        }
    }

    /// `sensor name: STATE;` or `sensor name: STATE[k];`.
    fn state_sensor(
        &mut self,
        name: &str,
        id: &syn::Ident,
        index: Option<&syn::LitInt>,
        unit: Option<&syn::LitStr>,
    ) -> Option<SensorDecl> {
        let state = id.to_string();
        let Some((array, own)) = self.sensed_state(&state) else {
            self.cx.error(
                id.span(),
                format!("sensor `{name}`: no state `{state}`; a sensor observes a body's position or velocity (its declared name), `P_<cv>`, `m_<cv>` or `Tw_<wall>`, or an expression of those and parameters"),
            );
            return None;
        };
        let full = match self.element(name, &state, array, index, id.span()) {
            Ok(f) => f,
            Err(e) => {
                self.cx.errors.push(e);
                return None;
            }
        };
        Some(SensorDecl {
            name: name.to_string(),
            state: full,
            unit: unit.map_or(own.to_string(), |u| u.value()),
            expr: None,
        })
    }

    /// The state's full name (`P_regen[2]`): an array state needs an index, a scalar none.
    fn element(
        &self,
        name: &str,
        state: &str,
        array: bool,
        index: Option<&syn::LitInt>,
        span: proc_macro2::Span,
    ) -> syn::Result<String> {
        match (index, array) {
            (None, false) => Ok(state.to_string()),
            (Some(k), true) => Ok(format!("{state}[{}]", k.base10_parse::<usize>()?)),
            (None, true) => Err(syn::Error::new(
                span,
                format!("sensor `{name}`: `{state}` is an array state: write `{state}[k]`"),
            )),
            (Some(_), false) => Err(syn::Error::new(
                span,
                format!("sensor `{name}`: `{state}` is not an array state: drop the index"),
            )),
        }
    }

    /// `sensor name: EXPR "unit";`: the states it reads become the inputs of its output.
    fn expr_sensor(&mut self, name: &str, s: &SensorAst) -> Option<SensorDecl> {
        let Some(unit) = &s.unit else {
            self.cx.error(
                s.name.span(),
                format!("sensor `{name}`: an expression sensor needs its unit: `sensor {name}: <expression> \"Pa\";`"),
            );
            return None;
        };
        let mut reads = Vec::new();
        let mut e = s.expr.clone();
        if let Err(err) = self.reads(name, &mut e, &mut reads) {
            self.cx.errors.push(err);
            return None;
        }
        let inputs: HashMap<String, Sym> = (0..reads.len())
            .map(|i| (format!("__read{i}"), Sym::Input(i as u32)))
            .collect();
        let scope = Scope {
            params: &self.params,
            lets: &HashMap::new(),
            states: &inputs,
            index: None,
        };
        match convert(&mut self.topo.arena, &scope, &e) {
            Ok(value) => Some(SensorDecl {
                name: name.to_string(),
                state: String::new(),
                unit: unit.value(),
                expr: Some(SensorExpr { value, reads }),
            }),
            Err(err) => {
                self.cx.errors.push(err);
                None
            }
        }
    }

    /// Replace every state `e` reads by an input `__read<i>` (`reads[i]` its name), and
    /// refuse a name that is neither a state nor a parameter.
    fn reads(&self, name: &str, e: &mut Expr, reads: &mut Vec<String>) -> syn::Result<()> {
        let mut leaf = |state: String, span| {
            let i = reads.iter().position(|r| *r == state).unwrap_or_else(|| {
                reads.push(state);
                reads.len() - 1
            });
            let id = syn::Ident::new(&format!("__read{i}"), span);
            Expr::Path(syn::ExprPath {
                attrs: Vec::new(),
                qself: None,
                path: id.into(),
            })
        };
        if let Some((id, index)) = state_read(e) {
            let state = id.to_string();
            if self.is_param(&state) || (state == "pi" && index.is_none()) {
                return Ok(());
            }
            let Some((array, _)) = self.sensed_state(&state) else {
                return Err(syn::Error::new(
                    id.span(),
                    format!("sensor `{name}`: unknown name `{state}`: a sensor expression reads states (a body's position or velocity, `P_<cv>`, `m_<cv>`, `Tw_<wall>`, `P_<array>[k]`) and parameters"),
                ));
            };
            let full = self.element(name, &state, array, index, id.span())?;
            *e = leaf(full, id.span());
            return Ok(());
        }
        match e {
            Expr::Binary(b) => {
                self.reads(name, &mut b.left, reads)?;
                self.reads(name, &mut b.right, reads)
            }
            Expr::Unary(u) => self.reads(name, &mut u.expr, reads),
            Expr::Paren(p) => self.reads(name, &mut p.expr, reads),
            Expr::Group(g) => self.reads(name, &mut g.expr, reads),
            Expr::Call(c) => c
                .args
                .iter_mut()
                .try_for_each(|a| self.reads(name, a, reads)),
            Expr::MethodCall(m) => {
                self.reads(name, &mut m.receiver, reads)?;
                m.args
                    .iter_mut()
                    .try_for_each(|a| self.reads(name, a, reads))
            }
            // anything else is refused by the conversion with its own message
            _ => Ok(()),
        }
    }

    /// Whether `state` names a declared state: `(is an array, its unit)`.
    fn sensed_state(&self, state: &str) -> Option<(bool, &'static str)> {
        // a flywheel's angle and speed (docs/physics.md section 12) in rad and rad/s
        if let Some(b) = self.topo.bodies.iter().find(|b| b.pos == state) {
            return Some((false, if b.rotary { "rad" } else { "m" }));
        }
        if let Some(b) = self.topo.bodies.iter().find(|b| b.vel == state) {
            return Some((false, if b.rotary { "rad/s" } else { "m/s" }));
        }
        let cv = |name: &str| match self.vessels.get(name) {
            Some(Vessel::Cv(i)) => Some(self.topo.cvs[*i].array),
            _ => None,
        };
        if let Some(v) = state.strip_prefix("P_") {
            return cv(v).map(|a| (a, "Pa"));
        }
        if let Some(v) = state.strip_prefix("m_") {
            return cv(v).map(|a| (a, "kg"));
        }
        let w = state.strip_prefix("Tw_")?;
        self.walls.get(w).map(|&(_, a)| (a, "K"))
    }
}
