//! # stirling: energetic, symbolic modeling of free-piston Stirling engines
//!
//! Declare a topology with [`stirling_model!`]; get, at compile time, a model type that
//! implements [`dsl::Model`]: the right-hand side, the analytic Jacobian, the parameter
//! Jacobian, the equations as text and LaTeX, and the bond-graph view. The analyses in
//! [`models`] run on any such model. The seed's family (`schmidt`, `cv1`, `cv2`,
//! `nsection`) is in [`models::family`].
//!
//! The generated code names the symbolic core `::stirling_dsl`, so a crate that declares
//! models depends on `stirling-dsl` as well as on this crate (or on `stirling-macros`).
//!
//! ```
//! use stirling::dsl::{Closure, Model, Style};
//! use stirling::stirling_model;
//!
//! stirling_model! {
//!     /// A gas spring: one piston on one control volume with one heat port.
//!     pub model GasSpring {
//!         params {
//!             m: 1.0 "kg", k: 50.0 "N/m", c: 2.0 "N s/m", A: 1e-3 "m^2", V0: 1e-4 "m^3",
//!             Tw: 300.0 "K", h: 50.0 "W/(m^2 K)", Aw: 0.02 "m^2",
//!             R: 287.0 "J/(kg K)", gamma: 1.4 "-", P0: 1e5 "Pa", eps: 1e-5 "kg/s",
//!         }
//!         gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
//!         body piston(y, w) { mass: m, spring: k, damper: c }
//!         space outside { pressure: P0, faces { piston: A } }
//!         cv gas { volume: V0, faces { piston: -A }, port wall { h: h, area: Aw, wall: Tw } }
//!     }
//! }
//!
//! let model = GasSpring::new(1, Closure::Full).unwrap();
//! let p = model.default_params();
//! let mut x = vec![0.0; model.n_states()]; // [y, w, P_gas]
//! model.equilibrium_guess(&p, &mut x);
//! let mut f = vec![0.0; x.len()];
//! model.rhs(&p, &x, 0.0, &mut f);
//! assert!(f.iter().all(|v| v.abs() < 1e-9)); // at rest
//! let j = model.jacobian_dense(&p, &x, 0.0);
//! let n = x.len(); // column-major: J[r + n c] = d f_r / d x_c
//! assert!((j[1 + n * 0] + 50.0).abs() < 1e-12); // d(w')/dy = -k/m: the spring
//! // the gas spring acts through the pressure state: d(P')/dw = gamma P0 A / V0
//! let gas_spring = 1.4 * 1e5 * 1e-3 / 1e-4;
//! assert!((j[2 + n * 1] - gas_spring).abs() < 1e-9 * gas_spring);
//! println!("{}", model.equations(Style::Text));
//! ```

pub use stirling_dsl as dsl;
pub use stirling_macros::stirling_model;
pub use stirling_models as models;
