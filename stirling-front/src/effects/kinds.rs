//! The effects an `effect` item can name: where each acts, its parameters (the strength
//! first, null 0) and its term.

use syn::{Expr, Ident};

/// Where an effect of a kind acts, and what it adds there.
pub enum Where {
    /// On a body (`on <body>`): a force term from the parameter names and the body's position
    /// and velocity, subtracted from the body's force.
    Body(fn(&[Ident], &Ident, &Ident) -> Expr),
    /// Between two volumes (`<from> -> <to>`): a mass-flow link with these fields.
    Between(fn(&[Ident]) -> Vec<(&'static str, Expr)>),
    /// On a declared link (`on link <from> -> <to>`): these fields added to it.
    Link(fn(&[Ident]) -> Vec<(&'static str, Expr)>),
    /// On a CV's heat port (`on port <cv>.<port>`): its fixed wall temperature becomes a wall.
    Port(super::ports::PortShape),
    /// On a declared sensor (`on sensor <name>`): a distortion of its reading, applied by the
    /// rig and fitted by the diagnosis; the model's equations are unchanged and its one
    /// parameter (`tau_<sensor>`, `gain_<sensor>`) is not a model parameter.
    Sensor,
}

/// A parameter: its default name (`{0}`: the body or first end, `{1}`: the body's position
/// or the second end), default value (the strength's is its null, 0), unit and doc (`{site}`:
/// where the effect acts).
pub struct ParamKind {
    pub name: &'static str,
    pub default: f64,
    pub unit: &'static str,
    pub doc: &'static str,
}

/// An effect kind.
pub struct Kind {
    pub name: &'static str,
    pub site: Where,
    pub params: &'static [ParamKind],
}

const fn param(
    name: &'static str,
    default: f64,
    unit: &'static str,
    doc: &'static str,
) -> ParamKind {
    ParamKind {
        name,
        default,
        unit,
        doc,
    }
}

/// Coulomb friction, smoothed: `Fc tanh(v / v_eps)`.
fn coulomb(p: &[Ident], _pos: &Ident, vel: &Ident) -> Expr {
    let (fc, eps) = (&p[0], &p[1]);
    syn::parse_quote!(#fc * tanh(#vel / #eps))
}

/// End stops: `kc relu(|q| - q_max) sign(q)`, `relu(u) = (u + |u|) / 2`.
fn end_stops(p: &[Ident], pos: &Ident, _vel: &Ident) -> Expr {
    let (kc, qmax) = (&p[0], &p[1]);
    syn::parse_quote!(#kc * ((abs(#pos) - #qmax) + abs(abs(#pos) - #qmax)) / 2.0 * sign(#pos))
}

/// A seal leak: a linear conductance.
fn leak(p: &[Ident]) -> Vec<(&'static str, Expr)> {
    let g = &p[0];
    vec![("conductance", syn::parse_quote!(#g))]
}

/// Quadratic (turbulent) friction of a link: `dP = R mdot + Rq mdot |mdot|`.
fn quadratic(p: &[Ident]) -> Vec<(&'static str, Expr)> {
    let rq = &p[0];
    vec![("quadratic", syn::parse_quote!(#rq))]
}

/// A seal leak through an orifice: the square-root law with its linear core `dP0`.
fn orifice_leak(p: &[Ident]) -> Vec<(&'static str, Expr)> {
    let (co, dp0) = (&p[0], &p[1]);
    vec![
        ("orifice", syn::parse_quote!(#co)),
        ("dp0", syn::parse_quote!(#dp0)),
    ]
}

pub const KINDS: &[Kind] = &[
    Kind {
        name: "coulomb",
        site: Where::Body(coulomb),
        params: &[
            param(
                "Fc_{0}",
                0.0,
                "N",
                "Coulomb friction force on {site} (0: none)",
            ),
            param(
                "v_eps",
                1.0e-3,
                "m/s",
                "velocity scale of the smoothed Coulomb friction",
            ),
        ],
    },
    Kind {
        name: "end_stops",
        site: Where::Body(end_stops),
        params: &[
            param(
                "kc_{0}",
                0.0,
                "N/m",
                "end-stop contact stiffness on {site} (0: no stops)",
            ),
            param("{1}max", 0.01, "m", "travel of {site} to its end stops"),
        ],
    },
    Kind {
        name: "leak",
        site: Where::Between(leak),
        params: &[param(
            "Gleak_{0}_{1}",
            0.0,
            "kg/(s Pa)",
            "seal-leak conductance {site} (0: no leak)",
        )],
    },
    Kind {
        name: "quadratic",
        site: Where::Link(quadratic),
        params: &[param(
            "Rq_{0}_{1}",
            0.0,
            "Pa s^2/kg^2",
            "quadratic flow resistance of {site} (0: linear only)",
        )],
    },
    Kind {
        name: "orifice_leak",
        site: Where::Between(orifice_leak),
        params: &[
            param(
                "Co_{0}_{1}",
                0.0,
                "kg/(s Pa^0.5)",
                "orifice seal-leak coefficient {site} (0: no leak)",
            ),
            param("dP0", 50.0, "Pa", "width of the orifice law's linear core"),
        ],
    },
    Kind {
        name: "lag",
        site: Where::Sensor,
        params: &[param(
            "tau_{0}",
            0.0,
            "s",
            "first-order lag of {site} (0: none)",
        )],
    },
    Kind {
        name: "gain",
        site: Where::Sensor,
        params: &[param(
            "gain_{0}",
            0.0,
            "-",
            "relative gain error of {site}: read (1 + gain) times the value",
        )],
    },
    Kind {
        name: "heater_input",
        site: Where::Port(super::ports::PortShape::Head),
        params: &[
            param(
                "kh_{0}_{1}",
                0.0,
                "K/J",
                "inverse heat capacity of the wall behind {site} (0: infinite, the fixed wall)",
            ),
            param(
                "Gh_{0}_{1}",
                0.5,
                "W/K",
                "conductance from the fixed source to the wall behind {site} (its finite input)",
            ),
        ],
    },
    Kind {
        name: "matrix_capacity",
        site: Where::Port(super::ports::PortShape::Matrix),
        params: &[
            param(
                "km_{0}_{1}",
                0.0,
                "K/J",
                "inverse heat capacity of the whole matrix behind {site} (0: infinite, the fixed wall)",
            ),
            param(
                "Gm_{0}_{1}",
                0.03,
                "W/K",
                "axial conductance of the whole matrix behind {site}",
            ),
        ],
    },
];
