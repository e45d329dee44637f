//! Checks of walls with a temperature state: the `wall` item, ports that name a wall, and
//! conduction links between walls or from a wall to a fixed temperature.

use stirling_dsl::expr::{At, Id, Sym};
use stirling_dsl::topology::{ConductionDecl, End, HeatEnd, Topology, Vessel, WallDecl};
use syn::spanned::Spanned;
use syn::{Expr, Ident};

use crate::ast::{EndAst, LinkAst, VesselAst};
use crate::check::Lower;

impl Lower {
    /// An array's length is the run-time section count `n`.
    pub(crate) fn check_array_length(&mut self, n: &Ident, what: &str) {
        if n != "n" {
            self.cx.error(n.span(), format!("{what}: an array's length is the run-time section count: write `[n]`, found `[{n}]`"));
        }
    }

    pub(crate) fn is_wall(&self, id: &Ident) -> bool {
        self.walls.contains_key(&id.to_string())
    }

    fn wall_block(&self, w: usize) -> u32 {
        Topology::wall_block(self.bodies_len(), self.cvs_len(), w)
    }

    /// Declare wall `v`: its name, its index, and (a single wall) its temperature as a name
    /// expressions may use.
    pub(crate) fn declare_wall(&mut self, v: &VesselAst) {
        if !self.declare(&v.name) {
            return;
        }
        let w = self.topo.walls.len();
        let name = v.name.to_string();
        self.walls.insert(name.clone(), (w, v.array.is_some()));
        if v.array.is_none() {
            let sym = Sym::State(self.wall_block(w), At::Scalar);
            self.states.insert(name.clone(), sym);
        }
        let zero = self.topo.arena.num(0.0);
        self.topo.walls.push(WallDecl {
            name,
            array: v.array.is_some(),
            capacity: zero,
            rest: zero,
            input: zero,
        });
    }

    /// The fields of wall `v`.
    pub(crate) fn wall(&mut self, v: &VesselAst) {
        let Some(&(w, array)) = self.walls.get(&v.name.to_string()) else {
            return;
        };
        let what = format!("wall `{}`", v.name);
        if let Some(n) = &v.array {
            self.check_array_length(n, &what);
        }
        if let Some(f) = v.faces.first() {
            self.cx.error(
                f.name.span(),
                format!("{what}: a wall has no faces (it does not move); give them to a CV"),
            );
        }
        if let Some(p) = v.ports.first() {
            self.cx.error(p.name.span(), format!("{what}: a wall has no ports; a CV's port names the wall (`wall: {}`), and a `link` conducts between walls or to a fixed temperature", v.name));
        }
        let index = array.then_some("j");
        let f = self.fields(&v.fields, &["capacity", "rest", "input"], &what);
        let span = v.name.span();
        let capacity = match f.get("capacity") {
            Some(c) => self.static_expr(&c.value, index, &format!("the capacity of `{}`", v.name)),
            None => {
                self.cx.error(span, format!("{what} has no capacity: expected `capacity: <expression>` (J/K; write `capacity: 1.0 / k` so that `k = 0` is the fixed wall exactly)"));
                self.topo.arena.num(1.0)
            }
        };
        let rest = match f.get("rest") {
            Some(r) => self.static_expr(
                &r.value,
                index,
                &format!("the rest temperature of `{}`", v.name),
            ),
            None => {
                self.cx.error(span, format!("{what} has no rest temperature: expected `rest: <expression>` (its temperature at rest, the equilibrium guess)"));
                self.topo.arena.num(1.0)
            }
        };
        let input = self.optional(&f, "input", index);
        let wall = &mut self.topo.walls[w];
        (wall.capacity, wall.rest) = (capacity, rest);
        if let Some(input) = input {
            wall.input = input;
        }
    }

    /// The `wall:` of a CV port: a declared wall (its temperature state and index) or a
    /// fixed temperature expression.
    pub(crate) fn port_wall(&mut self, e: &Expr, index: Option<&str>) -> (Id, Option<usize>) {
        let one = self.topo.arena.num(1.0);
        match e {
            Expr::Path(p) if p.path.get_ident().is_some_and(|i| self.is_wall(i)) => {
                let id = p.path.get_ident().expect("checked");
                let (w, array) = self.walls[&id.to_string()];
                if array {
                    self.cx.error(id.span(), format!("`{id}` is an array of walls: name the section, `{id}[j]`, from a port of an array of CVs"));
                } else {
                    // from an array of CVs: every section's port into the one wall `id`
                    let b = self.wall_block(w);
                    return (self.topo.arena.sym(Sym::State(b, At::Scalar)), Some(w));
                }
                (one, None)
            }
            Expr::Index(ix) => self.port_wall_section(ix, index).unwrap_or((one, None)),
            Expr::Path(p) if p.path.get_ident().is_some_and(|i| !self.known_name(i)) => {
                let id = p.path.get_ident().expect("checked");
                let msg = format!("unknown wall `{id}`: a port's `wall` is a declared wall ({}) or a temperature expression of parameters", self.wall_list());
                self.cx.error(id.span(), msg);
                (one, None)
            }
            _ => {
                let id = self.expr(e, index);
                if self.uses_wall(id) {
                    self.cx.error(e.span(), "a port's `wall` is either a declared wall's name or an expression without wall temperatures (the heat it exchanges would leave no trace in the wall's balance)");
                }
                (id, None)
            }
        }
    }

    /// `wall: matrix[j]` from a port of an array of CVs.
    fn port_wall_section(
        &mut self,
        ix: &syn::ExprIndex,
        index: Option<&str>,
    ) -> Option<(Id, Option<usize>)> {
        let base = match &*ix.expr {
            Expr::Path(p) => p.path.get_ident(),
            _ => None,
        };
        let Some(base) = base.filter(|b| self.is_wall(b)) else {
            let name = base.map_or_else(|| quote::quote!(#ix).to_string(), |b| b.to_string());
            let msg = format!("unknown wall `{name}`: a port's `wall` is a declared wall ({}) or a temperature expression of parameters", self.wall_list());
            self.cx.error(ix.expr.span(), msg);
            return None;
        };
        let (w, array) = self.walls[&base.to_string()];
        if !array {
            self.cx.error(
                ix.index.span(),
                format!("`{base}` is a single wall: remove the index"),
            );
            return None;
        }
        if index.is_none() {
            self.cx.error(ix.span(), format!("a single CV's port names a single wall; the sections of `{base}` belong to the sections of an array of CVs"));
            return None;
        }
        if self.index(&ix.index, index) != Some(At::Rel(0)) {
            self.cx.error(ix.index.span(), format!("section `j` of an array of CVs exchanges heat with section `j` of `{base}`: write `{base}[j]`"));
            return None;
        }
        let b = self.wall_block(w);
        Some((self.topo.arena.sym(Sym::State(b, At::Rel(0))), Some(w)))
    }

    fn known_name(&self, id: &Ident) -> bool {
        let s = id.to_string();
        self.is_param_or_let(&s)
            || self.states.contains_key(&s)
            || matches!(s.as_str(), "n" | "j" | "pi")
    }

    fn uses_wall(&self, id: Id) -> bool {
        let first = Topology::wall_block(self.bodies_len(), self.cvs_len(), 0);
        self.topo
            .arena
            .symbols(id)
            .iter()
            .any(|s| matches!(s, Sym::State(b, _) if *b >= first))
    }

    fn wall_list(&self) -> String {
        let mut names: Vec<&String> = self.walls.keys().collect();
        names.sort();
        match names.is_empty() {
            true => "none is declared".to_string(),
            false => format!(
                "one of {}",
                names
                    .iter()
                    .map(|s| s.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }
    }

    /// A `link` with a wall at one end at least: conduction `Q = G (T_from - T_to)`.
    pub(crate) fn conduction(&mut self, l: &LinkAst) {
        let var = l.range.as_ref().map(|r| r.var.to_string());
        let from = self.heat_end(&l.from, var.as_deref());
        let to = self.heat_end(&l.to, var.as_deref());
        let f = self.fields(
            &l.fields,
            &["conductance"],
            "a conduction `link` (between walls, or a wall and a fixed temperature)",
        );
        let conductance = self.required(
            &f,
            "conductance",
            l.span,
            "a conduction `link`",
            var.as_deref(),
        );
        let (Some(from), Some(to)) = (from, to) else {
            return;
        };
        if matches!((from, to), (HeatEnd::Fixed(_), HeatEnd::Fixed(_))) {
            self.cx
                .error(l.span, "a conduction link needs a wall at one end at least");
            return;
        }
        let key = |e: HeatEnd| match e {
            HeatEnd::Wall(end) => (end.vessel, end.at),
            HeatEnd::Fixed(_) => (Vessel::Space(usize::MAX), At::Scalar),
        };
        if self.link_shape_ok(l, key(from), key(to)) {
            self.topo.conductions.push(ConductionDecl {
                from,
                to,
                conductance,
            });
        }
    }

    /// A conduction end: a wall (with its section) or a parameter / `let` name.
    fn heat_end(&mut self, e: &EndAst, var: Option<&str>) -> Option<HeatEnd> {
        let name = e.name.to_string();
        let Some(&(w, array)) = self.walls.get(&name) else {
            if self.vessels.contains_key(&name) {
                self.cx.error(e.name.span(), format!("`{name}` is a gas vessel: a link joins gas vessels (mass flow) or walls (conduction), not a wall and a gas vessel"));
                return None;
            }
            if e.index.is_some() || !self.is_param_or_let(&name) {
                self.cx.error(e.name.span(), format!("unknown wall or temperature `{name}`: a conduction link joins walls ({}) or a wall and a fixed temperature (a parameter or `let` name)", self.wall_list()));
                return None;
            }
            let path = Expr::Path(syn::ExprPath {
                attrs: Vec::new(),
                qself: None,
                path: e.name.clone().into(),
            });
            return Some(HeatEnd::Fixed(self.static_expr(
                &path,
                None,
                "a fixed temperature",
            )));
        };
        let vessel = Vessel::Wall(w);
        match (&e.index, array) {
            (None, false) => Some(HeatEnd::Wall(End {
                vessel,
                at: At::Scalar,
            })),
            (Some(ix), false) => {
                self.cx.error(
                    ix.span(),
                    format!("`{name}` is a single wall: remove the index"),
                );
                None
            }
            (None, true) => {
                self.cx.error(e.name.span(), format!("`{name}` is an array of walls: name a section, e.g. `{name}[0]`, `{name}[n - 1]` or `{name}[j]`"));
                None
            }
            (Some(ix), true) => self
                .index(ix, var)
                .map(|at| HeatEnd::Wall(End { vessel, at })),
        }
    }
}
