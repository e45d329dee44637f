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

/// A measured channel as an axis label, e.g. `p \[Pa\]`.
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

/// Tick labels for a linear axis spanning `span`: as many decimals as its ticks (about ten
/// to the span) need, and never `-0`.
pub fn linear_ticks(span: f64) -> impl Fn(&f64) -> String {
    let step = (span / 10.0).abs().max(1e-300);
    let decimals = (-step.log10().floor()).clamp(0.0, 9.0) as usize;
    move |v: &f64| {
        let s = format!("{v:.decimals$}");
        if s.trim_start_matches('-')
            .chars()
            .all(|c| c == '0' || c == '.')
        {
            s.trim_start_matches('-').to_string()
        } else {
            s
        }
    }
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
    }

    #[test]
    fn linear_ticks_have_the_decimals_of_their_step_and_no_negative_zero() {
        let f = linear_ticks(0.2);
        assert_eq!(f(&-0.0), "0.00");
        assert_eq!(f(&-1e-17), "0.00");
        assert_eq!(f(&0.05), "0.05");
        assert_eq!(f(&-0.1), "-0.10");
        assert_eq!(linear_ticks(2000.0)(&-500.0), "-500");
        assert_eq!(channel_label("p_hot"), "p_hot [Pa]");
    }
}
