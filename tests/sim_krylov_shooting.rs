//! The Newton-Krylov shooting route against the dense one: directional monodromy
//! products against the dense monodromy and against finite differences of the flow, and
//! at nsection n = 10 the same limit cycle and the same leading Floquet multipliers.

use stirling::dsl::{Closure, Model};
use stirling::models::family::NSection;
use stirling::models::sim::{
    self, flow_with_monodromy, shoot, shoot_krylov, tangent::flow_with_tangent, KrylovOptions,
    ShootingOptions, SimOptions,
};

/// The settled cycle of the default engine at `n` (start: displacer at 5 mm).
fn settled(model: &dyn Model, p: &[f64]) -> sim::Settled {
    let mut x0 = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x0);
    x0[0] = 5e-3;
    sim::settle(
        model,
        p,
        &x0,
        20.0,
        &[],
        3,
        1e-3,
        &SimOptions::default(),
        None,
    )
    .unwrap()
}

fn max_abs(v: impl Iterator<Item = f64>) -> f64 {
    v.fold(0.0, |a, b| a.max(b.abs()))
}

/// `D^-1 Phi D v` by the tangent flow equals the dense monodromy's product to round-off
/// and the central difference of the flow to its truncation and tolerance noise.
#[test]
fn tangent_products_match_dense_monodromy_and_finite_differences() {
    let model = NSection::new(3, Closure::Full).unwrap();
    let p = model.default_params();
    let st = settled(&model, &p);
    let n = model.n_states();
    let opts = ShootingOptions::default().sim;
    let s = sim::state_scale(&model, &p);
    let (_, mono, _) = flow_with_monodromy(&model, &p, &st.x0, st.period, &opts).unwrap();
    let (_, mut tf, _) =
        flow_with_tangent(&model, &p, &st.x0, st.period, &opts, 1, 1 << 30).unwrap();
    let v: Vec<f64> = (0..n)
        .map(|i| ((i * 7 + 3) % 11) as f64 / 11.0 - 0.5)
        .collect();
    let mut w = v.clone();
    tf.apply(&mut w).unwrap();
    // twice: the second product runs on the cached factors
    let mut w2 = v.clone();
    tf.apply(&mut w2).unwrap();
    let dense: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| mono[i + j * n] * s[j] * v[j]).sum::<f64>() / s[i])
        .collect();
    let wn = max_abs(w.iter().copied());
    let e_dense = max_abs(w.iter().zip(&dense).map(|(a, b)| a - b)) / wn;
    let e_cache = max_abs(w.iter().zip(&w2).map(|(a, b)| a - b)) / wn;
    // central differences of the flow, integrated at 1e-12: noise ~ rtol / eps,
    // truncation ~ eps^2; the better of two steps
    let fd_opts = SimOptions {
        rtol: 1e-12,
        atol: 1e-12,
        ..opts
    };
    let fd_error = |eps: f64| -> f64 {
        let shifted = |sign: f64| -> Vec<f64> {
            let x: Vec<f64> = (0..n)
                .map(|j| st.x0[j] + sign * eps * s[j] * v[j])
                .collect();
            sim::simulate(&model, &p, &x, st.period, &[st.period], &fd_opts)
                .unwrap()
                .x_end
        };
        let (xp, xm) = (shifted(1.0), shifted(-1.0));
        let fd: Vec<f64> = (0..n)
            .map(|i| (xp[i] - xm[i]) / (2.0 * eps * s[i]))
            .collect();
        max_abs(w.iter().zip(&fd).map(|(a, b)| a - b)) / wn
    };
    let (e3, e4) = (fd_error(1e-3), fd_error(1e-4));
    let e_fd = e3.min(e4);
    eprintln!("|Phi v| {wn:.3e}: vs dense {e_dense:.2e}, cached {e_cache:.2e}, vs FD {e3:.2e} (eps 1e-3), {e4:.2e} (eps 1e-4)");
    assert!(e_dense < 1e-10, "tangent vs dense monodromy: {e_dense:e}");
    assert!(e_cache < 1e-12, "cached factors: {e_cache:e}");
    assert!(e_fd < 1e-5, "tangent vs finite differences: {e_fd:e}");
}

/// n = 10 (28 states): both routes from the same settled cycle converge to the same cycle,
/// and the leading multipliers agree.
#[test]
fn krylov_route_equals_dense_route_at_n10() {
    let model = NSection::new(10, Closure::Full).unwrap();
    let p = model.default_params();
    let st = settled(&model, &p);
    let opts = ShootingOptions::default();
    let d = shoot(&model, &p, &st.x0, st.period, &opts).unwrap();
    let k = shoot_krylov(
        &model,
        &p,
        &st.x0,
        st.period,
        &opts,
        &KrylovOptions::default(),
    )
    .unwrap();
    let s = sim::state_scale(&model, &p);
    let dx = max_abs(
        d.x0.iter()
            .zip(&k.x0)
            .zip(&s)
            .map(|((a, b), w)| (a - b) / w),
    );
    let dt = (d.period - k.period).abs() / d.period;
    eprintln!(
        "dense: {} iterations, residual {:.2e}; krylov: {} iterations, residual {:.2e}",
        d.iterations, d.residual, k.iterations, k.residual
    );
    eprintln!("period difference {dt:.2e}, scaled x0 difference {dx:.2e}");
    eprintln!("dense  {:?}", &d.floquet[..k.floquet.len()]);
    eprintln!("krylov {:?}", k.floquet);
    assert!(dt < 1e-9, "period: {dt:e}");
    assert!(dx < 1e-7, "x0: {dx:e}");
    // the trivial pair: within the Jordan-block splitting of either eigen-solver
    assert!(k.trivial_multiplier_error() < 1e-6);
    assert!(k.floquet.len() >= 6);
    let mut worst = 0.0f64;
    for &(re, im) in &k.floquet {
        let m = re.hypot(im);
        if m < 1e-6 {
            continue; // the cloud near 0: relative accuracy not meaningful
        }
        let near = d
            .floquet
            .iter()
            .map(|&(a, b)| (a - re).hypot(b - im))
            .fold(f64::MAX, f64::min);
        worst = worst.max(near / m);
    }
    eprintln!("worst relative multiplier difference {worst:.2e}");
    assert!(worst < 1e-6, "leading multipliers differ by {worst:e}");
}
