//! Which free parameter belongs to which stage: a parameter whose column of the parameter
//! Jacobian touches a body's velocity row is mechanical (stage 1), one that touches a gas
//! row is a gas parameter (stage 2). Walls with a heat capacity are integrated by the gas
//! stage, so a parameter that enters only wall rows (a matrix's or a heater head's inverse
//! capacity, inert at its null) is a gas parameter too.

use stirling_dsl::{Model, StateKind};

use super::FitError;

/// Split the free parameters by the rows they enter: body rows -> stage 1, gas rows -> stage 2.
pub fn classify(
    model: &dyn Model,
    p: &[f64],
    names: &[String],
) -> Result<(Vec<usize>, Vec<usize>), FitError> {
    let n = model.n_states();
    let mut x = vec![0.0; n];
    model.equilibrium_guess(p, &mut x);
    for (i, s) in model.states().iter().enumerate() {
        match s.kind {
            StateKind::Position(k) => x[i] = 1e-3 * (1.0 + k as f64),
            StateKind::Velocity(k) => x[i] = 0.1 * (1.0 + 0.5 * k as f64),
            StateKind::Pressure(k) => x[i] *= 1.0 + 0.01 * (1.0 + k as f64),
            StateKind::Mass(_) | StateKind::WallTemperature(_) => {}
        }
    }
    let jp = model.param_jacobian_dense(p, &x, 0.0);
    let st = model.states();
    let (mut mech, mut gas) = (Vec::new(), Vec::new());
    for name in names {
        let j = model
            .param_index(name)
            .ok_or_else(|| FitError::UnknownParameter {
                name: name.clone(),
                model: model.name().into(),
            })?;
        let col = &jp[j * n..(j + 1) * n];
        let body = st
            .iter()
            .zip(col)
            .any(|(s, v)| matches!(s.kind, StateKind::Velocity(_)) && *v != 0.0);
        let g = st.iter().zip(col).any(|(s, v)| {
            matches!(
                s.kind,
                StateKind::Pressure(_) | StateKind::Mass(_) | StateKind::WallTemperature(_)
            ) && *v != 0.0
        });
        if !body && !g {
            return Err(FitError::NotInEquations {
                name: name.clone(),
                model: model.name().into(),
            });
        }
        if body {
            mech.push(j);
        }
        if g {
            gas.push(j);
        }
    }
    Ok((mech, gas))
}

/// The seed's free parameters, for a model that declares none (`free a, b;`).
const SEED_FREE: [&str; 7] = ["kd", "kp", "bd", "bp", "hh", "hk", "Rf"];

/// Default free parameters: those the model declares free (`free a, b;`), else the seed's
/// names it has; either way only those that enter its equations.
pub fn default_free(model: &dyn Model, p: &[f64]) -> Vec<String> {
    let declared = model.declared_free();
    let names: &[&str] = if declared.is_empty() {
        &SEED_FREE
    } else {
        declared
    };
    names
        .iter()
        .map(|s| s.to_string())
        .filter(|s| classify(model, p, std::slice::from_ref(s)).is_ok())
        .collect()
}
