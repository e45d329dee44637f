//! Axis conventions shared by every figure: each axis label carries its unit in brackets
//! (`name [unit]`, `[-]` for a ratio), logarithmic axes are labelled by powers of ten.

/// `name [unit]`.
pub fn label(name: &str, unit: &str) -> String {
    format!("{name} [{unit}]")
}

/// The unit of a measured channel by its name (`p*`: pressure, `x`, `y`: displacement).
pub fn channel_unit(channel: &str) -> &'static str {
    match channel {
        "x" | "y" => "m",
        c if c.starts_with('p') || c.starts_with('P') => "Pa",
        _ => "-",
    }
}

/// A measured channel as an axis label, e.g. `p [Pa]`.
pub fn channel_label(channel: &str) -> String {
    label(channel, channel_unit(channel))
}

/// A tick label on a logarithmic axis: `10²`, `10⁻¹` at powers of ten, nothing between.
pub fn pow10(v: &f64) -> String {
    let e = v.log10();
    if !e.is_finite() || (e - e.round()).abs() > 1e-6 {
        return String::new();
    }
    const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let k = e.round() as i64;
    let mut s = String::from("10");
    if k < 0 {
        s.push('⁻');
    }
    for d in k.unsigned_abs().to_string().bytes() {
        s.push(SUP[(d - b'0') as usize]);
    }
    s
}

/// `(lo, hi)` widened to whole decades.
pub fn decades(lo: f64, hi: f64) -> (f64, f64) {
    (
        10f64.powf(lo.log10().floor()),
        10f64.powf(hi.log10().ceil()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn powers_of_ten() {
        assert_eq!(pow10(&100.0), "10²");
        assert_eq!(pow10(&0.1), "10⁻¹");
        assert_eq!(pow10(&1.0), "10⁰");
        assert_eq!(pow10(&1e12), "10¹²");
        assert_eq!(pow10(&20.0), "");
        assert_eq!(decades(6.3, 941.0), (1.0, 1000.0));
        assert_eq!(channel_label("p_hot"), "p_hot [Pa]");
    }
}
