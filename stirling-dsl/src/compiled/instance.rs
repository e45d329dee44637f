//! A plan's expressions at a given `n`: each frame expression instantiated at its place (a
//! scalar row, section `j` of an array row, or section `j` of a loop over the sections) into
//! a fresh arena whose leaves are the state's and the parameters' elements. Equal values of
//! neighbouring sections (a link's flux is the outflow of one section and the inflow of the
//! next) meet as one node: the arena's hash-consing is the common-subexpression elimination.
//!
//! The places follow the emitted code exactly, so the tape computes what the macro's Rust
//! computes: in a row's first and only section the index `j` is the number 0 and in its last
//! `n - 1`; in the interior sections and in every loop (sums, vessels, walls) `j` and `n` are
//! values the arithmetic does not see through (as the generated code's `jf` and `nf`); a
//! division in a row, a sum or a chain is `a * (1 / b)` as
//! [`crate::codegen::canon::quotient`] writes it, elsewhere `a / b`.

use std::collections::HashMap;

use crate::codegen::canon::quotient;
use crate::expr::{Arena, At, Id, Node, Sym};
use crate::topology::System;

/// Where a frame expression is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Place {
    /// A scalar row, or a function of the whole state: no section.
    Scalar,
    /// Section `j` of an array row, of variant `v` (0 the only section, 1 the first, 2 an
    /// interior one, 3 the last).
    Row { v: u8, j: u32 },
    /// Section `j` of a loop over every section (sums, vessels, walls, chains).
    Loop { j: u32 },
}

/// The variant of section `j` of `n` (`crate::topology::VARIANTS` order).
pub(crate) fn variant(j: usize, n: usize) -> u8 {
    match (n, j) {
        (1, _) => 0,
        (_, 0) => 1,
        _ if j + 1 == n => 3,
        _ => 2,
    }
}

/// A leaf of the instantiated arena.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Leaf {
    State(usize),
    Param(usize),
    /// The value read by an expression sensor.
    Read(usize),
    /// An integer the arithmetic does not see through (`j`, `n`).
    Opaque(u32),
}

impl Leaf {
    /// The symbol that stands for the leaf in the instantiated arena (its own encoding:
    /// `Sym::Sum(v)` is the opaque integer `v` there, as no sum is left).
    fn sym(self) -> Sym {
        match self {
            Leaf::State(i) => Sym::State(i as u32, At::Scalar),
            Leaf::Param(k) => Sym::Param(k as u32),
            Leaf::Read(i) => Sym::Input(i as u32),
            Leaf::Opaque(v) => Sym::Sum(v),
        }
    }

    /// The leaf a symbol of the instantiated arena stands for.
    pub(crate) fn of(s: Sym) -> Option<Leaf> {
        Some(match s {
            Sym::State(i, At::Scalar) => Leaf::State(i as usize),
            Sym::Param(k) => Leaf::Param(k as usize),
            Sym::Input(i) => Leaf::Read(i as usize),
            Sym::Sum(v) => Leaf::Opaque(v),
            _ => return None,
        })
    }
}

/// An expression that cannot be instantiated: a flaw of the assembly, never of the input
/// (reported, not a panic).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum InstanceError {
    #[error("internal: state block {0} has no state in this closure")]
    NoBlock(u32),
    #[error("internal: element {at:?} of block {block} outside the array at section {j} of {n}")]
    Outside {
        block: u32,
        at: At,
        j: i64,
        n: usize,
    },
    #[error("internal: symbol {0:?} read outside the sections")]
    Misplaced(Sym),
}

/// The instantiated arena and the memo of what is in it.
pub(crate) struct Instance<'a> {
    src: &'a Arena,
    sums: &'a [Id],
    /// State offset of every block, by its symbol number (`None`: not in this closure).
    offsets: Vec<Option<usize>>,
    n: usize,
    /// Parameter values folded in as numbers (`None`: the parameters are inputs).
    fold: Option<&'a [f64]>,
    pub(crate) out: Arena,
    memo: HashMap<(Id, Place, bool), Id>,
    sum_values: HashMap<u32, Id>,
}

impl<'a> Instance<'a> {
    pub(crate) fn new(
        src: &'a Arena,
        sys: &System,
        sums: &'a [Id],
        n: usize,
        fold: Option<&'a [f64]>,
    ) -> Self {
        let max = sys
            .blocks
            .iter()
            .map(|b| b.sym as usize + 1)
            .max()
            .unwrap_or(0);
        let mut offsets = vec![None; max.max(sys.array_blocks.len())];
        let (mut s, mut a) = (0usize, 0usize);
        for b in &sys.blocks {
            offsets[b.sym as usize] = Some(s + a * n);
            if b.array {
                a += 1;
            } else {
                s += 1;
            }
        }
        Instance {
            src,
            sums,
            offsets,
            n,
            fold,
            out: Arena::new(),
            memo: HashMap::new(),
            sum_values: HashMap::new(),
        }
    }

    /// The number of sections.
    pub(crate) fn n(&self) -> usize {
        self.n
    }

    /// The state index of element `at` of block `block` read at `place`.
    pub(crate) fn index(&self, block: u32, at: At, place: Place) -> Result<usize, InstanceError> {
        let off = self
            .offsets
            .get(block as usize)
            .copied()
            .flatten()
            .ok_or(InstanceError::NoBlock(block))?;
        let n = self.n as i64;
        let k = match (at, place) {
            (At::Scalar | At::First, _) => 0,
            (At::Last, _) => n - 1,
            (At::Rel(r), Place::Row { j, .. } | Place::Loop { j }) => j as i64 + r as i64,
            (At::Rel(_), Place::Scalar) => {
                return Err(InstanceError::Misplaced(Sym::State(block, at)))
            }
        };
        if k < 0 || k >= n {
            let j = match place {
                Place::Row { j, .. } | Place::Loop { j } => j as i64,
                Place::Scalar => -1,
            };
            return Err(InstanceError::Outside {
                block,
                at,
                j,
                n: self.n,
            });
        }
        Ok(off + k as usize)
    }

    /// `id` read at `place`; `recip`: divisions as `a * (1 / b)`.
    pub(crate) fn get(&mut self, root: Id, place: Place, recip: bool) -> Result<Id, InstanceError> {
        if let Some(&r) = self.memo.get(&(root, place, recip)) {
            return Ok(r);
        }
        // post-order without recursion: a user's expression may be deep
        let mut stack = vec![(root, false)];
        while let Some((id, ready)) = stack.pop() {
            if self.memo.contains_key(&(id, place, recip)) {
                continue;
            }
            let node = self.src.node(id).clone();
            let kids = node.children();
            if !ready && !kids.is_empty() {
                stack.push((id, true));
                stack.extend(kids.into_iter().map(|k| (k, false)));
                continue;
            }
            let kids: Vec<Id> = kids
                .iter()
                .map(|k| self.memo[&(*k, place, recip)])
                .collect();
            let r = self.build(&node, &kids, place, recip)?;
            self.memo.insert((id, place, recip), r);
        }
        Ok(self.memo[&(root, place, recip)])
    }

    fn build(
        &mut self,
        node: &Node,
        kids: &[Id],
        place: Place,
        recip: bool,
    ) -> Result<Id, InstanceError> {
        Ok(match *node {
            Node::Sym(s) => self.leaf(s, place)?,
            Node::Named(..) => kids[0],
            Node::Div(a, b) if recip => self.quotient(a, b, kids),
            _ => self.out.make(node.with_children(kids)),
        })
    }

    /// [`quotient`] decided on the frame expression (whose constants are the instantiated
    /// one's before the index is set), then folded at the section as the emitted code's
    /// value numbering does.
    fn quotient(&mut self, a: Id, b: Id, kids: &[Id]) -> Id {
        let (x, y) = (kids[0], kids[1]);
        match (self.src.as_const(a), self.src.as_const(b)) {
            (None, None) => {
                let one = self.out.num(1.0);
                let r = self.out.div(one, y);
                self.out.mul(x, r)
            }
            _ => quotient(&mut self.out, x, y),
        }
    }

    fn leaf(&mut self, s: Sym, place: Place) -> Result<Id, InstanceError> {
        let n = self.n as u32;
        let leaf = match (s, place) {
            (Sym::Param(k), _) => match self.fold {
                Some(p) => return Ok(self.out.num(p[k as usize])),
                None => Leaf::Param(k as usize),
            },
            (Sym::State(b, at), _) => Leaf::State(self.index(b, at, place)?),
            (Sym::Input(i), _) => Leaf::Read(i as usize),
            (Sym::Count, _) => Leaf::Opaque(n),
            (Sym::Index, Place::Row { v: 0 | 1, .. }) => return Ok(self.out.num(0.0)),
            (Sym::Index, Place::Row { v: 3, .. }) => {
                let (count, one) = (self.out.sym(Leaf::Opaque(n).sym()), self.out.num(1.0));
                return Ok(self.out.sub(count, one));
            }
            (Sym::Index, Place::Row { j, .. } | Place::Loop { j }) => Leaf::Opaque(j),
            (Sym::Index, Place::Scalar) => return Err(InstanceError::Misplaced(s)),
            (Sym::Sum(k), _) => return self.sum(k),
        };
        Ok(self.out.sym(leaf.sym()))
    }

    /// `S_k = sum_j s_k(j)`, accumulated from `j = 0` as the emitted loop does.
    fn sum(&mut self, k: u32) -> Result<Id, InstanceError> {
        if let Some(&v) = self.sum_values.get(&k) {
            return Ok(v);
        }
        let template = self.sums[k as usize];
        let mut acc = self.out.num(0.0);
        for j in 0..self.n as u32 {
            let t = self.get(template, Place::Loop { j }, true)?;
            acc = self.out.add(acc, t);
        }
        self.sum_values.insert(k, acc);
        Ok(acc)
    }
}

impl Instance<'_> {
    /// The constant value of a frame expression, if it is one.
    pub(crate) fn src_const(&self, id: Id) -> Option<f64> {
        self.src.as_const(id)
    }
}
