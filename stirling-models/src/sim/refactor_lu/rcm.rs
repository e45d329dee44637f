//! Reverse Cuthill-McKee on the pattern of `A + A^T`: a banded order, which on a chain of
//! control volumes runs along the sections, each section's states side by side.
//!
//! Breadth-first from a pseudo-peripheral start (the far end of a search from a node of least
//! degree, repeated while the depth grows), the unvisited neighbours of each node taken by
//! increasing degree, the whole order reversed (George and Liu, *Computer Solution of Large
//! Sparse Positive Definite Systems*, 1981, ch. 4). Every connected component is ordered in
//! turn. Why our own: neither faer nor diffsol has it, and it is 60 lines.

use faer::sparse::SymbolicSparseColMatRef;

/// The symmetric adjacency of `sym` (diagonal dropped), as sorted, deduplicated lists.
fn adjacency(sym: SymbolicSparseColMatRef<'_, usize>) -> Vec<Vec<usize>> {
    let n = sym.ncols();
    let mut adj = vec![Vec::new(); n];
    for c in 0..n {
        for &r in &sym.row_idx()[sym.col_ptr()[c]..sym.col_ptr()[c + 1]] {
            if r != c && r < n {
                adj[r].push(c);
                adj[c].push(r);
            }
        }
    }
    for a in &mut adj {
        a.sort_unstable();
        a.dedup();
    }
    adj
}

/// Breadth-first levels from `start` within unvisited nodes: the visit order and the depth.
fn bfs(adj: &[Vec<usize>], start: usize, seen: &[bool]) -> (Vec<usize>, usize) {
    let mut mark = seen.to_vec();
    let (mut order, mut level, mut depth) = (vec![start], vec![start], 0);
    mark[start] = true;
    while !level.is_empty() {
        let mut next = Vec::new();
        for &u in &level {
            let mut nb: Vec<usize> = adj[u].iter().copied().filter(|&v| !mark[v]).collect();
            nb.sort_by_key(|&v| adj[v].len());
            for v in nb {
                mark[v] = true;
                next.push(v);
            }
        }
        order.extend(&next);
        depth += usize::from(!next.is_empty());
        level = next;
    }
    (order, depth)
}

/// The reverse Cuthill-McKee permutation `(forward, inverse)` of `sym`.
pub(super) fn order(sym: SymbolicSparseColMatRef<'_, usize>) -> (Vec<usize>, Vec<usize>) {
    let n = sym.ncols();
    let adj = adjacency(sym);
    let mut seen = vec![false; n];
    let mut fwd = Vec::with_capacity(n);
    while fwd.len() < n {
        let mut start = (0..n)
            .filter(|&v| !seen[v])
            .min_by_key(|&v| adj[v].len())
            .expect("an unvisited node while the order is short");
        let (mut visit, mut depth) = bfs(&adj, start, &seen);
        loop {
            let far = *visit.last().expect("the start is visited");
            let (v2, d2) = bfs(&adj, far, &seen);
            if d2 <= depth || far == start {
                break;
            }
            (start, visit, depth) = (far, v2, d2);
        }
        for &v in &visit {
            seen[v] = true;
        }
        fwd.extend(visit);
    }
    fwd.reverse();
    let mut inv = vec![0; n];
    for (i, &v) in fwd.iter().enumerate() {
        inv[v] = i;
    }
    (fwd, inv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::SymbolicSparseColMat;

    /// A path `0 - 1 - ... - (n-1)` whose nodes carry the labels `label[k]`, both directions
    /// and the diagonal in the pattern.
    fn labelled_path(label: &[usize]) -> SymbolicSparseColMat<usize> {
        let n = label.len();
        let mut cols = vec![Vec::new(); n];
        for k in 0..n {
            cols[label[k]].push(label[k]);
            if k + 1 < n {
                cols[label[k]].push(label[k + 1]);
                cols[label[k + 1]].push(label[k]);
            }
        }
        let (mut ptr, mut idx) = (vec![0], Vec::new());
        for mut c in cols {
            c.sort_unstable();
            idx.extend(c);
            ptr.push(idx.len());
        }
        SymbolicSparseColMat::new_checked(n, n, ptr, None, idx)
    }

    #[test]
    fn a_shuffled_path_is_ordered_along_itself() {
        let label = [7, 3, 9, 0, 5, 1, 8, 2, 6, 4];
        let sym = labelled_path(&label);
        let (fwd, inv) = order(sym.as_ref());
        let mut sorted = fwd.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..10).collect::<Vec<_>>(), "a permutation");
        for (i, &v) in fwd.iter().enumerate() {
            assert_eq!(inv[v], i);
        }
        // along the path, neighbours are next to each other in the order: bandwidth 1
        for k in 0..9 {
            let (a, b) = (inv[label[k]], inv[label[k + 1]]);
            assert_eq!(a.abs_diff(b), 1, "nodes {} and {}", label[k], label[k + 1]);
        }
    }
}
