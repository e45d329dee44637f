//! The static response of the bodies to a constant pressure offset, and how a CV's prescribed
//! pressure mixes the cold-side and hot-side channels.

use nalgebra::{DMatrix, DVector};
use stirling_dsl::Model;

use super::FitError;

/// Weight of the cold-side channel in the prescribed pressure of CV `i` of `ncv` (hot = 0).
pub fn cold_weight(i: usize, ncv: usize, have_hot: bool) -> f64 {
    if !have_hot || ncv < 2 {
        1.0
    } else {
        i as f64 / (ncv - 1) as f64
    }
}

/// Static shift of the body positions per unit pressure offset on each pressure channel:
/// `dq = -J_aq^-1 J_aP off` (rows: the velocity equations; columns: positions, pressures).
/// Channels: `[0]` the cold side, `[1]` the hot side (zero unless `have_hot`), then one per
/// CV outside the working gas ([`crate::layout::StateLayout::outside`] order).
pub fn static_shift(
    model: &dyn Model,
    p: &[f64],
    have_hot: bool,
) -> Result<Vec<Vec<f64>>, FitError> {
    let n = model.n_states();
    let mut eq = vec![0.0; n];
    model.equilibrium_guess(p, &mut eq);
    let j = model.jacobian_dense(p, &eq, 0.0);
    let layout = crate::layout::StateLayout::working_gas(model);
    let (pos, vel, ps) = (&layout.positions, &layout.velocities, &layout.pressures);
    let jaq = DMatrix::from_fn(vel.len(), pos.len(), |r, c| j[vel[r] + n * pos[c]]);
    let lu = jaq.lu();
    let weight = |ch: usize, i: usize| {
        let wc = cold_weight(i, ps.len(), have_hot);
        if ch == 0 {
            wc
        } else {
            1.0 - wc
        }
    };
    let mut out = Vec::new();
    for ch in 0..2 + layout.outside.len() {
        let rhs = DVector::from_fn(vel.len(), |r, _| match ch {
            0 | 1 => ps
                .iter()
                .enumerate()
                .map(|(i, &pi)| j[vel[r] + n * pi] * weight(ch, i))
                .sum::<f64>(),
            k => j[vel[r] + n * layout.outside[k - 2]],
        });
        let dq = lu.solve(&(-rhs)).ok_or(FitError::SingularStatics)?;
        out.push(dq.iter().copied().collect());
    }
    Ok(out)
}
