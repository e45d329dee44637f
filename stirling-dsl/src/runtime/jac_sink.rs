//! Where a generated Jacobian writes its entries.
//!
//! A generated Jacobian is a straight program that hands its entries `(row, col, value)` to a
//! writer, in an order fixed by the model and `n` alone (never by the state). Three writers:
//! - [`JacSink::Dense`](crate::runtime::jac_sink::JacSink::Dense): added into column-major storage;
//! - [`JacSink::Triplets`](crate::runtime::jac_sink::JacSink::Triplets): appended as coordinate
//!   triplets (the pattern and the values);
//! - [`JacValues`](crate::runtime::jac_sink::JacValues): only the values, in that fixed order, into
//!   a slice: what a sparse solver wants once it knows the pattern
//!   ([`crate::Model::jacobian_pattern`]), 8 bytes per entry instead of 24 and no length
//!   bookkeeping (the format of CasADi's generated code).

/// What a generated Jacobian writes to (`add` accumulates where entries coincide).
pub trait JacWrite {
    /// Add `v` at `(r, c)`.
    fn add(&mut self, r: usize, c: usize, v: f64);
    /// Add the entries `(r, c, v)` in order.
    fn add_all<const K: usize>(&mut self, entries: &[(usize, usize, f64); K]);
}

/// Where the Jacobian entries go; `add` accumulates.
pub enum JacSink<'a> {
    /// Column-major dense storage with `nrows` rows (zero it first).
    Dense { data: &'a mut [f64], nrows: usize },
    /// Coordinate triplets `(row, col, value)`.
    Triplets(&'a mut Vec<(usize, usize, f64)>),
}

impl JacSink<'_> {
    /// Add `v` at `(r, c)`.
    #[inline(always)]
    pub fn add(&mut self, r: usize, c: usize, v: f64) {
        match self {
            JacSink::Dense { data, nrows } => data[r + *nrows * c] += v,
            JacSink::Triplets(t) => t.push((r, c, v)),
        }
    }

    /// Add the entries `(r, c, v)` in order: one capacity check for a block of triplets (a
    /// `push` per entry stores the length and loads it again for the next one, a chain
    /// through memory that costs more than the entry's arithmetic).
    #[inline(always)]
    pub fn add_all<const K: usize>(&mut self, entries: &[(usize, usize, f64); K]) {
        match self {
            JacSink::Dense { data, nrows } => {
                for &(r, c, v) in entries {
                    data[r + *nrows * c] += v;
                }
            }
            JacSink::Triplets(t) => t.extend_from_slice(entries),
        }
    }
}

impl JacWrite for JacSink<'_> {
    #[inline(always)]
    fn add(&mut self, r: usize, c: usize, v: f64) {
        JacSink::add(self, r, c, v)
    }
    #[inline(always)]
    fn add_all<const K: usize>(&mut self, entries: &[(usize, usize, f64); K]) {
        JacSink::add_all(self, entries)
    }
}

/// The values of the entries in the generated order, written (not added) one after the
/// other into `data`; `len` counts them (the next position).
pub struct JacValues<'a> {
    data: &'a mut [f64],
    len: usize,
}

impl<'a> JacValues<'a> {
    /// A writer filling `data` from its start (`data` must hold every entry: its length is
    /// that of [`crate::Model::jacobian_pattern`]).
    pub fn new(data: &'a mut [f64]) -> Self {
        Self { data, len: 0 }
    }
}

impl JacWrite for JacValues<'_> {
    #[inline(always)]
    fn add(&mut self, _r: usize, _c: usize, v: f64) {
        self.data[self.len] = v;
        self.len += 1;
    }
    #[inline(always)]
    fn add_all<const K: usize>(&mut self, entries: &[(usize, usize, f64); K]) {
        let dst = &mut self.data[self.len..self.len + K];
        for (d, e) in dst.iter_mut().zip(entries) {
            *d = e.2;
        }
        self.len += K;
    }
}
