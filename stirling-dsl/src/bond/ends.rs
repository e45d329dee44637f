//! Link and conduction ends as `TopologyInfo` writes them (`hot`, `regen[0]`, `regen[j+1]`,
//! `regen[n-1]`), resolved to elements at a given `n`.

use super::error::BondError;

/// An end: a name and, for an array element, its index (`None` for a scalar).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct End<'a> {
    pub name: &'a str,
    pub index: Option<Index>,
}

/// An element index as written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Index {
    /// A fixed element (`0`, `n-1` resolved at `n`) given by its offset from the start
    /// (`from_end == false`) or from `n` (`from_end == true`, `n-1`: offset `-1`).
    Fixed { offset: i64, from_end: bool },
    /// The running section `j` plus an offset (`j`, `j+1`, `j-1`).
    Rel(i64),
}

/// Parses `name` or `name[index]`.
pub fn parse(text: &str) -> Result<End<'_>, BondError> {
    let Some((name, rest)) = text.split_once('[') else {
        return Ok(End {
            name: text.trim(),
            index: None,
        });
    };
    let bad = || BondError::End(text.to_string());
    let inner: String = rest
        .strip_suffix(']')
        .ok_or_else(bad)?
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect();
    let (head, offset) = split_offset(&inner).ok_or_else(bad)?;
    let index = match head {
        "j" => Index::Rel(offset),
        "n" => Index::Fixed {
            offset,
            from_end: true,
        },
        "" => Index::Fixed {
            offset,
            from_end: false,
        },
        _ => return Err(bad()),
    };
    Ok(End {
        name: name.trim(),
        index: Some(index),
    })
}

/// `j+1` -> `("j", 1)`, `n-1` -> `("n", -1)`, `3` -> `("", 3)`, `j` -> `("j", 0)`.
fn split_offset(s: &str) -> Option<(&str, i64)> {
    if let Ok(k) = s.parse::<i64>() {
        return Some(("", k));
    }
    let head_len = s.find(['+', '-']).unwrap_or(s.len());
    let (head, tail) = s.split_at(head_len);
    let offset = if tail.is_empty() {
        0
    } else {
        tail.trim_start_matches('+').parse().ok()?
    };
    Some((head, offset))
}

/// The element an end names at section `j` of `n`, or `None` when it falls outside `0..n`.
pub fn element(index: Option<Index>, j: usize, n: usize) -> Option<usize> {
    let k = match index {
        None => return Some(0),
        Some(Index::Rel(o)) => j as i64 + o,
        Some(Index::Fixed { offset, from_end }) => offset + if from_end { n as i64 } else { 0 },
    };
    (0..n as i64).contains(&k).then_some(k as usize)
}

/// The sections `j` a link or conduction between `a` and `b` repeats over at `n`: every `j`
/// with both ends inside the arrays when one end runs with `j`, else just one.
pub fn sections(a: &End, b: &End, n: usize) -> Vec<usize> {
    let runs = |e: &End| matches!(e.index, Some(Index::Rel(_)));
    if !runs(a) && !runs(b) {
        return vec![0];
    }
    let inside = |e: &End, j| e.index.is_none() || element(e.index, j, n).is_some();
    (0..n).filter(|&j| inside(a, j) && inside(b, j)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_parse_and_resolve() {
        let e = parse("regen[j + 1]").unwrap();
        assert_eq!(e.name, "regen");
        assert_eq!(element(e.index, 2, 4), Some(3));
        assert_eq!(element(e.index, 3, 4), None);
        let last = parse("r[n-1]").unwrap();
        assert_eq!(element(last.index, 0, 10), Some(9));
        assert_eq!(element(parse("r[0]").unwrap().index, 5, 10), Some(0));
        assert_eq!(parse("hot").unwrap().index, None);
        assert!(parse("r[k]").is_err());
        let (a, b) = (parse("r[j]").unwrap(), parse("r[j+1]").unwrap());
        assert_eq!(sections(&a, &b, 3), vec![0, 1]);
        assert_eq!(sections(&a, &b, 1), Vec::<usize>::new());
        assert_eq!(sections(&a, &parse("bounce").unwrap(), 2), vec![0, 1]);
    }
}
