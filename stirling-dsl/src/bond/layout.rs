//! A simple layered layout of a bond graph, for drawing it without Graphviz: layers along the
//! power direction (left to right, longest path), each layer ordered by the mean position of
//! its neighbours (a few barycentre sweeps), text-sized boxes.

use std::collections::VecDeque;

use super::graph::BondGraph;

/// Horizontal gap between layers and vertical gap between boxes (px).
const GAP_X: f64 = 56.0;
const GAP_Y: f64 = 18.0;
/// Box height and the width of one character of the label (px, 13 px Helvetica).
const BOX_H: f64 = 18.0;
const CHAR_W: f64 = 7.4;
/// Margin round the drawing (px).
pub const MARGIN: f64 = 16.0;

/// Where each node is drawn: the centre and the half sizes of its box.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    pub centre: Vec<(f64, f64)>,
    pub half: Vec<(f64, f64)>,
    pub width: f64,
    pub height: f64,
}

/// The layered layout of `g`.
pub fn layered(g: &BondGraph) -> Layout {
    let layers = order(g, layer_of(g));
    let half: Vec<(f64, f64)> = g
        .nodes
        .iter()
        .map(|n| {
            (
                n.text().chars().count() as f64 * CHAR_W / 2.0 + 5.0,
                BOX_H / 2.0,
            )
        })
        .collect();
    let mut centre = vec![(0.0, 0.0); g.nodes.len()];
    let heights: Vec<f64> = layers
        .iter()
        .map(|l| l.len() as f64 * (BOX_H + GAP_Y) - GAP_Y)
        .collect();
    let height = heights.iter().copied().fold(0.0, f64::max);
    let mut x = MARGIN;
    for (l, nodes) in layers.iter().enumerate() {
        let w = nodes.iter().map(|&n| half[n].0).fold(0.0, f64::max);
        let mut y = MARGIN + (height - heights[l]) / 2.0 + BOX_H / 2.0;
        for &n in nodes {
            centre[n] = (x + w, y);
            y += BOX_H + GAP_Y;
        }
        x += 2.0 * w + GAP_X;
    }
    Layout {
        centre,
        half,
        width: x - GAP_X + MARGIN,
        height: height + 2.0 * MARGIN,
    }
}

/// The neighbours of every node (through any bond).
fn neighbours(g: &BondGraph) -> Vec<Vec<usize>> {
    let mut adj = vec![Vec::new(); g.nodes.len()];
    for b in &g.bonds {
        adj[b.from].push(b.to);
        adj[b.to].push(b.from);
    }
    adj
}

/// The layer of each node: the longest power path reaching it (bonds point from a lower to
/// a higher layer), then each node moved right next to the nearest of its successors that
/// is not a leaf, and each leaf (an element on one bond into it) right after its node. A
/// directed cycle is broken at its first node.
fn layer_of(g: &BondGraph) -> Vec<usize> {
    let order = topological(g);
    let mut layer = vec![0usize; g.nodes.len()];
    let mut placed = vec![false; g.nodes.len()];
    for &n in &order {
        for b in g.bonds.iter().filter(|b| b.to == n && placed[b.from]) {
            layer[n] = layer[n].max(layer[b.from] + 1);
        }
        placed[n] = true;
    }
    let degree = |n: usize| g.bonds.iter().filter(|b| b.from == n || b.to == n).count();
    let leaf = |n: usize| degree(n) == 1 && g.bonds.iter().any(|b| b.to == n);
    for &n in order.iter().rev() {
        let next = g
            .bonds
            .iter()
            .filter(|b| b.from == n && layer[b.to] > layer[n] && !leaf(b.to))
            .map(|b| layer[b.to])
            .min();
        if let Some(m) = next {
            layer[n] = layer[n].max(m - 1);
        }
    }
    for b in &g.bonds {
        if leaf(b.to) {
            layer[b.to] = layer[b.from] + 1;
        }
    }
    layer
}

/// The nodes in an order where every bond goes forwards (Kahn's algorithm; when only
/// nodes on cycles are left, the first of them goes next).
fn topological(g: &BondGraph) -> Vec<usize> {
    let mut indegree = vec![0usize; g.nodes.len()];
    for b in &g.bonds {
        indegree[b.to] += 1;
    }
    let mut done = vec![false; g.nodes.len()];
    let mut order = Vec::with_capacity(g.nodes.len());
    let mut queue: VecDeque<usize> = (0..g.nodes.len()).filter(|&n| indegree[n] == 0).collect();
    while order.len() < g.nodes.len() {
        let n = match queue.pop_front() {
            Some(n) if !done[n] => n,
            Some(_) => continue,
            None => match (0..g.nodes.len()).find(|&n| !done[n]) {
                Some(n) => n,
                None => break,
            },
        };
        done[n] = true;
        order.push(n);
        for b in g.bonds.iter().filter(|b| b.from == n) {
            indegree[b.to] = indegree[b.to].saturating_sub(1);
            if indegree[b.to] == 0 && !done[b.to] {
                queue.push_back(b.to);
            }
        }
    }
    order
}

/// The nodes of each layer, ordered by barycentre sweeps (down then up, four times).
fn order(g: &BondGraph, layer: Vec<usize>) -> Vec<Vec<usize>> {
    let adj = neighbours(g);
    let count = layer.iter().copied().max().map_or(0, |m| m + 1);
    let mut layers = vec![Vec::new(); count];
    for (n, &l) in layer.iter().enumerate() {
        layers[l].push(n);
    }
    let mut rank = vec![0.0; g.nodes.len()];
    let set_ranks = |layers: &Vec<Vec<usize>>, rank: &mut Vec<f64>| {
        for l in layers {
            for (i, &n) in l.iter().enumerate() {
                rank[n] = i as f64 - l.len() as f64 / 2.0;
            }
        }
    };
    set_ranks(&layers, &mut rank);
    for sweep in 0..8 {
        let down = sweep % 2 == 0;
        let range: Vec<usize> = if down {
            (1..count).collect()
        } else {
            (0..count.saturating_sub(1)).rev().collect()
        };
        for l in range {
            let key = |n: usize| {
                let ns: Vec<f64> = adj[n]
                    .iter()
                    .filter(|&&m| if down { layer[m] < l } else { layer[m] > l })
                    .map(|&m| rank[m])
                    .collect();
                if ns.is_empty() {
                    rank[n]
                } else {
                    ns.iter().sum::<f64>() / ns.len() as f64
                }
            };
            let mut keyed: Vec<(f64, usize)> = layers[l].iter().map(|&n| (key(n), n)).collect();
            keyed.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            layers[l] = keyed.into_iter().map(|(_, n)| n).collect();
            set_ranks(&layers, &mut rank);
        }
    }
    layers
}
