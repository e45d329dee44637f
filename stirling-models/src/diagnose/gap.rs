//! The nominal model's held-out gap per channel, with the calibrated parameters and how far
//! they moved from their starts.

use super::context::{Context, Eval};
use super::types::{ChannelError, GapBefore, ParamShift};
use crate::fit;
use crate::fit::FittedStage;

/// The nominal model's held-out gap per channel, with the calibrated parameters.
pub(super) fn gap_before(ctx: &Context, nominal: &Eval, stages: &[FittedStage]) -> GapBefore {
    let channels = channel_errors(ctx, nominal);
    let fitted: Vec<(&fit::vars::Var, f64)> = stages
        .iter()
        .flat_map(|st| st.stage.vars.iter())
        .filter_map(|v| match v.kind {
            fit::vars::VarKind::Param(i) => Some((v, ctx.p_nom[i])),
            _ => None,
        })
        .collect();
    let params = fitted.iter().map(|(v, x)| (v.name.clone(), *x)).collect();
    let shifts = fitted
        .iter()
        .filter(|(v, _)| v.initial != 0.0)
        .map(|(v, x)| {
            let factor = x / v.initial;
            ParamShift {
                name: v.name.clone(),
                start: v.initial,
                calibrated: *x,
                factor,
                prior_sd: v.prior.filter(|_| factor > 0.0).map(|s| factor.ln() / s),
            }
        })
        .collect();
    GapBefore {
        shifts,
        channels,
        holdout_error: nominal.holdout_error,
        train_error: nominal.train_error,
        params,
    }
}

/// The held-out error of an evaluation per channel.
pub(super) fn channel_errors(ctx: &Context, ev: &Eval) -> Vec<ChannelError> {
    let (a, b) = ctx.hold_idx;
    ev.channels
        .iter()
        .zip(&ev.hp)
        .map(|(c, r)| {
            let rms = (r[a..b].iter().map(|v| v * v).sum::<f64>() / (b - a) as f64).sqrt();
            let s = ctx.noise_of(c);
            ChannelError {
                channel: c.clone(),
                rms,
                noise: s,
                ratio: rms / s,
            }
        })
        .collect()
}
