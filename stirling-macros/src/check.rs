//! Checking and lowering: names resolved, rules enforced, errors collected with
//! the user's spans, and the [`Topology`] built.

use std::collections::HashMap;

use proc_macro2::Span;
use stirling_dsl::expr::{At, Id, Sym};
use stirling_dsl::topology::{
    BodyDecl, CouplingDecl, CvDecl, End, FaceDecl, GasDecl, LinkDecl, ParamDecl, PortDecl,
    SpaceDecl, Topology, Vessel,
};
use syn::spanned::Spanned;
use syn::Ident;

use crate::ast::{BodyAst, EndAst, Field, Item, LinkAst, ModelAst, VesselAst};
use crate::expr::{convert, Scope};

/// Collects errors so that all are reported at once.
#[derive(Default)]
pub(crate) struct Ctxt {
    errors: Vec<syn::Error>,
}

impl Ctxt {
    pub(crate) fn error(&mut self, span: Span, msg: impl std::fmt::Display) {
        self.errors.push(syn::Error::new(span, msg));
    }

    fn finish(self) -> syn::Result<()> {
        let mut it = self.errors.into_iter();
        match it.next() {
            None => Ok(()),
            Some(mut first) => {
                it.for_each(|e| first.combine(e));
                Err(first)
            }
        }
    }
}

/// Check `ast` and build its topology.
pub fn lower(ast: &ModelAst) -> syn::Result<Topology> {
    let mut l = Lower::default();
    l.topo.name = model_name(ast);
    l.topo.doc = ast.doc.clone();
    l.run(ast);
    l.cx.finish()?;
    Ok(l.topo)
}

/// Names the generated functions use for their own locals: a declared name equal to one
/// would shadow it (or be shadowed) in the emitted code.
fn generated_local(name: &str) -> bool {
    let temp = name
        .strip_prefix('t')
        .is_some_and(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()));
    matches!(
        name,
        "p" | "x" | "t" | "u" | "out" | "sink" | "f" | "nf" | "jf"
    ) || temp
        || name.starts_with("o_")
        || name.starts_with("__")
}

fn model_name(ast: &ModelAst) -> String {
    for it in &ast.items {
        if let Item::Name(s) = it {
            return s.value();
        }
    }
    ast.ident.to_string().to_lowercase()
}

#[derive(Default)]
pub(crate) struct Lower {
    pub(crate) cx: Ctxt,
    pub(crate) topo: Topology,
    declared: HashMap<String, Span>,
    params: HashMap<String, u32>,
    lets: HashMap<String, Id>,
    pub(crate) states: HashMap<String, Sym>,
    bodies: HashMap<String, usize>,
    pub(crate) vessels: HashMap<String, Vessel>,
    cv_arrays: Vec<bool>,
    /// Declared walls: index and whether an array.
    pub(crate) walls: HashMap<String, (usize, bool)>,
}

impl Lower {
    pub(crate) fn declare(&mut self, id: &Ident) -> bool {
        let name = id.to_string();
        if self.declared.contains_key(&name) {
            self.cx.error(id.span(), format!("duplicate name `{name}`: every parameter, let, state, body, space and CV needs its own name"));
            return false;
        }
        if matches!(name.as_str(), "n" | "pi" | "j") {
            self.cx.error(
                id.span(),
                format!("`{name}` is reserved (`n` sections, `j` section index, `pi`)"),
            );
            return false;
        }
        self.declared.insert(name, id.span());
        true
    }

    /// As [`Lower::declare`], for a name that becomes a local of the generated code
    /// (parameters, lets).
    fn declare_local(&mut self, id: &Ident) -> bool {
        let name = id.to_string();
        if generated_local(&name) {
            self.cx.error(
                id.span(),
                format!("`{name}` is reserved for the generated code (`p`, `x`, `t`, `u`, `out`, `sink`, `f`, `nf`, `jf`, `t0`, `t1`, .., `o_*`, `__*`): choose another name for this parameter or `let`"),
            );
            return false;
        }
        self.declare(id)
    }

    fn run(&mut self, ast: &ModelAst) {
        for it in &ast.items {
            if let Item::Params(ps) = it {
                ps.iter().for_each(|p| self.param(p));
            }
        }
        for it in &ast.items {
            if let Item::Body(b) = it {
                self.declare_body(b);
            }
        }
        for it in &ast.items {
            if let Item::Space(v) | Item::Cv(v) = it {
                self.declare_vessel(v, matches!(it, Item::Cv(_)));
            }
        }
        for it in &ast.items {
            if let Item::Wall(v) = it {
                self.declare_wall(v);
            }
        }
        for it in &ast.items {
            match it {
                Item::Let(name, e) => self.let_(name, e),
                Item::Gas(span, f) => self.gas(*span, f),
                Item::Body(b) => self.body(b),
                Item::Coupling(c) => self.coupling(c),
                Item::Space(v) => self.space(v),
                Item::Cv(v) => self.cv(v),
                Item::Wall(v) => self.wall(v),
                Item::Link(l) => self.link(l),
                Item::Name(_) | Item::Params(_) => {}
            }
        }
        self.check_space_links(ast);
        if !self.topo.cvs.is_empty() && self.topo.gas.is_none() {
            self.cx.error(ast.ident.span(), "a model with control volumes needs a `gas { R: .., gamma: .., charge: .., mdot_eps: .. }` item");
        }
    }

    /// A link into a space carries its enthalpy, so the space needs a temperature.
    fn check_space_links(&mut self, ast: &ModelAst) {
        let mut bad = Vec::new();
        for l in &self.topo.links {
            for v in [l.from.vessel, l.to.vessel] {
                if let Vessel::Space(s) = v {
                    if self.topo.spaces[s].temperature.is_none() {
                        bad.push(self.topo.spaces[s].name.clone());
                    }
                }
            }
        }
        for name in bad {
            self.cx.error(ast.ident.span(), format!("space `{name}` takes part in a mass-flow link, so it needs `temperature: <expression>`"));
        }
    }

    /// Convert an expression, recording an error (and returning 0) on failure.
    pub(crate) fn expr(&mut self, e: &syn::Expr, index: Option<&str>) -> Id {
        let scope = Scope {
            params: &self.params,
            lets: &self.lets,
            states: &self.states,
            index: index.map(str::to_string),
        };
        match convert(&mut self.topo.arena, &scope, e) {
            Ok(id) => id,
            Err(err) => {
                self.cx.errors.push(err);
                self.topo.arena.num(0.0)
            }
        }
    }

    /// As [`Lower::expr`], and the value must not depend on the motion.
    pub(crate) fn static_expr(&mut self, e: &syn::Expr, index: Option<&str>, what: &str) -> Id {
        let id = self.expr(e, index);
        if self
            .topo
            .arena
            .symbols(id)
            .iter()
            .any(|s| matches!(s, Sym::State(..)))
        {
            self.cx.error(
                e.span(),
                format!("{what} must not depend on the states (positions, velocities)"),
            );
        }
        id
    }

    fn param(&mut self, p: &crate::ast::ParamAst) {
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

    fn declare_body(&mut self, b: &BodyAst) {
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

    fn declare_vessel(&mut self, v: &VesselAst, cv: bool) {
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

    fn let_(&mut self, name: &Ident, e: &syn::Expr) {
        let id = self.expr(e, None);
        if self.declare_local(name) {
            let named = self.topo.arena.named(&name.to_string(), id);
            self.lets.insert(name.to_string(), named);
        }
    }

    /// Split fields into the known ones; unknown or repeated fields are errors.
    pub(crate) fn fields<'f>(
        &mut self,
        fields: &'f [Field],
        known: &[&str],
        what: &str,
    ) -> HashMap<String, &'f Field> {
        let mut out = HashMap::new();
        for f in fields {
            let key = f.name.to_string();
            if !known.contains(&key.as_str()) {
                self.cx.error(
                    f.name.span(),
                    format!(
                        "unknown field `{key}` in {what}: expected one of {}",
                        known.join(", ")
                    ),
                );
            } else if out.insert(key.clone(), f).is_some() {
                self.cx.error(
                    f.name.span(),
                    format!("field `{key}` given twice in {what}"),
                );
            }
        }
        out
    }

    pub(crate) fn required(
        &mut self,
        f: &HashMap<String, &Field>,
        key: &str,
        span: Span,
        what: &str,
        index: Option<&str>,
    ) -> Id {
        match f.get(key) {
            Some(field) => self.expr(&field.value, index),
            None => {
                self.cx.error(
                    span,
                    format!("{what} has no `{key}`: expected `{key}: <expression>`"),
                );
                self.topo.arena.num(1.0)
            }
        }
    }

    pub(crate) fn optional(
        &mut self,
        f: &HashMap<String, &Field>,
        key: &str,
        index: Option<&str>,
    ) -> Option<Id> {
        f.get(key).map(|field| self.expr(&field.value, index))
    }

    fn gas(&mut self, span: Span, fields: &[Field]) {
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

    fn body(&mut self, b: &BodyAst) {
        let Some(&k) = self.bodies.get(&b.name.to_string()) else {
            return;
        };
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

    fn body_ref(&mut self, id: &Ident) -> Option<usize> {
        let found = self.bodies.get(&id.to_string()).copied();
        if found.is_none() {
            let mut names: Vec<&String> = self.bodies.keys().collect();
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

    fn coupling(&mut self, c: &crate::ast::CouplingAst) {
        let (a, b) = (self.body_ref(&c.a), self.body_ref(&c.b));
        let f = self.fields(&c.fields, &["damper"], "`coupling`");
        let damper = self.required(&f, "damper", c.a.span(), "`coupling`", None);
        if let (Some(a), Some(b)) = (a, b) {
            self.topo.couplings.push(CouplingDecl { a, b, damper });
        }
    }

    fn faces(&mut self, faces: &[Field], owner: &str) -> Vec<FaceDecl> {
        let mut out = Vec::new();
        for f in faces {
            let body = self.body_ref(&f.name);
            let coeff = self.static_expr(
                &f.value,
                None,
                &format!("the face coefficient of `{owner}` on `{}`", f.name),
            );
            if let Some(body) = body {
                out.push(FaceDecl { body, coeff });
            }
        }
        out
    }

    fn space(&mut self, v: &VesselAst) {
        let what = format!("space `{}`", v.name);
        if let Some(n) = &v.array {
            self.cx.error(
                n.span(),
                format!("{what}: a given-pressure space cannot be an array"),
            );
        }
        if !v.ports.is_empty() {
            self.cx.error(
                v.ports[0].name.span(),
                format!("{what}: a given-pressure space has no heat ports (make it a `cv`)"),
            );
        }
        let f = self.fields(&v.fields, &["pressure", "volume", "temperature"], &what);
        let pressure = self.required(&f, "pressure", v.name.span(), &what, None);
        let volume = self
            .optional(&f, "volume", None)
            .unwrap_or_else(|| self.topo.arena.num(0.0));
        let temperature = self.optional(&f, "temperature", None);
        let faces = self.faces(&v.faces, &v.name.to_string());
        self.topo.spaces.push(SpaceDecl {
            name: v.name.to_string(),
            pressure,
            volume,
            temperature,
            faces,
        });
    }

    fn cv(&mut self, v: &VesselAst) {
        let what = format!("control volume `{}`", v.name);
        let index = v.array.as_ref().map(|_| "j");
        if let Some(n) = &v.array {
            self.check_array_length(n, &what);
            if let Some(f) = v.faces.first() {
                self.cx.error(f.name.span(), format!("{what}: faces on an array of CVs are not supported; give the faces to a single CV"));
            }
        }
        let f = self.fields(&v.fields, &["volume"], &what);
        let volume = match f.get("volume") {
            Some(field) => {
                self.static_expr(&field.value, index, &format!("the volume of `{}`", v.name))
            }
            None => {
                self.cx.error(v.name.span(), format!("{what} has no volume: expected `volume: <expression>` (its volume at rest)"));
                self.topo.arena.num(1.0)
            }
        };
        if v.ports.is_empty() {
            self.cx.error(v.name.span(), format!("{what} has no heat port: expected `port name {{ h: .., area: .., wall: .. }}` (its rest temperature is the ports' mean wall temperature)"));
        }
        let ports = v.ports.iter().map(|p| self.port(p, index)).collect();
        let faces = if v.array.is_some() {
            Vec::new()
        } else {
            self.faces(&v.faces, &v.name.to_string())
        };
        self.topo.cvs.push(CvDecl {
            name: v.name.to_string(),
            array: v.array.is_some(),
            volume,
            faces,
            ports,
        });
    }

    fn port(&mut self, p: &crate::ast::PortAst, index: Option<&str>) -> PortDecl {
        let what = format!("heat port `{}`", p.name);
        let f = self.fields(&p.fields, &["h", "area", "wall"], &what);
        let h = self.required(&f, "h", p.name.span(), &what, index);
        let area = self.required(&f, "area", p.name.span(), &what, index);
        let (wall, wall_ref) = match f.get("wall") {
            Some(field) => self.port_wall(&field.value, index),
            None => {
                self.cx.error(
                    p.name.span(),
                    format!("{what} has no wall temperature: expected `wall: <expression>` or `wall: <declared wall>`"),
                );
                (self.topo.arena.num(1.0), None)
            }
        };
        PortDecl {
            name: p.name.to_string(),
            h,
            area,
            wall,
            wall_ref,
        }
    }

    fn link(&mut self, l: &LinkAst) {
        if self.is_wall(&l.from.name) || self.is_wall(&l.to.name) {
            return self.conduction(l);
        }
        let var = l.range.as_ref().map(|r| r.var.to_string());
        let from = self.end(&l.from, var.as_deref());
        let to = self.end(&l.to, var.as_deref());
        let f = self.fields(
            &l.fields,
            &["resistance", "conductance", "quadratic", "orifice", "dp0"],
            "`link`",
        );
        let orifice = self.orifice(l, &f, var.as_deref());
        let conductance = self.optional(&f, "conductance", var.as_deref());
        let resistance = match (orifice, conductance) {
            (Some((_, _, r)), _) => r,
            (None, conductance) => match conductance {
                Some(g) => {
                    if f.contains_key("resistance") || f.contains_key("quadratic") {
                        self.cx.error(l.span, "a `link` takes either `conductance: G` (mdot = G dP) or `resistance: R` with optional `quadratic: Rq`, not both");
                    }
                    let one = self.topo.arena.num(1.0);
                    self.topo.arena.div(one, g)
                }
                None => self.required(
                    &f,
                    "resistance",
                    l.span,
                    "`link` (or `conductance: G`, or `orifice: C` with `dp0: dP0`)",
                    var.as_deref(),
                ),
            },
        };
        let quadratic = if conductance.is_some() || orifice.is_some() {
            None
        } else {
            self.optional(&f, "quadratic", var.as_deref())
        };
        let (Some(from), Some(to)) = (from, to) else {
            return;
        };
        let link = LinkDecl {
            from,
            to,
            resistance,
            quadratic,
            conductance,
            orifice: orifice.map(|(c, dp0, _)| (c, dp0)),
        };
        if self.link_shape_ok(
            l,
            (link.from.vessel, link.from.at),
            (link.to.vessel, link.to.at),
        ) {
            self.topo.links.push(link);
        }
    }

    /// `orifice: C, dp0: dP0`: `(C, dP0, sqrt(dP0)/C)`, the last the small-`dP` resistance
    /// shown for the link; `None` without `orifice`.
    fn orifice(
        &mut self,
        l: &LinkAst,
        f: &HashMap<String, &Field>,
        var: Option<&str>,
    ) -> Option<(Id, Id, Id)> {
        let Some(c) = self.optional(f, "orifice", var) else {
            if let Some(field) = f.get("dp0") {
                self.cx.error(
                    field.name.span(),
                    "`dp0` is the regularization width of an orifice: it goes with `orifice: C`",
                );
            }
            return None;
        };
        for other in ["resistance", "conductance", "quadratic"] {
            if let Some(field) = f.get(other) {
                self.cx.error(field.name.span(), format!("an orifice link (`orifice: C, dp0: dP0`, mdot = C dP / (dP^2 + dP0^2)^(1/4)) takes no `{other}`"));
            }
        }
        let at = f.get("orifice").map_or(l.span, |field| field.name.span());
        let dp0 = self.required(
            f,
            "dp0",
            at,
            "an orifice `link` (`orifice: C, dp0: dP0`: the pressure difference below which the flow is linear)",
            var,
        );
        let a = &mut self.topo.arena;
        let root = a.func(stirling_dsl::expr::Func::Sqrt, dp0);
        let r = a.div(root, c);
        Some((c, dp0, r))
    }

    fn end(&mut self, e: &EndAst, var: Option<&str>) -> Option<End> {
        let Some(&vessel) = self.vessels.get(&e.name.to_string()) else {
            let mut names: Vec<&String> = self.vessels.keys().collect();
            names.sort();
            let list = names
                .iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join(", ");
            self.cx.error(
                e.name.span(),
                format!(
                    "unknown control volume or space `{}`: expected one of {list}",
                    e.name
                ),
            );
            return None;
        };
        let array = matches!(vessel, Vessel::Cv(i) if self.is_array_cv(i));
        match (&e.index, array) {
            (None, false) => Some(End {
                vessel,
                at: At::Scalar,
            }),
            (Some(ix), false) => {
                self.cx.error(
                    ix.span(),
                    format!("`{}` is not an array: remove the index", e.name),
                );
                None
            }
            (None, true) => {
                self.cx.error(
                    e.name.span(),
                    format!(
                        "`{}` is an array: name a section, e.g. `{0}[0]`, `{0}[n - 1]` or `{0}[j]`",
                        e.name
                    ),
                );
                None
            }
            (Some(ix), true) => self.index(ix, var).map(|at| End { vessel, at }),
        }
    }

    pub(crate) fn bodies_len(&self) -> usize {
        self.bodies.len()
    }

    pub(crate) fn cvs_len(&self) -> usize {
        self.cv_arrays.len()
    }

    pub(crate) fn is_param_or_let(&self, name: &str) -> bool {
        self.params.contains_key(name) || self.lets.contains_key(name)
    }

    /// Whether CV number `i` (declaration order) is an array.
    fn is_array_cv(&self, i: usize) -> bool {
        self.cv_arrays.get(i).copied().unwrap_or(false)
    }
}
