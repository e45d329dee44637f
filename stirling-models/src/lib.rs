//! # stirling-models: the seed family and the analyses
//!
//! Every analysis here is generic: it takes a `&dyn` [`dsl::Model`], the trait every
//! `stirling_model!` declaration implements, so a topology declared in user code gets the
//! same equilibrium, poles, margins, limit cycle and plots as the seed's family.
//!
//! - [`model`]: model construction. [`family`]: `schmidt`, `cv1`, `cv2`, `nsection`
//!   declared with `stirling_model!` on the default engine of docs/physics.md section 8;
//!   [`effects`]: the effects the nominal models leave out; [`params`]: parameter files,
//!   overrides and validation; [`registry`]: the family by name, as the command line uses it.
//! - [`linear`]: equilibrium by Newton ([`linear::equilibrium::solve`]), the dynamic poles
//!   with the inventory mode removed ([`linear::dynamic_poles`]), the loop broken at a
//!   pressure force with gain and phase margins and Bode/Nyquist data
//!   ([`linear::linearize`]), root loci ([`linear::locus`]).
//! - [`sim`]: stiff integration on the analytic Jacobian ([`sim::simulate`], [`sim::integrate()`]
//!   for any [`sim::OdeSystem`], e.g. [`sim::EnergySystem`] which carries the energy budget as a
//!   quadrature), limit cycles by shooting with Floquet multipliers ([`sim::limit_cycle`]), cycle
//!   work ([`sim::cycle_work`]).
//! - [`plot`]: SVG figures (pole map, Bode, root locus, start-up response, PV diagrams).
//! - [`data`]: measured records (CSV) with row and column errors; [`rig`]: the virtual test
//!   rig that writes them from a truth model with effects, noise and offsets.
//! - [`fit`]: the two-stage identification (mechanics driven by pressure, gas driven by
//!   positions), on the seed's sensors too; [`diagnose`]: the sim-to-real gap diagnosis.
//! - [`layout`]: which state is what; [`signal`]: smoothing, noise level, cycles, harmonics,
//!   filters and statistical tails shared by the analyses.
//!
//! ## Linear analysis
//!
//! ```
//! use stirling_models::dsl::{Closure, Model};
//! use stirling_models::family::NSection;
//! use stirling_models::linear::{self, LinearOptions};
//!
//! let model = NSection::new(2, Closure::Full).unwrap(); // 2 regenerator sections, 12 states
//! let p = model.default_params();
//! let lin = linear::linearize(&model, &p, &LinearOptions::default()).unwrap();
//! // the rest state solves f(x) = 0 (Newton on the analytic Jacobian)
//! assert!(lin.dynamics.equilibrium.scaled_residual < 1e-8);
//! // the default engine is unstable: one pair in the right half plane, near 85 rad/s
//! let rhp: Vec<_> = lin.dynamics.poles.iter().filter(|p| p.rhp).collect();
//! assert_eq!(rhp.len(), 2);
//! assert!((rhp[0].im.abs() - 85.0).abs() < 15.0);
//! let m = &lin.margins;
//! println!("loop at `{}`: Gm {:?} dB at {:?} rad/s", lin.open_loop.full.name, m.gain_db, m.phase_crossover_rad_s);
//! // the serializable summary (what `stirling linearize --json` prints)
//! let report = lin.report(&model);
//! assert_eq!(report.rhp_count, 2);
//! ```
//!
//! ## Simulation, energy budget and limit cycle
//!
//! ```
//! use stirling_models::dsl::{Closure, Model};
//! use stirling_models::family::NSection;
//! use stirling_models::sim::{self, EnergySystem, Hooks, ModelSystem, SimOptions};
//!
//! let model = NSection::new(1, Closure::Full).unwrap();
//! let p = model.default_params();
//! let mut x0 = vec![0.0; model.n_states()];
//! model.equilibrium_guess(&p, &mut x0);
//! x0[0] = 5e-3; // displace the displacer by 5 mm
//!
//! // a short run: the gas inventory is conserved to round-off
//! let tr = sim::simulate(&model, &p, &x0, 0.05, &sim::uniform_samples(0.05, 50), &SimOptions::default()).unwrap();
//! let m0 = model.gas_mass(&p, &x0);
//! assert!(tr.x.iter().all(|x| (model.gas_mass(&p, x) - m0).abs() < 1e-12 * m0));
//!
//! // the energy budget (docs/physics.md section 10) as a quadrature state of the same run:
//! // E(t) - E(0) = integral of heat + boundary + mechanical power
//! let n = model.n_states();
//! let mut z0 = x0.clone();
//! z0.push(0.0);
//! let sys = EnergySystem { inner: ModelSystem { model: &model, p: &p } };
//! let tr = sim::integrate(&sys, &z0, 0.05, &[0.05], &SimOptions::default(), Hooks::default()).unwrap();
//! let gap = model.energy(&p, &tr.x_end[..n]) - model.energy(&p, &x0) - tr.x_end[n];
//! assert!(gap.abs() < 1e-3);
//!
//! // settle on the limit cycle, refine it by shooting, and measure it
//! let lc = sim::limit_cycle(&model, &p, &x0, 20.0, &[], &SimOptions::default(), None).unwrap();
//! let f = &lc.figures;
//! println!("{:.3} Hz, x {:.2} mm, y {:.2} mm, {:.4} J per cycle", f.frequency_hz, 1e3 * f.x_amp, 1e3 * f.y_amp, lc.work.total);
//! assert!(lc.work.total > 0.0, "the engine does work");
//! assert!((f.frequency_hz - 85.0 / (2.0 * std::f64::consts::PI)).abs() < 3.0);
//! ```
//!
//! ## Your own topology
//!
//! Declare it with `stirling_model!` (in a user crate: `stirling::stirling_model`, with
//! `stirling-dsl` as a dependency) and pass it to the same functions. A complete engine with
//! a closed bounce space and a linear alternator is `examples/custom_topology.rs`, a
//! user-chosen regenerator profile `examples/custom_profile.rs`; the chapter
//! `docs/custom-topologies.md` walks through both. In short:
//!
//! ```
//! use stirling_models::dsl::{Closure, Model};
//! use stirling_models::linear::{self, NewtonOptions};
//!
//! stirling_macros::stirling_model! {
//!     /// A piston on a gas spring that a heated wall drives through a heat port.
//!     pub model HeatedSpring {
//!         params {
//!             m: 0.3 "kg", k: 60.0 "N/m", c: 0.5 "N s/m", A: 2.8e-3 "m^2", V0: 2.0e-4 "m^3",
//!             Tw: 450.0 "K", h: 200.0 "W/(m^2 K)", Aw: 0.01 "m^2",
//!             R: 287.05 "J/(kg K)", gamma: 1.4 "-", P0: 101325.0 "Pa", eps: 1e-5 "kg/s",
//!         }
//!         gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
//!         body piston(y, w) { mass: m, spring: k, damper: c }
//!         space outside { pressure: P0, faces { piston: A } }
//!         cv gas { volume: V0, faces { piston: -A }, port wall { h: h, area: Aw, wall: Tw } }
//!     }
//! }
//!
//! let model = HeatedSpring::new(1, Closure::Full).unwrap();
//! let p = model.default_params();
//! let d = linear::dynamic_poles(&model, &p, &NewtonOptions::default()).unwrap();
//! // states [y, w, P_gas]: a damped gas-spring pair and the thermal pole
//! assert_eq!(d.poles.len(), 3);
//! assert!(d.poles.iter().all(|p| !p.rhp));
//! println!("{}", model.equations(stirling_models::dsl::Style::Text));
//! ```

/// Measured data: CSV input with row/column errors, sensor offsets.
pub mod data;
/// The sim-to-real gap diagnosis: where, which effect, how far.
pub mod diagnose;
/// Identification: driven subsystems, forward sensitivities, Levenberg-Marquardt, report.
pub mod fit;
/// Which state of a model is what (positions, velocities, pressures, masses).
pub mod layout;
/// Linear analysis: equilibrium, poles, the loop broken at a pressure force, margins, locus.
pub mod linear;
/// Model construction: the family, the effects, the registry, parameters.
pub mod model;
/// SVG figures: pole map, Bode, root locus, start-up, PV diagrams, measured vs model.
/// Files written whole or not at all (temporary file and rename, pairs under a lock).
pub mod output;
pub mod plot;
/// The virtual test rig: truth model plus effects, noise, offsets, sample rate.
pub mod rig;
/// Signal processing shared by fit, diagnose and rig: smoothing, noise level, cycles,
/// harmonics, filters, statistical tails.
pub mod signal;
/// Nonlinear simulation, limit cycles, Floquet multipliers and cycle work.
pub mod sim;
/// Design sweeps: poles, whether the engine runs, and its cycle over a parameter grid.
pub mod sweep;

pub use model::{bounds, effects, family, files, outside, params, registry, user_models};
pub use registry::{build, RegistryError, FAMILY};
pub use stirling_dsl as dsl;
/// The macro at this crate's root: the exported bases (`default_engine`, `nsection_engine`)
/// call it back as `$crate::stirling_model!` when another crate extends them.
pub use stirling_macros::stirling_model;
