//! Value parsers for the numeric options: each refuses a value outside its range with a
//! message clap prefixes with the option and the value (`invalid value '-1' for '--n <N>'`).
//! Options that may receive a negative number are declared `allow_negative_numbers`, so that
//! the range check, not clap's "unexpected argument", answers.

/// The largest `--samples`.
pub const MAX_SAMPLES: usize = 1_000_000;

/// Why a numeric option's value was refused (clap prefixes the option and the value).
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum RangeError {
    #[error("`{0}` is not a number")]
    NotANumber(String),
    #[error("`{0}` is not a finite number")]
    NotFinite(String),
    #[error("`{0}` is not a whole number")]
    NotWhole(String),
    /// The value is a number outside the option's range: what the range is.
    #[error("{0}")]
    Outside(&'static str),
    #[error("must lie between 2 and {MAX_SAMPLES} (a record needs two samples; more than 1e6 is not a plot or a CSV one can use)")]
    Samples,
}

type Parsed<T> = Result<T, RangeError>;

fn number(s: &str) -> Parsed<f64> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| RangeError::NotANumber(s.into()))?;
    if !v.is_finite() {
        return Err(RangeError::NotFinite(s.into()));
    }
    Ok(v)
}

/// An integer, also written as `1e5`.
fn integer(s: &str) -> Parsed<f64> {
    let v = number(s)?;
    if v.fract() != 0.0 {
        return Err(RangeError::NotWhole(s.into()));
    }
    Ok(v)
}

/// Any finite number.
pub fn finite(s: &str) -> Parsed<f64> {
    number(s)
}

/// A finite number > 0.
pub fn positive(s: &str) -> Parsed<f64> {
    let v = number(s)?;
    if v <= 0.0 {
        return Err(RangeError::Outside("must be a finite number > 0"));
    }
    Ok(v)
}

/// A finite number >= 0.
pub fn non_negative(s: &str) -> Parsed<f64> {
    let v = number(s)?;
    if v < 0.0 {
        return Err(RangeError::Outside("must be a finite number >= 0"));
    }
    Ok(v)
}

/// The smallest solver tolerance: 100 times the resolution of a double (the tolerances are
/// scaled by each state's size); below it no step meets the tolerance and the solver's step
/// collapses, which would read as a fault of the model.
pub const MIN_TOLERANCE: f64 = 1e-14;

/// A solver tolerance in [MIN_TOLERANCE, 0.1].
pub fn tolerance(s: &str) -> Parsed<f64> {
    let why = "a tolerance must lie in [1e-14, 0.1], e.g. 1e-7 (below 1e-14, about 100 times the \
               resolution of a double, no solver step can meet it)";
    let v = above_zero_to(s, 0.1, why)?;
    if v < MIN_TOLERANCE {
        return Err(RangeError::Outside(why));
    }
    Ok(v)
}

/// A finite number in `(0, hi]`; `why` otherwise.
fn above_zero_to(s: &str, hi: f64, why: &'static str) -> Parsed<f64> {
    let v = number(s)?;
    if !(v > 0.0 && v <= hi) {
        return Err(RangeError::Outside(why));
    }
    Ok(v)
}

/// A count >= 1 (sections, steps).
pub fn at_least_one(s: &str) -> Parsed<usize> {
    let v = integer(s)?;
    if v < 1.0 {
        return Err(RangeError::Outside("must be at least 1"));
    }
    if v > 1e9 {
        return Err(RangeError::Outside("is too large"));
    }
    Ok(v as usize)
}

/// A noise seed: a whole number from 0 to 2^64 - 1 (a negative one is refused by this range,
/// not taken for an option).
pub fn seed(s: &str) -> Parsed<u64> {
    if let Ok(v) = s.trim().parse::<u64>() {
        return Ok(v);
    }
    let v = integer(s)?;
    if v < 0.0 {
        return Err(RangeError::Outside(
            "a seed is a whole number from 0 to 2^64 - 1, e.g. --seed 1",
        ));
    }
    if v >= 1.8446744073709552e19 {
        return Err(RangeError::Outside(
            "is too large (a seed is at most 2^64 - 1)",
        ));
    }
    Ok(v as u64)
}

/// A number of output samples in [2, MAX_SAMPLES].
pub fn samples(s: &str) -> Parsed<usize> {
    let v = integer(s)?;
    if !(2.0..=MAX_SAMPLES as f64).contains(&v) {
        return Err(RangeError::Samples);
    }
    Ok(v as usize)
}

/// A number of cycles >= 1 (multiple-shooting segments).
pub fn cycles(s: &str) -> Parsed<f64> {
    let v = number(s)?;
    if v < 1.0 {
        return Err(RangeError::Outside("must be at least 1 cycle per segment"));
    }
    Ok(v)
}

/// A restart interval in cycles: positive, at most 1000 (beyond that a record has no
/// second segment and the option would do nothing).
pub fn restart_cycles(s: &str) -> Parsed<f64> {
    above_zero_to(s, 1000.0, "must be above 0 and at most 1000 cycles")
}

/// A pair of counts `TUNE:EVAL` (whole numbers >= 0), as `--seeds 1:1`.
pub fn split_counts(s: &str) -> Parsed<(usize, usize)> {
    let (a, b) = s.split_once(':').ok_or(RangeError::Outside(
        "expected TUNE:EVAL, two whole numbers such as 1:1",
    ))?;
    let count = |v: &str| -> Parsed<usize> {
        let x = integer(v)?;
        if !(0.0..=1e6).contains(&x) {
            return Err(RangeError::Outside("each count must lie between 0 and 1e6"));
        }
        Ok(x as usize)
    };
    Ok((count(a)?, count(b)?))
}

/// A channel's noise level `NAME=SD` (SD a finite number >= 0), as `--noise emf=0.01`.
pub fn channel_noise(s: &str) -> Parsed<(String, f64)> {
    let (name, v) = s.split_once('=').ok_or(RangeError::Outside(
        "expected CHANNEL=SD, such as emf=0.01 (the standard deviation in the channel's unit)",
    ))?;
    let name = name.trim();
    if name.is_empty() {
        return Err(RangeError::Outside(
            "the channel's name is empty: expected CHANNEL=SD",
        ));
    }
    let v = number(v)?;
    if v < 0.0 {
        return Err(RangeError::Outside("the noise level must be >= 0"));
    }
    Ok((name.to_string(), v))
}

/// A state's starting value `NAME=VALUE` (VALUE a finite number), as `--start omega=18`.
pub fn state_value(s: &str) -> Parsed<(String, f64)> {
    let (name, v) = s.split_once('=').ok_or(RangeError::Outside(
        "expected STATE=VALUE, such as omega=18 (the state's name as `stirling info` lists it)",
    ))?;
    let name = name.trim();
    if name.is_empty() {
        return Err(RangeError::Outside(
            "the state's name is empty: expected STATE=VALUE",
        ));
    }
    Ok((name.to_string(), number(v)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges() {
        assert_eq!(tolerance("1e-7"), Ok(1e-7));
        assert!(tolerance("0").is_err() && tolerance("1").is_err() && tolerance("-1").is_err());
        assert!(tolerance("nan").is_err());
        assert!(tolerance("1e-30").is_err() && tolerance("1e-14").is_ok());
        assert_eq!(samples("1e5"), Ok(100_000));
        assert!(samples("1e8").is_err() && samples("1").is_err() && samples("2.5").is_err());
        assert_eq!(at_least_one("3"), Ok(3));
        assert!(at_least_one("0").is_err() && at_least_one("-1").is_err());
        assert!(positive("-1").is_err() && positive("inf").is_err());
        assert_eq!(channel_noise("emf=0.01"), Ok(("emf".into(), 0.01)));
        for bad in ["emf", "=1", "emf=-1", "emf=x", "emf=inf"] {
            assert!(channel_noise(bad).is_err(), "{bad}");
        }
        assert!(cycles("0.5").is_err() && cycles("2").is_ok());
    }
}
