//! Link ends seen from a row (which section a link touches, where its other end sits) and the
//! flow laws of a mass-flow link (docs/physics.md section 4).

use super::assemble::RowAt;
use super::decl::{GasDecl, Vessel};
use super::frame::Place;
use super::system::Variant;
use crate::expr::{At, Func, Id};

/// Whether a link end at `at` touches the row's section; returns the row's offset in the
/// link's frame (`0`, or `1` for the upper end of a chain link whose lower offset is `rel_min`).
pub(super) fn touches(at: At, row: RowAt, rel_min: i32) -> Option<i32> {
    match (at, row) {
        (At::Scalar, RowAt::Scalar) => Some(0),
        (At::First, RowAt::Array(_, v)) => {
            matches!(v, Variant::Single | Variant::First).then_some(0)
        }
        (At::Last, RowAt::Array(_, v)) => matches!(v, Variant::Single | Variant::Last).then_some(0),
        (At::Rel(r), RowAt::Array(_, v)) => {
            let upper = r > rel_min;
            let ok = if upper {
                matches!(v, Variant::Interior | Variant::Last)
            } else {
                matches!(v, Variant::First | Variant::Interior)
            };
            ok.then_some(r)
        }
        _ => None,
    }
}

/// The lower `Rel` offset of a link's two ends (`0` if neither is `Rel`).
pub(super) fn rel_min(from: At, to: At) -> i32 {
    let r = |a: At| if let At::Rel(r) = a { r } else { 0 };
    r(from).min(r(to))
}

/// Where a link end of array `vessel` sits relative to the row's own section.
pub(super) fn end_place(vessel: Vessel, at: At, row: RowAt, base: i32) -> Place {
    let own_array = matches!(row, RowAt::Array(v, _) if v == vessel);
    match at {
        At::Scalar => Place::Own,
        At::Rel(r) => Place::Shift(r - base),
        At::First => match row {
            RowAt::Array(_, Variant::Single | Variant::First) if own_array => Place::Own,
            _ => Place::First,
        },
        At::Last => match row {
            RowAt::Array(_, Variant::Single | Variant::Last) if own_array => Place::Own,
            _ => Place::Last,
        },
    }
}

pub(super) fn end_name(name: &str, array: bool, at: At) -> String {
    if !array {
        return name.to_string();
    }
    match at {
        At::First => format!("{name}[0]"),
        At::Last => format!("{name}[n-1]"),
        At::Rel(r) => format!("{name}[{}]", super::frame::index_text(r)),
        At::Scalar => name.to_string(),
    }
}

/// `dP = R mdot + Rq mdot |mdot|` solved for `mdot`: `2 dP / (R + sqrt(R^2 + 4 Rq |dP|))`.
pub(super) fn quadratic_flow(a: &mut crate::expr::Arena, dp: Id, r: Id, rq: Id) -> Id {
    let (two, four) = (a.num(2.0), a.num(4.0));
    let r2 = a.powi(r, 2);
    let adp = a.func(Func::Abs, dp);
    let t = a.mul(four, rq);
    let t = a.mul(t, adp);
    let s = a.add(r2, t);
    let root = a.func(Func::Sqrt, s);
    let den = a.add(r, root);
    let num = a.mul(two, dp);
    a.div(num, den)
}

/// The orifice law `mdot = C sign(dP) sqrt|dP|` regularized so that it is smooth at `dP = 0`:
/// `C dP / (dP^2 + dP0^2)^(1/4)`, written `C dP / sqrt(sqrt(dP^2 + dP0^2))`. For `|dP| >> dP0`
/// it is the square-root law to a relative `(dP0/dP)^2 / 4`; for `|dP| << dP0` it is linear,
/// `C dP / sqrt(dP0)`; it is infinitely differentiable for `dP0 > 0`.
pub(super) fn orifice_flow(a: &mut crate::expr::Arena, dp: Id, c: Id, dp0: Id) -> Id {
    let dp2 = a.powi(dp, 2);
    let w2 = a.powi(dp0, 2);
    let s = a.add(dp2, w2);
    let root = a.func(Func::Sqrt, s);
    let root = a.func(Func::Sqrt, root);
    let num = a.mul(c, dp);
    a.div(num, root)
}

/// `H = cp mdot (s T_from + (1 - s) T_to)`, `s = (1 + tanh(mdot/eps))/2`, `cp = gamma R/(gamma-1)`.
pub(super) fn enthalpy(
    a: &mut crate::expr::Arena,
    mdot: Id,
    t_from: Id,
    t_to: Id,
    gas: &GasDecl,
) -> Id {
    let (one, half) = (a.num(1.0), a.num(0.5));
    let ratio = a.div(mdot, gas.mdot_eps);
    let th = a.func(Func::Tanh, ratio);
    let opt = a.add(one, th);
    let s = a.mul(half, opt);
    let dt = a.sub(t_from, t_to);
    let sdt = a.mul(s, dt);
    let t_up = a.add(t_to, sdt);
    let gm1 = a.sub(gas.gamma, one);
    let gr = a.mul(gas.gamma, gas.r);
    let cp = a.div(gr, gm1);
    let cm = a.mul(cp, mdot);
    a.mul(cm, t_up)
}
