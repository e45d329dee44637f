//! # stirling-dsl: the symbolic core of `stirling`
//!
//! A free-piston Stirling engine is declared as a topology of bodies, gas control
//! volumes (CVs), faces, heat ports and mass-flow links. This crate turns such a
//! declaration into equations by the energetic rules of docs/physics.md, differentiates
//! them symbolically and emits Rust: the right-hand side, the analytic Jacobian and
//! the parameter Jacobian, for any number `n` of array sections chosen at run time.
//!
//! ## Map of the crate
//!
//! - [`expr`]: the hash-consed expression [`Arena`] (folding constructors, [`Arena::diff`],
//!   substitution, [`Arena::eval`], text/LaTeX [`expr::Printer`], Rust emission with CSE).
//! - [`topology`]: the declaration ([`Topology`]) and its assembly ([`assemble`]) into
//!   equations: faces give both `dV/dt` and the pressure forces, ports the heat, links the
//!   mass and enthalpy flows (docs/physics.md sections 1, 2, 4).
//! - [`codegen`]: emission of a whole model ([`codegen::generate`]), used by the
//!   `stirling_model!` macro at compile time.
//! - The run-time interface every generated model implements: [`Model`], with
//!   [`ParamInfo`], [`StateInfo`]/[`StateKind`], [`JacSink`], [`PowerTerms`], [`TopologyInfo`]
//!   and the true bond graph of a model, [`bond::bond_graph`] (docs/bond-graphs.md). The analyses of `stirling-models` take `&dyn Model`.
//!
//! ## Declaring a model (the usual entry point)
//!
//! Users do not call this crate's builders directly: they write a `stirling_model!`
//! declaration (crate `stirling-macros`, re-exported as `stirling::stirling_model`) in their
//! own crate. The macro checks the topology (unknown bodies or volumes, chain links that run
//! past the end of an array, missing ports, ... are compile errors at the user's tokens),
//! assembles it with this crate and emits a type `Name` with `Name::new(n, closure)` that
//! implements [`Model`]. The generated code names this crate `::stirling_dsl`, so a crate
//! that declares models depends on `stirling-dsl` as well (the facade `stirling` does).
//! The declaration syntax and a complete worked example are in the `stirling` crate root and
//! in `docs/custom-topologies.md`; what a generated model offers at run time:
//!
//! | [`Model`] method | what |
//! |---|---|
//! | `rhs`, `jacobian`, `param_jacobian` | `f(x, p)`, `df/dx`, `df/dp` (analytic) |
//! | `states`, `params`, `bodies`, `vessel_names` | the layout `[x, v, y, w, P_1.., m_1..]` and its meaning |
//! | `equilibrium_guess` | the rest state of docs/physics.md section 6 |
//! | `pv`, `temperatures`, `gas_mass` | derived quantities per vessel |
//! | `energy`, `power` | `E` and `dE/dt = heat + boundary + mechanical` (section 10) |
//! | `pressure_forces`, `pressure_force_gradient`, `body_masses` | where the loop is broken |
//! | `equations(Style::Text / Style::Latex)`, `topology` | the equations as text and the bond graph |
//!
//! ## The symbolic core by hand
//!
//! The expression arena is usable on its own. Expressions are hash-consed (equal
//! subexpressions share one node), constructors fold constants, and [`Arena::diff`]
//! differentiates with respect to any symbol. Here the heat flow of a port,
//! `Q = h Aw (Tw - T)` with the gas temperature `T = P V / (m R)` (docs/physics.md section 4),
//! and its derivative with respect to the pressure, which is what the generated Jacobian
//! holds in the row of `P'`:
//!
//! ```
//! use stirling_dsl::expr::Printer;
//! use stirling_dsl::{Arena, Style, Sym};
//!
//! let names = ["h", "Aw", "Tw", "R", "P", "V", "m"];
//! let mut a = Arena::new();
//! let s: Vec<_> = (0..names.len() as u32).map(|k| a.sym(Sym::Param(k))).collect();
//! let (h, aw, tw, r, p, v, m) = (s[0], s[1], s[2], s[3], s[4], s[5], s[6]);
//! // T = P V / (m R), named so that the printers show it as a definition
//! let pv = a.mul(p, v);
//! let mr = a.mul(m, r);
//! let t = a.div(pv, mr);
//! let t = a.named("T", t);
//! // Q = h Aw (Tw - T)
//! let hw = a.mul(h, aw);
//! let dt = a.sub(tw, t);
//! let q = a.mul(hw, dt);
//! let dq_dp = a.diff(q, Sym::Param(4));
//!
//! // evaluate at a state: dQ/dP = -h Aw V / (m R)
//! let values = [500.0, 0.0128, 600.0, 287.05, 101325.0, 1.5e-4, 8.8e-5];
//! let mut at = |sym: Sym| match sym {
//!     Sym::Param(k) => values[k as usize],
//!     _ => unreachable!(),
//! };
//! let expected = -500.0 * 0.0128 * 1.5e-4 / (8.8e-5 * 287.05);
//! assert!((a.eval(dq_dp, &mut at) - expected).abs() < 1e-12 * expected.abs());
//!
//! // the derivative with respect to a symbol it does not contain folds to the constant 0
//! let zero = a.diff(q, Sym::Count);
//! assert_eq!(a.as_const(zero), Some(0.0));
//! // hash-consing: building the same expression again gives the same node
//! let pv_again = a.mul(p, v);
//! assert_eq!(pv, pv_again);
//!
//! // print as text and as LaTeX, with the named intermediate as a definition
//! let namer = |sym: Sym| match sym {
//!     Sym::Param(k) => names[k as usize].to_string(),
//!     other => format!("{other:?}"),
//! };
//! let text = Printer::new(&a, Style::Text, &namer);
//! for (name, body) in text.definitions(&[q]) {
//!     println!("{name} = {body}");
//! }
//! println!("Q = {}", text.expr(q));
//! println!("dQ/dP = {}", text.expr(dq_dp));
//! let latex = Printer::new(&a, Style::Latex, &namer).expr(dq_dp);
//! println!("LaTeX: {latex}");
//! assert!(text.expr(q).contains('T'));
//! ```
//!
//! ## Invariants the generated code keeps
//!
//! - one face declaration `a_ik` yields both `dV_i/dt` and the force `a_ik P_i` on body `k`,
//!   so the gas's `P dV` work enters the bodies exactly (an energy-conserving transformer);
//! - with the `full` [`Closure`] the masses of linked CVs are states and `sum m_i` is
//!   conserved; `frozen` drops them (the seed's orders);
//! - the Jacobians are exact derivatives of the right-hand side (the smooth upwind switch
//!   `tanh(mdot/mdot_eps)` makes them exist everywhere).

/// The true bond graph of a model: junctions, causality, states.
pub mod bond;
mod closure;
/// Rust emission of a whole model.
pub mod codegen;
/// Models compiled at run time from a lowered topology: the same equations as the macro's,
/// as register tapes.
pub mod compiled;
/// The symbolic core.
pub mod expr;
/// What generated models implement and what the analyses use.
pub mod runtime;
/// The topology description and its energetic assembly into equations.
pub mod topology;

pub use closure::Closure;
pub use expr::{Arena, Id, Style, Sym};
pub use runtime::{
    BodyElementsInfo, BodyInfo, ConductionInfo, EffectSite, FaceInfo, JacSink, JacValues, JacWrite,
    LinkInfo, Model, ModelError, Observation, ObserveError, ParamInfo, PortInfo, PowerTerms,
    SensorInfo, StateInfo, StateKind, TopologyInfo, VesselInfo, WallInfo,
};
pub use topology::{assemble, Topology};

/// Helpers for generated code only.
#[doc(hidden)]
pub mod __private {
    pub use crate::expr::{sign, tanh};
    pub use crate::topology::Variant;
    pub use serde;

    impl Variant {
        /// The variant of section `j` of `n`.
        #[inline(always)]
        pub fn of(j: usize, n: usize) -> Variant {
            if n == 1 {
                Variant::Single
            } else if j == 0 {
                Variant::First
            } else if j + 1 == n {
                Variant::Last
            } else {
                Variant::Interior
            }
        }
    }
}
