//! Sparse matrices as the export writes them: 0-based triplets, row-major, each carrying the
//! [`FORMAT`](crate::linear::export::FORMAT) sentence that says how to read it.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// How triplets are read, written into each of them.
pub const FORMAT: &str = "triplets, 0-based: entry k is row i[k], column j[k], value v[k]; entries not listed are zero, no (i, j) repeats; scipy.sparse.coo_matrix((v, (i, j)), shape=(rows, cols))";

fn format() -> String {
    FORMAT.to_string()
}

/// A sparse matrix: 0-based row and column indices and the nonzero values (row-major).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Triplets {
    /// [`FORMAT`](crate::linear::export::FORMAT).
    #[serde(default = "format")]
    pub format: String,
    pub rows: usize,
    pub cols: usize,
    pub i: Vec<usize>,
    pub j: Vec<usize>,
    pub v: Vec<f64>,
}

impl Triplets {
    /// The empty `rows x cols` matrix.
    pub fn new(rows: usize, cols: usize) -> Self {
        Self {
            format: format(),
            rows,
            cols,
            i: Vec::new(),
            j: Vec::new(),
            v: Vec::new(),
        }
    }

    /// Append the entry `(i, j, v)` unless `v` is zero.
    pub fn push(&mut self, i: usize, j: usize, v: f64) {
        if v != 0.0 {
            self.i.push(i);
            self.j.push(j);
            self.v.push(v);
        }
    }

    /// A vector's nonzeros as one column (`n x 1`).
    pub fn column(v: &DVector<f64>) -> Self {
        let mut t = Self::new(v.len(), 1);
        v.iter().enumerate().for_each(|(i, x)| t.push(i, 0, *x));
        t
    }

    /// A vector's nonzeros as one row (`1 x n`).
    pub fn row(v: &DVector<f64>) -> Self {
        let mut t = Self::new(1, v.len());
        v.iter().enumerate().for_each(|(j, x)| t.push(0, j, *x));
        t
    }

    /// A dense matrix's nonzeros, row-major (small matrices only: the dense route's).
    pub fn of_dense(m: &DMatrix<f64>) -> Self {
        let mut t = Self::new(m.nrows(), m.ncols());
        for i in 0..m.nrows() {
            for j in 0..m.ncols() {
                t.push(i, j, m[(i, j)]);
            }
        }
        t
    }

    /// The entries as `(i, j, v)`.
    pub fn entries(&self) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
        (0..self.v.len()).map(|k| (self.i[k], self.j[k], self.v[k]))
    }

    /// The dense form (small matrices only).
    pub fn dense(&self) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(self.rows, self.cols);
        self.entries().for_each(|(i, j, v)| m[(i, j)] += v);
        m
    }

    /// The dense form by rows, as the JSON writes small matrices.
    pub fn dense_rows(&self) -> Vec<Vec<f64>> {
        let m = self.dense();
        (0..m.nrows())
            .map(|i| m.row(i).iter().copied().collect())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_keep_their_nonzeros_and_shape() {
        let v = DVector::from_vec(vec![0.0, 2.0, 0.0, -1.5]);
        let (c, r) = (Triplets::column(&v), Triplets::row(&v));
        assert_eq!(
            (c.rows, c.cols, c.i.clone(), c.j.clone()),
            (4, 1, vec![1, 3], vec![0, 0])
        );
        assert_eq!(
            (r.rows, r.cols, r.i.clone(), r.j.clone()),
            (1, 4, vec![0, 0], vec![1, 3])
        );
        assert_eq!(c.v, vec![2.0, -1.5]);
        assert_eq!(
            c.dense_rows(),
            vec![vec![0.0], vec![2.0], vec![0.0], vec![-1.5]]
        );
        assert_eq!(r.dense_rows(), vec![v.iter().copied().collect::<Vec<_>>()]);
        assert_eq!(c.format, FORMAT);
    }

    #[test]
    fn dense_round_trip_is_exact() {
        let m = DMatrix::from_row_slice(2, 3, &[0.0, 1.25, 0.0, -3.0, 0.0, 7.0]);
        let t = Triplets::of_dense(&m);
        assert_eq!(
            t.entries().collect::<Vec<_>>(),
            vec![(0, 1, 1.25), (1, 0, -3.0), (1, 2, 7.0)]
        );
        assert_eq!(t.dense(), m);
        let empty = Triplets::new(1, 1);
        assert_eq!(empty.dense_rows(), vec![vec![0.0]]);
    }

    #[test]
    fn the_format_is_read_back_and_defaulted() {
        let t = Triplets::column(&DVector::from_vec(vec![1.0]));
        let s = serde_json::to_string(&t).unwrap();
        assert!(s.starts_with("{\"format\":\"triplets, 0-based"), "{s}");
        assert_eq!(serde_json::from_str::<Triplets>(&s).unwrap(), t);
        let old = r#"{"rows":1,"cols":1,"i":[0],"j":[0],"v":[1.0]}"#;
        assert_eq!(serde_json::from_str::<Triplets>(old).unwrap(), t);
    }
}
