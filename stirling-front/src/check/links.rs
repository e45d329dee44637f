//! Checks of link ends and chain links: which section an index names, and that a
//! chain link stays inside its array.

use stirling_dsl::expr::{At, Sym};
use stirling_dsl::topology::Vessel;
use syn::spanned::Spanned;

use crate::ast::{LinkAst, RangeAst};
use crate::check::Lower;

/// `index(j, n)` evaluated at a sample point.
fn sample(l: &Lower, id: stirling_dsl::Id, j: f64, n: f64) -> f64 {
    l.topo.arena.eval(id, &mut |s| match s {
        Sym::Index => j,
        Sym::Count => n,
        _ => f64::NAN,
    })
}

impl Lower {
    /// Classify a section index: `0`, `n - 1`, or `j + k` with the link's range variable.
    pub(crate) fn index(&mut self, ix: &syn::Expr, var: Option<&str>) -> Option<At> {
        let id = self.expr(ix, var);
        let syms = self.topo.arena.symbols(id);
        if syms.iter().any(|s| !matches!(s, Sym::Index | Sym::Count)) {
            self.cx.error(
                ix.span(),
                "a section index may use only `n`, the range variable and integers",
            );
            return None;
        }
        let (f00, f10, f01) = (
            sample(self, id, 0.0, 10.0),
            sample(self, id, 1.0, 10.0),
            sample(self, id, 0.0, 11.0),
        );
        let (dj, dn) = (f10 - f00, f01 - f00);
        let at = match (dj, dn) {
            (0.0, 0.0) if f00 == 0.0 => Some(At::First),
            (0.0, 1.0) if f00 == 9.0 => Some(At::Last),
            (1.0, 0.0) if f00.fract() == 0.0 => Some(At::Rel(f00 as i32)),
            _ => None,
        };
        if at.is_none() {
            self.cx.error(ix.span(), "unsupported section index: expected `0`, `n - 1`, or `j + k` with the link's range variable `j`");
        }
        at
    }

    /// A chain link (`a[j] -> a[j + 1] for j in 0..n - 1`) must stay inside its array;
    /// a link without `for` must name fixed sections.
    pub(crate) fn link_shape_ok(
        &mut self,
        l: &LinkAst,
        from: (Vessel, At),
        to: (Vessel, At),
    ) -> bool {
        let rel = |at: At| if let At::Rel(r) = at { Some(r) } else { None };
        let (rf, rt) = (rel(from.1), rel(to.1));
        let Some(range) = &l.range else {
            if rf.is_some() || rt.is_some() {
                self.cx.error(
                    l.span,
                    "a link with a section variable needs a range: `for j in 0..n - 1`",
                );
                return false;
            }
            return true;
        };
        if let (Some(0), None) | (None, Some(0)) = (rf, rt) {
            let scalar = if rf.is_some() { to.1 } else { from.1 };
            return self.per_section_ok(l, scalar);
        }
        if rf.is_some() && rt.is_some() && from.0 != to.0 {
            // `link a[j] -> b[j + k] for j in 0..n`: sections of two arrays
            let (a, b) = (self.vessel_name(from.0), self.vessel_name(to.0));
            self.cx.error(
                l.to.name.span(),
                format!("`{b}` is an array: a per-section link (`for j in 0..n`) joins every section of `{a}` to one CV or space, not to the sections of another array (whose index would run over another length); write `link {a}[j] -> name for j in 0..n` with a single CV or space"),
            );
            return false;
        }
        let (Some(rf), Some(rt)) = (rf, rt) else {
            self.cx.error(range.span, "a `for` link must index both ends with the range variable, e.g. `a[j] -> a[j + 1]`");
            return false;
        };
        if from.0 != to.0 {
            self.cx
                .error(l.span, "a chain link must join sections of one array");
            return false;
        }
        self.chain_range_ok(range, from.0, rf.min(rt), rf.max(rt))
    }

    /// The range of a chain link whose ends sit at offsets `lo <= hi` of array `array`:
    /// `for j in 0..n - 1` with `hi = lo + 1 = 1`, or an error at the range.
    fn chain_range_ok(&mut self, range: &RangeAst, array: Vessel, lo: i32, hi: i32) -> bool {
        let start = self.expr(&range.start, None);
        let end = self.expr(&range.end, None);
        let s = sample(self, start, 0.0, 10.0);
        let e_off = sample(self, end, 0.0, 10.0) - 10.0;
        if s + lo as f64 != 0.0 && s + (lo as f64) < 0.0 {
            self.cx.error(
                range.start.span(),
                format!(
                    "the link runs before the start of the array: the index reaches {}",
                    s as i32 + lo
                ),
            );
            return false;
        }
        if e_off + hi as f64 > 0.0 {
            let name = self.vessel_name(array);
            let reach = e_off as i32 + hi - 1;
            let reach = if reach == 0 {
                "n".to_string()
            } else {
                format!("n {} {}", if reach > 0 { "+" } else { "-" }, reach.abs())
            };
            self.cx.error(
                range.end.span(),
                format!(
                    "the link runs past the end of `{name}`: its last section is n - 1, but with this range the index reaches {reach}; expected `for j in 0..n - {}`",
                    hi - lo
                ),
            );
            return false;
        }
        if s != 0.0 || lo != 0 || hi != 1 || e_off != -1.0 {
            self.cx.error(range.span, "unsupported chain: expected `a[j] -> a[j + 1] for j in 0..n - 1` (or the reverse direction)");
            return false;
        }
        true
    }

    /// `link a[j] -> b for j in 0..n`: every section of `a` to one CV or space `b`.
    fn per_section_ok(&mut self, l: &LinkAst, other: At) -> bool {
        let range = l.range.as_ref().expect("a `for` link");
        if other != At::Scalar {
            self.cx.error(l.to.name.span(), "a per-section link joins every section of an array to one CV or space, not to a section of an array");
            return false;
        }
        let start = self.expr(&range.start, None);
        let end = self.expr(&range.end, None);
        let (s, e) = (sample(self, start, 0.0, 10.0), sample(self, end, 0.0, 10.0));
        if s != 0.0 || e != 10.0 || sample(self, end, 0.0, 11.0) != 11.0 {
            self.cx.error(
                range.span,
                "a per-section link runs over every section: expected `for j in 0..n`",
            );
            return false;
        }
        true
    }

    fn vessel_name(&self, v: Vessel) -> String {
        if let Vessel::Wall(w) = v {
            let found = self.walls.iter().find(|(_, &(i, _))| i == w);
            return found.map(|(k, _)| k.clone()).unwrap_or_default();
        }
        self.vessels
            .iter()
            .find(|(_, &x)| x == v)
            .map(|(k, _)| k.clone())
            .unwrap_or_default()
    }
}
