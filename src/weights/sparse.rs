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
