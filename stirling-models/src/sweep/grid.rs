//! The points of a sweep: axes (a range or a list of values per parameter), their
//! Cartesian product in a fixed order, ties that move one parameter with another, and the
//! slice of the points one shard runs.

use serde::{Deserialize, Serialize};

use super::SweepError;

/// One swept parameter and its values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    pub name: String,
    pub values: Vec<f64>,
}

impl Axis {
    /// `NAME=a:b:k` (k values from a to b, ends included) or `NAME=v1,v2,...`.
    pub fn parse(s: &str) -> Result<Axis, SweepError> {
        let bad = |why: &str| SweepError::Axis {
            given: s.into(),
            why: why.into(),
        };
        let (name, spec) = s
            .split_once('=')
            .ok_or_else(|| bad("expected NAME=a:b:k or NAME=v1,v2,..."))?;
        let num = |v: &str| {
            v.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(&format!("`{v}` is not a finite number")))
        };
        let values = if spec.contains(':') {
            let parts: Vec<&str> = spec.split(':').collect();
            let [a, b, k] = parts[..] else {
                return Err(bad("a range is a:b:k (from a to b in k values)"));
            };
            let k: usize = k
                .trim()
                .parse()
                .ok()
                .filter(|&k| k >= 1)
                .ok_or_else(|| bad("the count k of a:b:k must be a whole number >= 1"))?;
            if k > super::MAX_POINTS {
                // the axis's values are held in memory before anything runs
                return Err(bad(&format!(
                    "{k} values on one axis, more than the {} a sweep holds (8 bytes each, \
                     before any point runs): use fewer values, or sweep the range in parts",
                    super::MAX_POINTS
                )));
            }
            let (a, b) = (num(a)?, num(b)?);
            let step = if k > 1 { (b - a) / (k - 1) as f64 } else { 0.0 };
            (0..k).map(|i| a + step * i as f64).collect()
        } else {
            spec.split(',').map(num).collect::<Result<Vec<f64>, _>>()?
        };
        Ok(Axis {
            name: name.trim().into(),
            values,
        })
    }
}

/// `follower = leader`: the follower keeps its ratio to the leader (`--tie Pb=Pmean`: the
/// bounce pressure moves with the charge pressure).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tie {
    pub follower: String,
    pub leader: String,
}

impl Tie {
    /// `FOLLOWER=LEADER`.
    pub fn parse(s: &str) -> Result<Tie, SweepError> {
        let (f, l) = s.split_once('=').ok_or_else(|| SweepError::Tie {
            given: s.into(),
            why: "expected FOLLOWER=LEADER, e.g. Pb=Pmean".into(),
        })?;
        Ok(Tie {
            follower: f.trim().into(),
            leader: l.trim().into(),
        })
    }
}

/// The ties a sweep applies unless told otherwise: the bounce pressure follows the charge
/// pressure (a charge pressure swept alone would load the piston with the difference).
pub fn default_ties(axes: &[Axis], has: impl Fn(&str) -> bool) -> Vec<Tie> {
    let swept = |n: &str| axes.iter().any(|a| a.name == n);
    [("Pb", "Pmean")]
        .iter()
        .filter(|(f, l)| swept(l) && !swept(f) && has(f) && has(l))
        .map(|(f, l)| Tie {
            follower: f.to_string(),
            leader: l.to_string(),
        })
        .collect()
}

/// The number of points of the product of `axes`.
pub fn count(axes: &[Axis]) -> usize {
    // saturating: a product past usize is refused as too large, not wrapped around
    axes.iter()
        .fold(1usize, |n, a| n.saturating_mul(a.values.len()))
}

/// Point `k` of the product (the last axis varies fastest).
pub fn point(axes: &[Axis], mut k: usize) -> Vec<f64> {
    let mut v = vec![0.0; axes.len()];
    for (i, a) in axes.iter().enumerate().rev() {
        let n = a.values.len();
        v[i] = a.values[k % n];
        k /= n;
    }
    v
}

/// The point indices shard `i` of `n` runs (`i` from 1): every `n`-th point, so that each
/// shard gets points from the whole grid (their cost varies over it).
pub fn shard(total: usize, i: usize, n: usize) -> Vec<usize> {
    (i - 1..total).step_by(n).collect()
}

/// `i/N` with `1 <= i <= N`.
pub fn parse_shard(s: &str) -> Result<(usize, usize), SweepError> {
    let bad = || SweepError::Shard { given: s.into() };
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n): (usize, usize) = (
        i.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if i == 0 || i > n {
        return Err(bad());
    }
    Ok((i, n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_parse_ranges_and_lists_and_refuse_bad_input() {
        let a = Axis::parse("Th=600:800:3").unwrap();
        assert_eq!(a.values, vec![600.0, 700.0, 800.0]);
        assert_eq!(
            Axis::parse("Pmean=1e5, 2e5").unwrap().values,
            vec![1e5, 2e5]
        );
        for bad in ["Th", "Th=1:2", "Th=1:2:0", "Th=a,b", "Th=1:2:x", "Th=inf"] {
            assert!(Axis::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn points_cover_the_product_and_shards_partition_it() {
        let axes = vec![
            Axis::parse("a=1,2").unwrap(),
            Axis::parse("b=10,20,30").unwrap(),
        ];
        assert_eq!(count(&axes), 6);
        // one axis past the cap is refused before its values are made
        let e = Axis::parse("Th=500:700:1000000000")
            .unwrap_err()
            .to_string();
        assert!(e.contains("1000000000 values on one axis"), "{e}");
        assert_eq!(point(&axes, 0), vec![1.0, 10.0]);
        assert_eq!(point(&axes, 4), vec![2.0, 20.0]);
        let mut all: Vec<usize> = (1..=4).flat_map(|i| shard(6, i, 4)).collect();
        all.sort();
        assert_eq!(all, (0..6).collect::<Vec<_>>());
        assert_eq!(parse_shard("2/4").unwrap(), (2, 4));
        for bad in ["0/4", "5/4", "2", "a/b"] {
            assert!(parse_shard(bad).is_err(), "{bad}");
        }
    }
}
