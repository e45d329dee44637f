//! Moving array expressions between frames.
//!
//! An array CV's quantities are built once in its own frame: its states at
//! `At::Rel(0)` and the section index as `Sym::Index` (the template). A
//! neighbour's quantity is the template shifted by `k` (`Rel(r) -> Rel(r + k)`,
//! `j -> j + k`); a scalar row sees an array end pinned to `First` or `Last`
//! (`j -> 0` or `j -> n - 1`). Named quantities are renamed with the frame, so
//! `T_regen[j]` becomes `T_regen[j+1]` or `T_regen[0]`.

use crate::expr::{Arena, At, Id, Sym};

/// Where a template is placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    /// Unchanged (scalar quantities, or the own section).
    Own,
    /// Shifted by `k` sections.
    Shift(i32),
    /// Pinned to section 0.
    First,
    /// Pinned to section `n - 1`.
    Last,
}

/// Move `id` to `place`; `array_blocks` tells which state blocks are arrays.
pub fn place(arena: &mut Arena, id: Id, at: Place, array_blocks: &[bool]) -> Id {
    if at == Place::Own || at == Place::Shift(0) {
        return id;
    }
    let index = match at {
        Place::Shift(k) => {
            let (j, k) = (arena.sym(Sym::Index), arena.num(k as f64));
            arena.add(j, k)
        }
        Place::First => arena.num(0.0),
        _ => {
            let (n, one) = (arena.sym(Sym::Count), arena.num(1.0));
            arena.sub(n, one)
        }
    };
    let mut map = |a: &mut Arena, s: Sym| match s {
        Sym::Index => Some(index),
        Sym::State(b, At::Rel(r)) if array_blocks.get(b as usize) == Some(&true) => {
            Some(a.sym(Sym::State(b, moved(r, at))))
        }
        _ => None,
    };
    arena.subst_renaming(id, &mut map, &|name| rename(name, at))
}

fn moved(r: i32, at: Place) -> At {
    match at {
        Place::Shift(k) => At::Rel(r + k),
        Place::First if r == 0 => At::First,
        Place::Last if r == 0 => At::Last,
        // a template only holds its own section; other offsets cannot be pinned
        _ => At::Rel(r),
    }
}

/// `T_regen[j]` -> `T_regen[j+1]` (shift 1), `T_regen[0]` (first), `T_regen[n-1]` (last).
pub fn rename(name: &str, at: Place) -> String {
    let Some(open) = name.find("[j") else {
        return name.to_string();
    };
    let Some(close) = name[open..].find(']').map(|c| c + open) else {
        return name.to_string();
    };
    let r: i32 = name[open + 2..close].parse().unwrap_or(0);
    let inner = match at {
        Place::Own => return name.to_string(),
        Place::Shift(k) => index_text(r + k),
        Place::First => "0".to_string(),
        Place::Last => "n-1".to_string(),
    };
    format!("{}[{inner}]{}", &name[..open], &name[close + 1..])
}

/// `j`, `j+1`, `j-1`.
pub fn index_text(r: i32) -> String {
    match r {
        0 => "j".to_string(),
        r if r > 0 => format!("j+{r}"),
        r => format!("j{r}"),
    }
}
