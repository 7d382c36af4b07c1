//! Sparse linear algebra the weight solvers share: principal sub-matrices of a symmetric sprs
//! matrix, their Cholesky factorization (faer, sequential), and products.

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{MatMut, Side};
use sprs::CsMat;

/// Why a factorization failed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SolveError {
    #[error("the system is not positive definite")]
    NotPositiveDefinite,
    #[error("{count} mesh vertices lie on pieces that no handle reaches")]
    Unreachable { count: usize },
    #[error("sparse matrix assembly failed: {0}")]
    Assembly(String),
}

/// A Cholesky factorization of the principal sub-matrix A[keep, keep] of a symmetric matrix.
pub struct SubmatrixCholesky {
    llt: faer::sparse::linalg::solvers::Llt<usize, f64>,
    len: usize,
}

/// Maps each index of `0..n` to its position in `keep` (sorted ascending), or `usize::MAX`.
pub fn positions(n: usize, keep: &[usize]) -> Vec<usize> {
    let mut pos = vec![usize::MAX; n];
    for (k, &i) in keep.iter().enumerate() {
        pos[i] = k;
    }
    pos
}

impl SubmatrixCholesky {
    /// Factors A[keep, keep]; `a` must be symmetric (only its lower triangle is read).
    pub fn new(a: &CsMat<f64>, keep: &[usize]) -> Result<Self, SolveError> {
        let pos = positions(a.rows(), keep);
        let mut triplets = Vec::new();
        for (k, &i) in keep.iter().enumerate() {
            if let Some(row) = a.outer_view(i) {
                for (j, &v) in row.iter() {
                    let pj = pos[j];
                    if pj != usize::MAX && pj <= k {
                        triplets.push(Triplet::new(k, pj, v));
                    }
                }
            }
        }
        let len = keep.len();
        let mat = SparseColMat::<usize, f64>::try_new_from_triplets(len, len, &triplets)
            .map_err(|e| SolveError::Assembly(format!("{e:?}")))?;
        let llt = mat
            .sp_cholesky(Side::Lower)
            .map_err(|_| SolveError::NotPositiveDefinite)?;
        Ok(SubmatrixCholesky { llt, len })
    }

    /// Solves A[keep, keep] x = b in place, for every column of `b` (column-major, `len` rows).
    pub fn solve_in_place(&self, b: &mut [f64]) {
        if self.len == 0 {
            return;
        }
        let cols = b.len() / self.len;
        self.llt
            .solve_in_place(MatMut::from_column_major_slice_mut(b, self.len, cols));
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// The lower triangle of a symmetric principal sub-matrix A[keep, keep] in compressed columns,
/// with its symbolic Cholesky analysis (fill-reducing ordering, elimination tree) done once, so
/// that matrices with the same pattern and other values (A + a diagonal, as interior-point
/// iterations produce) factor numerically only.
pub struct SharedPattern {
    symbolic: faer::sparse::SymbolicSparseColMat<usize>,
    llt_symbolic: faer::sparse::linalg::solvers::SymbolicLlt<usize>,
    /// A's values in the pattern's order.
    pub values: Vec<f64>,
    /// Where each column's diagonal entry sits in `values`.
    pub diagonal: Vec<usize>,
}

impl SharedPattern {
    /// Analyzes A[keep, keep] (A symmetric; every kept diagonal entry must be stored).
    pub fn new(a: &CsMat<f64>, keep: &[usize]) -> Result<Self, SolveError> {
        let pos = positions(a.rows(), keep);
        let len = keep.len();
        let mut col_ptr = Vec::with_capacity(len + 1);
        let mut row_idx = Vec::new();
        let mut values = Vec::new();
        let mut diagonal = Vec::with_capacity(len);
        col_ptr.push(0);
        for (k, &i) in keep.iter().enumerate() {
            // Column k of the lower triangle = row k's entries at or below the diagonal.
            let mut column: Vec<(usize, f64)> = a
                .outer_view(i)
                .map(|row| {
                    row.iter()
                        .filter_map(|(j, &v)| {
                            (pos[j] != usize::MAX && pos[j] >= k).then_some((pos[j], v))
                        })
                        .collect()
                })
                .unwrap_or_default();
            column.sort_unstable_by_key(|e| e.0);
            if column.first().map(|e| e.0) != Some(k) {
                column.insert(0, (k, 0.0));
            }
            diagonal.push(row_idx.len());
            for (r, v) in column {
                row_idx.push(r);
                values.push(v);
            }
            col_ptr.push(row_idx.len());
        }
        let symbolic =
            faer::sparse::SymbolicSparseColMat::new_checked(len, len, col_ptr, None, row_idx);
        let llt_symbolic =
            faer::sparse::linalg::solvers::SymbolicLlt::try_new(symbolic.as_ref(), Side::Lower)
                .map_err(|e| SolveError::Assembly(format!("{e:?}")))?;
        Ok(SharedPattern {
            symbolic,
            llt_symbolic,
            values,
            diagonal,
        })
    }

    pub fn len(&self) -> usize {
        self.diagonal.len()
    }

    pub fn is_empty(&self) -> bool {
        self.diagonal.is_empty()
    }

    /// Factors the matrix with this pattern and the given values (numeric phase only).
    pub fn factor(&self, values: &[f64]) -> Result<PatternCholesky, SolveError> {
        let mat = faer::sparse::SparseColMatRef::new(self.symbolic.as_ref(), values);
        let llt = faer::sparse::linalg::solvers::Llt::try_new_with_symbolic(
            self.llt_symbolic.clone(),
            mat,
            Side::Lower,
        )
        .map_err(|_| SolveError::NotPositiveDefinite)?;
        Ok(PatternCholesky {
            llt,
            len: self.len(),
        })
    }

    /// y = A x with A given by this pattern and `values` (symmetric: lower triangle stored).
    pub fn mat_vec(&self, values: &[f64], x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        let (col_ptr, row_idx) = (self.symbolic.col_ptr(), self.symbolic.row_idx());
        for c in 0..self.len() {
            for k in col_ptr[c]..col_ptr[c + 1] {
                let (r, v) = (row_idx[k], values[k]);
                y[r] += v * x[c];
                if r != c {
                    y[c] += v * x[r];
                }
            }
        }
        y
    }
}

/// A numeric Cholesky factorization over a [`SharedPattern`].
pub struct PatternCholesky {
    llt: faer::sparse::linalg::solvers::Llt<usize, f64>,
    len: usize,
}

impl PatternCholesky {
    /// Solves in place for one right-hand side.
    pub fn solve_in_place(&self, b: &mut [f64]) {
        if self.len > 0 {
            self.llt
                .solve_in_place(MatMut::from_column_major_slice_mut(b, self.len, 1));
        }
    }
}

/// y = A x for a CSR matrix.
pub fn mat_vec(a: &CsMat<f64>, x: &[f64]) -> Vec<f64> {
    a.outer_iterator()
        .map(|row| row.iter().map(|(j, v)| v * x[j]).sum())
        .collect()
}

/// A · diag(d) · A for a symmetric CSR matrix A: the bi-Laplacian K M⁻¹ K with d = 1/mass.
pub fn sandwich_diagonal(a: &CsMat<f64>, d: &[f64]) -> CsMat<f64> {
    let mut scaled = a.clone();
    // Scaling the rows of the left factor by d scales A's columns in the product's middle.
    for (i, mut row) in scaled.outer_iterator_mut().enumerate() {
        for (_, v) in row.iter_mut() {
            *v *= d[i];
        }
    }
    // (diag(d) A) is row-scaled; A · (diag(d) A) = A diag(d) A.
    &a.view() * &scaled.view()
}

#[cfg(test)]
mod tests {
    use super::*;
    use sprs::TriMat;

    #[test]
    fn solves_a_principal_submatrix() {
        // A tridiagonal SPD matrix; keep indices 0, 2, 3.
        let mut t = TriMat::new((4, 4));
        for i in 0..4 {
            t.add_triplet(i, i, 4.0);
            if i + 1 < 4 {
                t.add_triplet(i, i + 1, -1.0);
                t.add_triplet(i + 1, i, -1.0);
            }
        }
        let a: CsMat<f64> = t.to_csr();
        let chol = SubmatrixCholesky::new(&a, &[0, 2, 3]).unwrap();
        // A[{0,2,3}] = [[4,0,0],[0,4,-1],[0,-1,4]]
        let mut b = vec![4.0, 3.0, 3.0];
        chol.solve_in_place(&mut b);
        for (got, want) in b.iter().zip([1.0, 1.0, 1.0]) {
            assert!((got - want).abs() < 1e-12);
        }
    }

    #[test]
    fn sandwich_matches_dense_product() {
        let mut t = TriMat::new((3, 3));
        for (i, j, v) in [
            (0, 0, 2.0),
            (0, 1, -1.0),
            (1, 0, -1.0),
            (1, 1, 2.0),
            (1, 2, -1.0),
            (2, 1, -1.0),
            (2, 2, 1.0),
        ] {
            t.add_triplet(i, j, v);
        }
        let a: CsMat<f64> = t.to_csr();
        let d = [0.5, 2.0, 1.0];
        let q = sandwich_diagonal(&a, &d);
        let dense = |m: &CsMat<f64>, i: usize, j: usize| *m.get(i, j).unwrap_or(&0.0);
        for i in 0..3 {
            for j in 0..3 {
                let want: f64 = (0..3)
                    .map(|k| dense(&a, i, k) * d[k] * dense(&a, k, j))
                    .sum();
                assert!((dense(&q, i, j) - want).abs() < 1e-12);
            }
        }
    }
}
