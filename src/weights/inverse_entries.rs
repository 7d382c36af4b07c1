//! Entries of H⁻¹ from a supernodal Cholesky factor H = L Lᵀ, without solving for whole columns.
//!
//! (H⁻¹)ᵢₖ = (L⁻¹ eᵢ) · (L⁻¹ eₖ), and L⁻¹ eₖ is nonzero only on the columns of the
//! elimination tree's path from k to its root (Gilbert's theorem on the reach of a sparse
//! right-hand side): on a mesh ordered by minimum degree, a few percent of the matrix. A forward
//! solve along that path ([`ForwardColumn`]) costs a few percent of a full solve, the dot product
//! of two of them is an entry of H⁻¹, and a combination H⁻¹ Σ cₖ eₖ = L⁻ᵀ Σ cₖ (L⁻¹ eₖ) costs one
//! backward solve for any number of terms. [`super::bounds`] needs exactly these: the Schur
//! complement of the held vertices, E_Pᵀ H⁻¹ E_P, and the solution with them held.
//!
//! In: a [`PatternCholesky`] (its supernodal factor, in the pattern's fill-reducing order).
//! Indices in and out are the caller's (the pattern's `keep` positions).

use super::sparse::PatternCholesky;
use faer::sparse::linalg::cholesky::supernodal::{SupernodalLltRef, SymbolicSupernodalCholesky};
use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;

/// A factor prepared for forward columns: the supernode of every permuted position.
pub struct InverseEntries<'f, 'p> {
    factor: &'f PatternCholesky<'p>,
    symbolic: &'p SymbolicSupernodalCholesky<usize>,
    supernode_of: Vec<usize>,
}

/// L⁻¹ eₖ on the supernodes of the elimination-tree path from k's supernode to the root,
/// ascending (a supernode's parent has a higher index).
#[derive(Clone, Debug)]
pub struct ForwardColumn {
    /// (supernode, its first permuted column, offset of its values in `values`).
    path: Vec<(usize, usize, usize)>,
    values: Vec<f64>,
}

impl ForwardColumn {
    /// (H⁻¹)ᵢₖ for the columns of i and k: the dot product over the supernodes both paths
    /// share (the paths meet at the two vertices' lowest common ancestor and coincide above).
    pub fn dot(&self, other: &ForwardColumn) -> f64 {
        let (mut a, mut b, mut sum) = (0, 0, 0.0);
        while a < self.path.len() && b < other.path.len() {
            let (sa, _, oa) = self.path[a];
            let (sb, _, ob) = other.path[b];
            match sa.cmp(&sb) {
                std::cmp::Ordering::Less => a += 1,
                std::cmp::Ordering::Greater => b += 1,
                std::cmp::Ordering::Equal => {
                    let len = self.segment_len(a);
                    sum += self.values[oa..oa + len]
                        .iter()
                        .zip(&other.values[ob..ob + len])
                        .map(|(x, y)| x * y)
                        .sum::<f64>();
                    a += 1;
                    b += 1;
                }
            }
        }
        sum
    }

    fn segment_len(&self, at: usize) -> usize {
        let end = self.path.get(at + 1).map_or(self.values.len(), |p| p.2);
        end - self.path[at].2
    }
}

impl<'f, 'p> InverseEntries<'f, 'p> {
    /// `None` when the factor is not supernodal ([`super::sparse::SharedPattern`] forces the
    /// supernodal analysis, so only an empty pattern has none).
    pub fn new(factor: &'f PatternCholesky<'p>) -> Option<Self> {
        let SymbolicCholeskyRaw::Supernodal(symbolic) = factor.pattern.cholesky.raw() else {
            return None;
        };
        let (begin, end) = (symbolic.supernode_begin(), symbolic.supernode_end());
        let mut supernode_of = vec![0; symbolic.nrows()];
        for s in 0..symbolic.n_supernodes() {
            supernode_of[begin[s]..end[s]].fill(s);
        }
        Some(InverseEntries {
            factor,
            symbolic,
            supernode_of,
        })
    }

    fn llt(&self) -> SupernodalLltRef<'_, usize, f64> {
        SupernodalLltRef::new(self.symbolic, &self.factor.l_values)
    }

    /// L⁻¹ eₖ for the caller's index `k`.
    pub fn forward(&self, k: usize) -> ForwardColumn {
        let symbolic = self.symbolic;
        let (begin, end) = (symbolic.supernode_begin(), symbolic.supernode_end());
        let llt = self.llt();
        let val_ptr = symbolic.col_ptr_for_val();
        let values = &self.factor.l_values;
        let start = self.factor.pattern.position[k];
        // The running right-hand side, dense over the permuted positions: only rows on the
        // path are ever set (a column's rows are its elimination-tree ancestors), and each is
        // read once, when the path reaches its supernode.
        let mut work = vec![0.0; symbolic.nrows()];
        work[start] = 1.0;
        let mut column = ForwardColumn {
            path: Vec::new(),
            values: Vec::new(),
        };
        let mut below = Vec::new();
        let mut s = self.supernode_of[start];
        loop {
            let (first, width) = (begin[s], end[s] - begin[s]);
            let pattern = llt.supernode(s).pattern();
            let rows = width + pattern.len();
            // Column-major, `rows` × `width`: the lower-triangular diagonal block on top.
            let block = &values[val_ptr[s]..val_ptr[s + 1]];
            let offset = column.values.len();
            column.values.extend_from_slice(&work[first..first + width]);
            let x = &mut column.values[offset..];
            for c in 0..width {
                let col = &block[c * rows..(c + 1) * rows];
                x[c] /= col[c];
                let xc = x[c];
                for (xr, &l) in x[c + 1..].iter_mut().zip(&col[c + 1..width]) {
                    *xr -= l * xc;
                }
            }
            below.clear();
            below.resize(pattern.len(), 0.0);
            for (c, &xc) in x.iter().enumerate() {
                let col = &block[c * rows + width..(c + 1) * rows];
                for (b, &l) in below.iter_mut().zip(col) {
                    *b += l * xc;
                }
            }
            for (&row, &b) in pattern.iter().zip(&below) {
                work[row] -= b;
            }
            column.path.push((s, first, offset));
            match pattern.first() {
                Some(&parent_column) => s = self.supernode_of[parent_column],
                None => break,
            }
        }
        column
    }

    /// H⁻¹ Σ cₖ eₖ for the terms (L⁻¹ eₖ, cₖ), in the caller's order: one backward solve.
    pub fn combination(&self, terms: &[(&ForwardColumn, f64)]) -> Vec<f64> {
        use faer::dyn_stack::{MemBuffer, MemStack};
        let n = self.symbolic.nrows();
        let mut r = vec![0.0; n];
        for (column, c) in terms {
            for (at, &(_, first, offset)) in column.path.iter().enumerate() {
                let len = column.segment_len(at);
                for (ri, &v) in r[first..first + len]
                    .iter_mut()
                    .zip(&column.values[offset..offset + len])
                {
                    *ri += c * v;
                }
            }
        }
        let mut memory = MemBuffer::new(
            self.symbolic
                .solve_in_place_scratch::<f64>(1, faer::Par::Seq),
        );
        self.llt().l_transpose_solve_with_conj(
            faer::Conj::No,
            faer::MatMut::from_column_major_slice_mut(&mut r, n, 1),
            faer::Par::Seq,
            MemStack::new(&mut memory),
        );
        let order = &self.factor.pattern.order;
        let mut out = vec![0.0; n];
        for (&v, &i) in r.iter().zip(order) {
            out[i] = v;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weights::sparse::tests::grid_laplacian;
    use crate::weights::sparse::SharedPattern;

    /// A 2D grid's Laplacian (shifted) squared: the shape of a bi-Laplacian.
    fn grid_bilaplacian(side: usize) -> sprs::CsMat<f64> {
        let l = grid_laplacian(side, 0.01);
        &l * &l
    }

    #[test]
    fn entries_and_combinations_match_full_solves() {
        let h = grid_bilaplacian(23);
        let n = h.rows();
        // A principal sub-matrix, as the support solves use.
        let keep: Vec<usize> = (0..n).filter(|i| i % 7 != 3).collect();
        let pattern = SharedPattern::new(&h, &keep).unwrap();
        let factor = pattern.factor(&pattern.values).unwrap();
        let inverse = InverseEntries::new(&factor).unwrap();
        let m = keep.len();
        let picks = [0, 5, m / 3, m / 2, m - 1];
        let full: Vec<Vec<f64>> = picks
            .iter()
            .map(|&k| {
                let mut e = vec![0.0; m];
                e[k] = 1.0;
                factor.solve_in_place(&mut e);
                e
            })
            .collect();
        let forward: Vec<ForwardColumn> = picks.iter().map(|&k| inverse.forward(k)).collect();
        for (a, fa) in forward.iter().enumerate() {
            for (b, &kb) in picks.iter().enumerate() {
                let entry = fa.dot(&forward[b]);
                assert!((entry - full[a][kb]).abs() < 1e-10 * full[a][kb].abs().max(1.0));
            }
            // The path is a small part of the matrix.
            assert!(fa.values.len() < m / 2, "{} of {m}", fa.values.len());
        }
        let terms: Vec<(&ForwardColumn, f64)> =
            forward.iter().zip([1.0, -2.0, 0.5, 3.0, -1.0]).collect();
        let combined = inverse.combination(&terms);
        for (i, &v) in combined.iter().enumerate() {
            let expected: f64 = terms
                .iter()
                .enumerate()
                .map(|(t, (_, c))| c * full[t][i])
                .sum();
            assert!((v - expected).abs() < 1e-9 * expected.abs().max(1.0), "{i}");
        }
    }
}
