//! Kinematics (docs/physics.md section 12): flywheels, and the cranks and linkages that make a
//! position a function of a flywheel's angle.

use stirling_dsl::expr::{At, Func, Id, Sym};
use stirling_dsl::topology::{MechanismDecl, Topology};
use syn::spanned::Spanned;

use super::Lower;
use crate::ast::{BodyAst, MechanismAst};

impl Lower {
    /// A flywheel's fields: `J omega' = T_gas - c omega - Tc tanh(omega/omega_eps) - load + force`,
    /// lowered to a body whose mass is the inertia and whose force holds the friction and load.
    pub(super) fn flywheel(&mut self, b: &BodyAst, k: usize) {
        let what = format!("flywheel `{}`", b.name);
        let f = self.fields(
            &b.fields,
            &[
                "inertia",
                "damper",
                "friction",
                "omega_eps",
                "load",
                "force",
            ],
            &what,
        );
        let inertia = self.required(&f, "inertia", b.name.span(), &what, None);
        let zero = self.topo.arena.num(0.0);
        let damper = self.optional(&f, "damper", None).unwrap_or(zero);
        let load = self.optional(&f, "load", None).unwrap_or(zero);
        let extra = self.optional(&f, "force", None).unwrap_or(zero);
        let friction = match (f.get("friction"), f.get("omega_eps")) {
            (None, None) => zero,
            (Some(fc), None) => {
                self.cx.error(fc.name.span(), format!("{what}: a Coulomb `friction` needs `omega_eps`, the angular velocity (rad/s) over which `friction * tanh(omega / omega_eps)` changes sign"));
                zero
            }
            (None, Some(e)) => {
                self.cx.error(
                    e.name.span(),
                    format!("{what}: `omega_eps` without `friction`"),
                );
                zero
            }
            (Some(fc), Some(e)) => {
                let tc = self.static_expr(&fc.value, None, "a flywheel's Coulomb friction");
                let eps = self.static_expr(&e.value, None, "a flywheel's `omega_eps`");
                let omega = self
                    .topo
                    .arena
                    .sym(Sym::State(Topology::vel_block(k), At::Scalar));
                let a = &mut self.topo.arena;
                let r = a.div(omega, eps);
                let t = a.func(Func::Tanh, r);
                a.mul(tc, t)
            }
        };
        let a = &mut self.topo.arena;
        let force = a.sub(extra, load);
        let force = a.sub(force, friction);
        let body = &mut self.topo.bodies[k];
        (body.mass, body.damper, body.force) = (inertia, damper, force);
    }

    /// First pass: the mechanism's name and position are declared, its flywheel found.
    pub(super) fn declare_mechanism(&mut self, m: &MechanismAst) {
        let ok = self.declare(&m.name) & self.declare(&m.pos);
        let body = self.flywheel_ref(&m.on, &m.name);
        if body.is_none() {
            self.refused_mechanisms.insert(m.name.to_string());
        }
        if let (true, Some(body)) = (ok, body) {
            let zero = self.topo.arena.num(0.0);
            self.mechanisms
                .insert(m.name.to_string(), self.topo.mechanisms.len());
            self.topo.mechanisms.push(MechanismDecl {
                name: m.name.to_string(),
                pos: m.pos.to_string(),
                kind: m.kind.to_string(),
                body,
                position: zero,
                ratio: zero,
            });
        }
    }

    /// The flywheel a mechanism is `on`.
    fn flywheel_ref(&mut self, on: &syn::Ident, name: &syn::Ident) -> Option<usize> {
        let found = self.topo.bodies.iter().position(|b| *on == b.name);
        match found {
            Some(k) if self.topo.bodies[k].rotary => Some(k),
            Some(_) => {
                self.cx.error(on.span(), format!("`{name}` is driven by a flywheel's angle, but `{on}` is a body: declare `flywheel {on}(angle, speed) {{ inertia: .. }}`"));
                None
            }
            None => {
                let wheels: Vec<String> = self
                    .topo
                    .bodies
                    .iter()
                    .filter(|b| b.rotary)
                    .map(|b| format!("`{}`", b.name))
                    .collect();
                let list = if wheels.is_empty() {
                    "no flywheel is declared".to_string()
                } else {
                    format!("expected {}", wheels.join(", "))
                };
                self.cx
                    .error(on.span(), format!("unknown flywheel `{on}`: {list}"));
                None
            }
        }
    }

    /// Second pass: the position `s(theta)` and its derivative, and the position's name
    /// bound to `s(theta)` for every later expression.
    pub(super) fn mechanism(&mut self, m: &MechanismAst) {
        let Some(&i) = self.mechanisms.get(&m.name.to_string()) else {
            return;
        };
        let k = self.topo.mechanisms[i].body;
        let angle = Sym::State(Topology::pos_block(k), At::Scalar);
        let what = format!("{} `{}`", m.kind, m.name);
        let s = match m.kind.to_string().as_str() {
            "crank" => self.slider_crank(m, angle, &what),
            _ => self.linkage(m, angle, &what),
        };
        let ds = self.topo.arena.diff(s, angle);
        let a = &mut self.topo.arena;
        let s = a.named(&format!("s_{}", m.name), s);
        let ds = a.named(&format!("ds_{}", m.name), ds);
        let decl = &mut self.topo.mechanisms[i];
        (decl.position, decl.ratio) = (s, ds);
        self.lets.insert(m.pos.to_string(), s);
    }

    /// `s = r cos(theta + phi) + sqrt(L^2 - r^2 sin^2(theta + phi)) - L`: the pin's distance
    /// from the crank's centre less the rod, `+r` at the dead centre towards the cylinder
    /// (`r cos(theta + phi)` for `L -> inf`).
    fn slider_crank(&mut self, m: &MechanismAst, angle: Sym, what: &str) -> Id {
        let f = self.fields(&m.fields, &["radius", "rod", "phase"], what);
        let span = m.name.span();
        let r = self.required_static(&f, "radius", span, what);
        let rod = self.required_static(&f, "rod", span, what);
        let zero = self.topo.arena.num(0.0);
        let phase = match f.get("phase") {
            Some(p) => self.static_expr(&p.value, None, "a crank's phase"),
            None => zero,
        };
        let (rv, lv) = (self.at_defaults(r), self.at_defaults(rod));
        if !(rv > 0.0) {
            let at = f.get("radius").map_or(span, |x| x.value.span());
            self.cx.error(at, format!("{what}: the crank radius must be positive, got {rv} at the parameters' defaults"));
        } else if !(lv > rv) {
            let at = f.get("rod").map_or(span, |x| x.value.span());
            self.cx.error(at, format!("{what}: the connecting rod ({lv} at the parameters' defaults) must be longer than the crank radius ({rv}), or the crank locks"));
        }
        let a = &mut self.topo.arena;
        let th = a.sym(angle);
        let psi = a.add(th, phase);
        let c = a.func(Func::Cos, psi);
        let sn = a.func(Func::Sin, psi);
        let rc = a.mul(r, c);
        let rs = a.mul(r, sn);
        let rs2 = a.powi(rs, 2);
        let l2 = a.powi(rod, 2);
        let under = a.sub(l2, rs2);
        let root = a.func(Func::Sqrt, under);
        let s = a.add(rc, root);
        a.sub(s, rod)
    }

    /// `position: <expression of the angle and parameters>`.
    fn linkage(&mut self, m: &MechanismAst, angle: Sym, what: &str) -> Id {
        let f = self.fields(&m.fields, &["position"], what);
        let Some(field) = f.get("position") else {
            self.cx.error(
                m.name.span(),
                format!("{what} has no `position`: expected `position: <expression of the angle>`"),
            );
            return self.topo.arena.num(0.0);
        };
        let s = self.expr(&field.value, None);
        let other = self
            .topo
            .arena
            .symbols(s)
            .into_iter()
            .any(|x| matches!(x, Sym::State(..)) && x != angle);
        if other {
            let wheel =
                &self.topo.bodies[self.topo.mechanisms[self.mechanisms[&m.name.to_string()]].body];
            let msg = format!("{what}: the position must be an expression of the angle `{}` of `{}` and parameters only", wheel.pos, wheel.name);
            self.cx.error(field.value.span(), msg);
        }
        s
    }

    fn required_static(
        &mut self,
        f: &std::collections::HashMap<String, &crate::ast::Field>,
        key: &str,
        span: proc_macro2::Span,
        what: &str,
    ) -> Id {
        match f.get(key) {
            Some(field) => self.static_expr(&field.value, None, &format!("the `{key}` of {what}")),
            None => {
                self.cx.error(
                    span,
                    format!("{what} has no `{key}`: expected `{key}: <expression>`"),
                );
                self.topo.arena.num(1.0)
            }
        }
    }

    /// The value of a parameter expression at the parameters' defaults (NaN if it reads a state).
    fn at_defaults(&self, id: Id) -> f64 {
        let params: Vec<f64> = self.topo.params.iter().map(|p| p.default).collect();
        self.topo.arena.eval(id, &mut |s| match s {
            Sym::Param(k) => params.get(k as usize).copied().unwrap_or(f64::NAN),
            _ => f64::NAN,
        })
    }
}
