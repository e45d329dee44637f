//! Causes outside the effect library: truth models for the rig and the diagnosis self-check
//! only. The diagnosis never sees them (they are not in [`crate::effects::EFFECTS`]); on
//! their records its right answer is `unexplained`.
//!
//! Both extend the augmented `nsection` engine (`nsection_fx`: every library effect at its null;
//! docs/custom-topologies.md, "Composition") with one strength parameter whose null (0) gives
//! the nominal `nsection` exactly; so the rig can put a library effect beside an outside cause
//! (the self-check's mixed records):
//!
//! - `h_speed`: heat-transfer coefficients that grow with the gas speed the pistons drive,
//!   `h_hot = hh (1 + chv |v|)`, `h_cold = hk (1 + chv |v - w|)`, with the smooth
//!   `|u| = sqrt(u^2 + v_h^2) - v_h` (a Reynolds-number dependence; `chv` in s/m);
//! - `spring_cubic`: hardening flexure springs, `-k3 x^3` on the displacer and
//!   `-k3 (kp/kd) y^3` on the piston (both flexures harden alike relative to their rate).

use stirling_dsl::{Closure, Model};
// `nsection_fx_engine` is crate-local: extending it calls back through the `stirling_model` in scope.
use super::effects::nsection_fx_engine;
use stirling_macros::stirling_model;

stirling_macros::stirling_model! {
    /// `nsection` with heat-transfer coefficients growing with the piston speeds (outside the
    /// effect library; `chv = 0` is the nominal model).
    pub model NSectionHSpeed extends nsection_fx_engine {
        name "nsection_h_speed";
        params {
            /// growth of the heat-transfer coefficients with the gas speed (0: constant h)
            chv: 0.0 "s/m",
            /// velocity scale of the smoothed speed
            v_h: 1.0e-3 "m/s",
        }
        modify cv hot {
            port hot { h: hh * (1.0 + chv * (sqrt(v * v + v_h * v_h) - v_h)), area: Awh0 - pi * D * x, wall: Th },
        }
        modify cv cold {
            port cold { h: hk * (1.0 + chv * (sqrt((v - w) * (v - w) + v_h * v_h) - v_h)), area: Awc0 + pi * D * (x - y), wall: Tk },
        }
    }
}

stirling_macros::stirling_model! {
    /// `nsection` with hardening (cubic) flexure springs (outside the effect library; `k3 = 0`
    /// is the nominal model).
    pub model NSectionSpringCubic extends nsection_fx_engine {
        name "nsection_spring_cubic";
        params {
            /// cubic stiffness of the displacer flexure; the piston's is `k3 kp / kd` (0: linear)
            k3: 0.0 "N/m^3",
        }
        modify body displacer { force: -k3 * x * x * x }
        modify body piston { force: -k3 * kp / kd * y * y * y }
    }
}

/// One outside cause: its truth model and strength parameter.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct OutsideInfo {
    pub name: &'static str,
    pub summary: &'static str,
    /// The strength parameter (null 0).
    pub param: &'static str,
    /// The self-check's unit strength (1x), chosen so that the limit cycle's stroke or
    /// frequency moves at least as much as under the library effects at their first strength.
    pub typical: f64,
    pub unit: &'static str,
}

/// The causes outside the library.
pub const OUTSIDE: &[OutsideInfo] = &[
    OutsideInfo {
        name: "h_speed",
        summary: "heat-transfer coefficients growing with the gas speed: h = hh (1 + chv |v|), hk (1 + chv |v - w|)",
        param: "chv",
        typical: 1.0,
        unit: "s/m",
    },
    OutsideInfo {
        name: "spring_cubic",
        summary: "hardening flexure springs: -k3 x^3 on the displacer, -k3 kp/kd y^3 on the piston",
        param: "k3",
        typical: 5.0e6,
        unit: "N/m^3",
    },
];

/// Why an outside truth model cannot be built.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum OutsideError {
    #[error("unknown truth model `{name}`: expected one of {known}")]
    Unknown { name: String, known: String },
    #[error("truth model `{name}` extends nsection; --n must be at least 1")]
    Sections { name: String },
}

/// The outside cause `name`.
pub fn outside(name: &str) -> Option<&'static OutsideInfo> {
    OUTSIDE.iter().find(|o| o.name == name)
}

/// The truth model of outside cause `name` with `n` regenerator sections (default 1).
pub fn build(
    name: &str,
    n: Option<usize>,
    closure: Closure,
) -> Result<Box<dyn Model>, OutsideError> {
    let n = n.unwrap_or(1);
    let bad = || OutsideError::Sections { name: name.into() };
    Ok(match name {
        "h_speed" => Box::new(NSectionHSpeed::new(n, closure).map_err(|_| bad())?),
        "spring_cubic" => Box::new(NSectionSpringCubic::new(n, closure).map_err(|_| bad())?),
        _ => {
            return Err(OutsideError::Unknown {
                name: name.into(),
                known: OUTSIDE
                    .iter()
                    .map(|o| o.name)
                    .collect::<Vec<_>>()
                    .join(", "),
            })
        }
    })
}
