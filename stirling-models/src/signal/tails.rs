//! Statistical tails: chi-square survival function and the complementary error function.

/// Upper tail of the chi-square distribution with `k` degrees of freedom (k = 1, 2; larger
/// `k` by the Wilson-Hilferty approximation).
pub fn chi2_sf(x: f64, k: usize) -> f64 {
    if !(x > 0.0) {
        return 1.0;
    }
    match k {
        1 => erfc((x / 2.0).sqrt()),
        2 => (-x / 2.0).exp(),
        _ => {
            let k = k as f64;
            let z = ((x / k).powf(1.0 / 3.0) - (1.0 - 2.0 / (9.0 * k))) / (2.0 / (9.0 * k)).sqrt();
            0.5 * erfc(z / std::f64::consts::SQRT_2)
        }
    }
}

/// Complementary error function (Numerical Recipes' Chebyshev fit, relative error < 1.2e-7).
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let ans = t
        * (-z * z - 1.26551223
            + t * (1.00002368
                + t * (0.37409196
                    + t * (0.09678418
                        + t * (-0.18628806
                            + t * (0.27886807
                                + t * (-1.13520398
                                    + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))))
            .exp();
    if x >= 0.0 {
        ans
    } else {
        2.0 - ans
    }
}
