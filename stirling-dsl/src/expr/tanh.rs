//! `tanh` for the generated code, without a call into libm on the usual path.
//!
//! Why not `f64::tanh`: every link of a model smooths its upwind switch with a `tanh`, and a
//! call into libm makes the caller spill every live `xmm` register around it (they are all
//! caller-saved in the System V ABI) and keeps the processor from overlapping one section of
//! the loop with the next. Here the saturated case (`|x| >= 22`, where `tanh` rounds to `+-1`:
//! everywhere but near a flow reversal) is one compare and branch inlined into the caller; the
//! rest (about 35 floating-point operations and one division) is out of line and cold. One
//! branch, not two: with the NaN test inline too, the family's release build took three times
//! as long (docs/performance.md).
//!
//! The method: with `a = |x| < 22`, `e = expm1(-2 a)` lies in `(-1, 0]` and `tanh(a) = -e /
//! (e + 2)`, accurate in relative terms for every `a`. `y = -2 a` is reduced to `y = k ln 2 +
//! r`, `|r| <= ln 2 / 2`, so that with `s = 2^k` and `p = expm1(r)` (its Taylor series to
//! degree 13, remainder below 1e-17 relative), `e = s p + (s - 1)` and `tanh(a) = ((1 - s) - s
//! p) / ((1 + s) + s p)`, where `s p`, `1 - s` and `1 + s` are exact and neither sum cancels.
//! Accuracy: within 2 units in the last place of the exact value on 40 000 sampled points in
//! `[1e-10, 20]` (checked against 50-digit decimals; glibc's `tanh` is also off by up to 2
//! there), hence within 3 of libm's (test `tanh_matches_libm`).

#[allow(clippy::excessive_precision)] // the digits of fdlibm's split of ln 2, as published
const LN2_HI: f64 = 6.931_471_803_691_238_164_90e-1; // ln 2 with 32 trailing zero bits
#[allow(clippy::excessive_precision)]
const LN2_LO: f64 = 1.908_214_929_270_587_700_02e-10; // ln 2 - LN2_HI
const INV_LN2: f64 = std::f64::consts::LOG2_E;
/// `1.5 * 2^52`: adding and subtracting it rounds a double of magnitude below `2^51` to an
/// integer (round to nearest even), without `roundsd` (not in the x86-64 baseline).
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// `tanh(x)`, within 3 ulp of libm's; `tanh(-0) = -0`, `tanh(+-inf) = +-1`, `tanh(NaN)` is NaN.
#[inline(always)]
pub fn tanh(x: f64) -> f64 {
    let a = x.abs();
    if a >= 22.0 {
        // saturated: the usual case away from a flow reversal
        1.0f64.copysign(x)
    } else {
        unsaturated(x, a) // and NaN
    }
}

/// `tanh(x)` for `|x| = a < 22` or NaN: out of line, so that the loop around a saturated `tanh`
/// keeps its values in registers.
#[cold]
#[inline(never)]
fn unsaturated(x: f64, a: f64) -> f64 {
    if a.is_nan() {
        return x;
    }
    // e = expm1(y) = s p + (s - 1), so -e = (1 - s) - s p and e + 2 = (1 + s) + s p, where
    // `s p`, `1 - s` and `1 + s` are exact: one rounding each side, no cancellation
    let y = -2.0 * a;
    let kf = (y * INV_LN2 + ROUNDER) - ROUNDER;
    let r = (y - kf * LN2_HI) - kf * LN2_LO;
    let s = f64::from_bits(((kf as i64 + 1023) as u64) << 52); // 2^k, k in [-64, 0]
    let sp = s * expm1_small(r);
    (((1.0 - s) - sp) / ((1.0 + s) + sp)).copysign(x)
}

/// `expm1(r)` for `|r| <= ln 2 / 2`: `r + r^2 q(r)`, `q` the Taylor series of
/// `(e^r - 1 - r) / r^2` to degree 11, in Estrin's scheme (a short dependency chain).
#[inline(always)]
fn expm1_small(r: f64) -> f64 {
    const C: [f64; 12] = [
        1.0 / 2.0,
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 120.0,
        1.0 / 720.0,
        1.0 / 5040.0,
        1.0 / 40320.0,
        1.0 / 362880.0,
        1.0 / 3628800.0,
        1.0 / 39916800.0,
        1.0 / 479001600.0,
        1.0 / 6227020800.0,
    ];
    let r2 = r * r;
    let r4 = r2 * r2;
    let r8 = r4 * r4;
    let p01 = C[0] + C[1] * r;
    let p23 = C[2] + C[3] * r;
    let p45 = C[4] + C[5] * r;
    let p67 = C[6] + C[7] * r;
    let p89 = C[8] + C[9] * r;
    let p1011 = C[10] + C[11] * r;
    let lo = (p01 + p23 * r2) + (p45 + p67 * r2) * r4;
    let hi = (p89 + p1011 * r2) * r8;
    r + r2 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::tanh;

    /// Distance in units in the last place between two finite doubles of the same sign.
    fn ulps(a: f64, b: f64) -> u64 {
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
    }

    #[test]
    fn tanh_matches_libm() {
        // a dense log grid from 1e-300 to 30 and a uniform one over the interesting range
        let mut xs: Vec<f64> = (0..200_000)
            .map(|i| 10f64.powf(-300.0 + 301.5 * i as f64 / 200_000.0))
            .collect();
        xs.extend((0..200_000).map(|i| 25.0 * i as f64 / 200_000.0));
        let mut worst = (0u64, 0.0);
        for &x in &xs {
            for x in [x, -x] {
                let (ours, libm) = (tanh(x), x.tanh());
                let d = ulps(ours, libm);
                if d > worst.0 {
                    worst = (d, x);
                }
            }
        }
        assert!(worst.0 <= 3, "{} ulp at x = {:e}", worst.0, worst.1);
    }

    #[test]
    fn tanh_special_values() {
        assert_eq!(tanh(0.0).to_bits(), 0.0f64.to_bits());
        assert_eq!(tanh(-0.0).to_bits(), (-0.0f64).to_bits());
        assert_eq!(tanh(f64::INFINITY), 1.0);
        assert_eq!(tanh(f64::NEG_INFINITY), -1.0);
        assert_eq!(tanh(1e300), 1.0);
        assert!(tanh(f64::NAN).is_nan());
        let tiny = f64::from_bits(1); // the smallest subnormal
        assert_eq!(tanh(tiny), tiny);
        assert_eq!(tanh(-tiny), -tiny);
    }

    #[test]
    fn tanh_is_odd_and_monotone() {
        let mut last = -1.0;
        for i in -20_000..=20_000 {
            let x = i as f64 * 1e-3;
            let t = tanh(x);
            assert_eq!(t.to_bits(), (-tanh(-x)).to_bits(), "odd at {x}");
            assert!(t >= last, "not monotone at {x}: {t} < {last}");
            last = t;
        }
    }
}
