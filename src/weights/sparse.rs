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

/// Diagonal shifts (relative to the largest diagonal entry) tried in turn by
/// [`SharedPattern::factor_regularized`].
pub const REGULARIZATION_STEPS: [f64; 3] = [1e-13, 1e-11, 1e-9];

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
///
/// The matrix is stored permuted into the fill-reducing order once, and analysed in that order
/// with no further permutation, so that a numeric factorization only scatters the values (faer
/// would otherwise permute the whole matrix on every factorization: a tenth of the bounded
/// solve's time).
pub struct SharedPattern {
    /// The lower triangle in the caller's order (for products).
    symbolic: faer::sparse::SymbolicSparseColMat<usize>,
    /// The lower triangle of P A Pᵀ, P the fill-reducing order.
    permuted: faer::sparse::SymbolicSparseColMat<usize>,
    /// The analysis of `permuted`, in its own (identity) order.
    pub(super) cholesky: faer::sparse::linalg::cholesky::SymbolicCholesky<usize>,
    /// `order[k]`: the caller's index at permuted position k.
    pub(super) order: Vec<usize>,
    /// `position[i]`: the permuted position of the caller's index i (the inverse of `order`).
    pub(super) position: Vec<usize>,
    /// Where each entry of `values` goes in `permuted`'s values.
    scatter: Vec<usize>,
    /// A's values in the pattern's order.
    pub values: Vec<f64>,
    /// Where each column's diagonal entry sits in `values`.
    pub diagonal: Vec<usize>,
}

impl SharedPattern {
    /// Analyzes A[keep, keep] (A symmetric; every kept diagonal entry must be stored).
    pub fn new(a: &CsMat<f64>, keep: &[usize]) -> Result<Self, SolveError> {
        Self::analyze(a, keep, None)
    }

    /// [`SharedPattern::new`] with the fill-reducing order taken from `rank` (one entry per row
    /// of `a`; kept indices are eliminated by increasing rank) instead of computed: for many
    /// principal sub-matrices of one matrix, one order of the whole ([`fill_reducing_rank`])
    /// restricted to each saves a minimum-degree analysis per sub-matrix.
    pub fn with_rank(a: &CsMat<f64>, keep: &[usize], rank: &[usize]) -> Result<Self, SolveError> {
        Self::analyze(a, keep, Some(rank))
    }

    fn analyze(a: &CsMat<f64>, keep: &[usize], rank: Option<&[usize]>) -> Result<Self, SolveError> {
        use faer::sparse::linalg::cholesky::{
            factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering,
        };
        let assembly = |e: faer::sparse::FaerError| SolveError::Assembly(format!("{e:?}"));
        let len = keep.len();
        let (symbolic, values, diagonal) = lower_triangle(a, keep);
        let (order, inverse): (Vec<usize>, Vec<usize>) = match rank {
            Some(rank) => {
                let mut order: Vec<usize> = (0..len).collect();
                order.sort_unstable_by_key(|&k| rank[keep[k]]);
                let mut inverse = vec![0; len];
                for (at, &k) in order.iter().enumerate() {
                    inverse[k] = at;
                }
                (order, inverse)
            }
            None => minimum_degree_order(&symbolic)?,
        };
        // Entry (r, c) of the lower triangle moves to (inverse[r], inverse[c]), mirrored into
        // the lower triangle: bucketed by its new column (a counting sort, linear in the
        // entries: a global sort was most of the analysis), then each column's few rows sorted.
        let (col_ptr, row_idx) = (symbolic.col_ptr(), symbolic.row_idx());
        let moved = |c: usize, k: usize| {
            let (pr, pc) = (inverse[row_idx[k]], inverse[c]);
            (pr.min(pc), pr.max(pc))
        };
        let mut lower_ptr = vec![0usize; len + 1];
        for c in 0..len {
            for k in col_ptr[c]..col_ptr[c + 1] {
                lower_ptr[moved(c, k).0 + 1] += 1;
            }
        }
        for c in 0..len {
            lower_ptr[c + 1] += lower_ptr[c];
        }
        let mut next = lower_ptr.clone();
        let mut slots = vec![(0usize, 0usize); values.len()];
        for c in 0..len {
            for k in col_ptr[c]..col_ptr[c + 1] {
                let (column, row) = moved(c, k);
                slots[next[column]] = (row, k);
                next[column] += 1;
            }
        }
        for c in 0..len {
            slots[lower_ptr[c]..lower_ptr[c + 1]].sort_unstable();
        }
        let mut scatter = vec![0usize; values.len()];
        for (at, &(_, k)) in slots.iter().enumerate() {
            scatter[k] = at;
        }
        let lower_rows: Vec<usize> = slots.iter().map(|&(r, _)| r).collect();
        // faer's analysis without reordering reads the upper triangle as given: the transpose,
        // bucketed by row; reading the lower triangle column by column leaves each upper
        // column's rows sorted.
        let mut upper_ptr = vec![0usize; len + 1];
        for &r in &lower_rows {
            upper_ptr[r + 1] += 1;
        }
        for c in 0..len {
            upper_ptr[c + 1] += upper_ptr[c];
        }
        let mut next = upper_ptr.clone();
        let mut upper_rows = vec![0usize; lower_rows.len()];
        for c in 0..len {
            for &r in &lower_rows[lower_ptr[c]..lower_ptr[c + 1]] {
                upper_rows[next[r]] = c;
                next[r] += 1;
            }
        }
        let permuted =
            faer::sparse::SymbolicSparseColMat::new_checked(len, len, lower_ptr, None, lower_rows);
        let upper =
            faer::sparse::SymbolicSparseColMat::new_checked(len, len, upper_ptr, None, upper_rows);
        // Supernodal is forced: faer's flop-ratio heuristic picks the simplicial factorization
        // for meshes of about 1k vertices and for some sub-meshes, where it is 2–4× slower per
        // numeric factorization, and every interior-point iteration pays for one.
        let cholesky = factorize_symbolic_cholesky(
            upper.as_ref(),
            Side::Upper,
            SymmetricOrdering::Identity,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold:
                    faer::sparse::linalg::SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .map_err(assembly)?;
        Ok(SharedPattern {
            symbolic,
            permuted,
            cholesky,
            order,
            position: inverse,
            scatter,
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

    /// [`SharedPattern::factor`], retried with the diagonal raised by
    /// [`REGULARIZATION_STEPS`] × the largest diagonal entry when rounding makes a pivot
    /// vanish: a positive semi-definite matrix assembled from a mesh with near-degenerate
    /// triangles (angles under a degree, vertex masses many orders below their neighbors')
    /// can lose definiteness in floating point although it has none to lose in exact
    /// arithmetic. The shift changes the solution by about that relative amount.
    pub fn factor_regularized(&self, values: &[f64]) -> Result<PatternCholesky<'_>, SolveError> {
        if let Ok(f) = self.factor(values) {
            return Ok(f);
        }
        let largest = self
            .diagonal
            .iter()
            .map(|&d| values[d].abs())
            .fold(0.0, f64::max);
        for step in REGULARIZATION_STEPS {
            let mut shifted = values.to_vec();
            for &d in &self.diagonal {
                shifted[d] += step * largest;
            }
            if let Ok(f) = self.factor(&shifted) {
                return Ok(f);
            }
        }
        Err(SolveError::NotPositiveDefinite)
    }

    /// Factors the matrix with this pattern and the given values (numeric phase only,
    /// sequential: callers run handles in parallel).
    pub fn factor(&self, values: &[f64]) -> Result<PatternCholesky<'_>, SolveError> {
        use faer::dyn_stack::{MemBuffer, MemStack};
        use faer::linalg::cholesky::llt::factor::LltRegularization;
        let mut permuted_values = vec![0.0; values.len()];
        for (k, &v) in values.iter().enumerate() {
            permuted_values[self.scatter[k]] = v;
        }
        let mut l_values = vec![0.0; self.cholesky.len_val()];
        let mut memory = MemBuffer::new(
            self.cholesky
                .factorize_numeric_llt_scratch::<f64>(faer::Par::Seq, Default::default()),
        );
        let matrix = faer::sparse::SparseColMatRef::new(self.permuted.as_ref(), &permuted_values);
        self.cholesky
            .factorize_numeric_llt(
                &mut l_values,
                matrix,
                Side::Lower,
                LltRegularization::default(),
                faer::Par::Seq,
                MemStack::new(&mut memory),
                Default::default(),
            )
            .map_err(|_| SolveError::NotPositiveDefinite)?;
        Ok(PatternCholesky {
            pattern: self,
            l_values,
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

/// A fill-reducing elimination rank for A[keep, keep] (A symmetric): `rank[i]` is kept index
/// i's position in the order faer's minimum-degree analysis chooses, `usize::MAX` elsewhere.
/// For [`SharedPattern::with_rank`].
pub fn fill_reducing_rank(a: &CsMat<f64>, keep: &[usize]) -> Result<Vec<usize>, SolveError> {
    let (symbolic, _, _) = lower_triangle(a, keep);
    let (order, _) = minimum_degree_order(&symbolic)?;
    let mut rank = vec![usize::MAX; a.rows()];
    for (at, &k) in order.iter().enumerate() {
        rank[keep[k]] = at;
    }
    Ok(rank)
}

/// The lower triangle of A[keep, keep] (A symmetric, CSR; `keep` ascending) in compressed
/// columns, every diagonal entry stored (zero where A stores none): its pattern, its values,
/// and where each column's diagonal entry sits in the values.
fn lower_triangle(
    a: &CsMat<f64>,
    keep: &[usize],
) -> (
    faer::sparse::SymbolicSparseColMat<usize>,
    Vec<f64>,
    Vec<usize>,
) {
    debug_assert!(
        keep.windows(2).all(|w| w[0] < w[1]),
        "keep must be ascending"
    );
    let pos = positions(a.rows(), keep);
    let len = keep.len();
    let mut col_ptr = Vec::with_capacity(len + 1);
    let mut row_idx = Vec::new();
    let mut values = Vec::new();
    let mut diagonal = Vec::with_capacity(len);
    col_ptr.push(0);
    for (k, &i) in keep.iter().enumerate() {
        // Column k of the lower triangle = row k's entries at or below the diagonal, in
        // order (a CSR row's columns are sorted, and `keep` is).
        diagonal.push(row_idx.len());
        row_idx.push(k);
        values.push(0.0);
        if let Some(row) = a.outer_view(i) {
            for (j, &v) in row.iter() {
                let p = pos[j];
                if p == k {
                    values[diagonal[k]] = v;
                } else if p != usize::MAX && p > k {
                    row_idx.push(p);
                    values.push(v);
                }
            }
        }
        col_ptr.push(row_idx.len());
    }
    let symbolic =
        faer::sparse::SymbolicSparseColMat::new_checked(len, len, col_ptr, None, row_idx);
    (symbolic, values, diagonal)
}

/// faer's approximate minimum degree order of a symmetric pattern given by its lower triangle:
/// (`order[k]`: the index eliminated k-th, its inverse). The order alone, without the
/// symbolic factorization a full analysis would add (a third of the analysis' time).
fn minimum_degree_order(
    lower: &faer::sparse::SymbolicSparseColMat<usize>,
) -> Result<(Vec<usize>, Vec<usize>), SolveError> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::amd;
    let n = lower.nrows();
    let (mut order, mut inverse) = (vec![0usize; n], vec![0usize; n]);
    let nnz = lower.row_idx().len();
    let mut memory = MemBuffer::try_new(amd::order_maybe_unsorted_scratch::<usize>(n, nnz))
        .map_err(|e| SolveError::Assembly(format!("{e:?}")))?;
    amd::order_maybe_unsorted(
        &mut order,
        &mut inverse,
        lower.as_ref(),
        amd::Control::default(),
        MemStack::new(&mut memory),
    )
    .map_err(|e| SolveError::Assembly(format!("{e:?}")))?;
    Ok((order, inverse))
}

/// A numeric Cholesky factorization over a [`SharedPattern`].
pub struct PatternCholesky<'a> {
    pub(super) pattern: &'a SharedPattern,
    /// The factor's values, in the pattern's fill-reducing order.
    pub(super) l_values: Vec<f64>,
}

impl PatternCholesky<'_> {
    /// Solves in place for one right-hand side (in the caller's order).
    pub fn solve_in_place(&self, b: &mut [f64]) {
        use faer::dyn_stack::{MemBuffer, MemStack};
        let n = self.pattern.len();
        if n == 0 {
            return;
        }
        let order = &self.pattern.order;
        let mut x: Vec<f64> = order.iter().map(|&i| b[i]).collect();
        let cholesky = &self.pattern.cholesky;
        let mut memory = MemBuffer::new(cholesky.solve_in_place_scratch::<f64>(1, faer::Par::Seq));
        faer::sparse::linalg::cholesky::LltRef::new(cholesky, &self.l_values)
            .solve_in_place_with_conj(
                faer::Conj::No,
                MatMut::from_column_major_slice_mut(&mut x, n, 1),
                faer::Par::Seq,
                MemStack::new(&mut memory),
            );
        for (k, &i) in order.iter().enumerate() {
            b[i] = x[k];
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
pub(crate) mod tests {
    use super::*;
    use sprs::TriMat;

    /// The Laplacian of a `side` × `side` grid (4-neighbours) plus `shift` on the diagonal:
    /// symmetric positive definite for a positive shift, a mesh-like sparsity pattern.
    pub(crate) fn grid_laplacian(side: usize, shift: f64) -> CsMat<f64> {
        let n = side * side;
        let mut t = TriMat::new((n, n));
        for j in 0..side {
            for i in 0..side {
                let v = j * side + i;
                let mut degree = 0.0;
                for (di, dj) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)] {
                    let (a, b) = (i as i64 + di, j as i64 + dj);
                    if (0..side as i64).contains(&a) && (0..side as i64).contains(&b) {
                        t.add_triplet(v, b as usize * side + a as usize, -1.0);
                        degree += 1.0;
                    }
                }
                t.add_triplet(v, v, degree + shift);
            }
        }
        t.to_csr()
    }

    /// A positive semi-definite matrix that is singular: the plain factorization fails, the
    /// regularized one shifts the diagonal by a tiny relative amount and succeeds, and an
    /// indefinite matrix still fails.
    #[test]
    fn regularized_factorization_shifts_only_what_rounding_needs() {
        let matrix = |off: f64| {
            let mut t = TriMat::new((2, 2));
            t.add_triplet(0, 0, 1.0);
            t.add_triplet(1, 1, 1.0);
            t.add_triplet(0, 1, off);
            t.add_triplet(1, 0, off);
            t.to_csr::<usize>()
        };
        let singular = SharedPattern::new(&matrix(1.0), &[0, 1]).unwrap();
        assert!(singular.factor(&singular.values).is_err());
        let f = singular.factor_regularized(&singular.values).unwrap();
        // Solves (A + εI) x = (1, 1) with x ≈ (0.5, 0.5).
        let mut x = vec![1.0, 1.0];
        f.solve_in_place(&mut x);
        assert!(
            (x[0] - 0.5).abs() < 1e-6 && (x[1] - 0.5).abs() < 1e-6,
            "{x:?}"
        );
        let indefinite = SharedPattern::new(&matrix(2.0), &[0, 1]).unwrap();
        assert!(indefinite.factor_regularized(&indefinite.values).is_err());
    }

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
    fn shared_pattern_factors_and_solves_in_the_callers_order() {
        // A 9×9 grid's Laplacian plus the identity (SPD; AMD reorders it), kept without its
        // first and last vertices, with a diagonal shift as the interior point adds.
        let a = grid_laplacian(9, 1.0);
        let n = a.rows();
        let keep: Vec<usize> = (1..n - 1).collect();
        let pattern = SharedPattern::new(&a, &keep).unwrap();
        let mut values = pattern.values.clone();
        for (k, &d) in pattern.diagonal.iter().enumerate() {
            values[d] += 0.5 + k as f64 * 0.01;
        }
        let b: Vec<f64> = (0..keep.len())
            .map(|k| ((k * 7) % 5) as f64 - 2.0)
            .collect();
        let mut x = b.clone();
        pattern.factor(&values).unwrap().solve_in_place(&mut x);
        // A x = b, checked with the pattern's own product.
        let ax = pattern.mat_vec(&values, &x);
        for (got, want) in ax.iter().zip(&b) {
            assert!((got - want).abs() < 1e-10, "{got} vs {want}");
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
