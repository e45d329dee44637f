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

/// Static shift of the body positions per unit pressure offset on the cold and hot channels:
/// `dq = -J_aq^-1 J_aP off` (rows: the velocity equations; columns: positions, pressures).
pub fn static_shift(
    model: &dyn Model,
    p: &[f64],
    have_hot: bool,
) -> Result<[Vec<f64>; 2], FitError> {
    let n = model.n_states();
    let mut eq = vec![0.0; n];
    model.equilibrium_guess(p, &mut eq);
    let j = model.jacobian_dense(p, &eq, 0.0);
    let layout = crate::layout::StateLayout::of(model);
    let (pos, vel, ps) = (&layout.positions, &layout.velocities, &layout.pressures);
    let jaq = DMatrix::from_fn(vel.len(), pos.len(), |r, c| j[vel[r] + n * pos[c]]);
    let lu = jaq.lu();
    let mut out = [Vec::new(), Vec::new()];
    for (ch, o) in out.iter_mut().enumerate() {
        let rhs = DVector::from_fn(vel.len(), |r, _| {
            ps.iter()
                .enumerate()
                .map(|(i, &pi)| {
                    let wc = cold_weight(i, ps.len(), have_hot);
                    j[vel[r] + n * pi] * if ch == 0 { wc } else { 1.0 - wc }
                })
                .sum::<f64>()
        });
        let dq = lu.solve(&(-rhs)).ok_or(FitError::SingularStatics)?;
        *o = dq.iter().copied().collect();
    }
    Ok(out)
}
