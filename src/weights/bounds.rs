//! The bounds of one handle's weight on a known support, by a Schur complement over the
//! support's factorization.
//!
//! [`super::support`] solves each handle's bi-Laplacian once on the region where its weight is
//! strictly inside (0, 1). That region comes from a coarse solve, which does not resolve what
//! happens at the fine mesh's scale: around an interior point handle, and along a bone, the
//! fine weight rises to one on a small plateau (3–19 vertices on the critter rigs) where the
//! unconstrained solve on the support overshoots one, and near bones it dips below zero where
//! the coarse support reaches too far. Clamping the overshoot left the neighbourhood up to
//! 0.28 too high (docs/two-level-weights.md). Here the bounded problem on the support,
//! min ½ xᵀ H x − bᵀ x subject to 0 ≤ x ≤ 1 (H the support's bi-Laplacian, already factored,
//! x₀ = H⁻¹ b its unconstrained solution), is solved exactly: with the vertices held at a bound
//! as the set P, x = x₀ − H⁻¹ E_P λ, and the multipliers λ (signed: positive at the upper
//! bound, negative at the lower) solve the small dense system (E_Pᵀ H⁻¹ E_P) λ = x₀[P] − bound.
//! P is found by Lawson and Hanson's active-set method for non-negative multipliers: add the
//! most violating vertex, step back while a multiplier would change sign (its vertex leaves
//! P), so it ends in finitely many steps. Each vertex added costs one solve with the existing
//! factor (its column of H⁻¹) and a dense Cholesky factorization of |P|², |P| a few dozen.
//!
//! In: the factored support matrix, x₀ (in the support's order). Out: x within the bounds up
//! to [`BOUND_SLACK`], the held vertices exactly on theirs, and how many are held.

use super::sparse::PatternCholesky;
use nalgebra::{DMatrix, DVector};

/// A solved vertex is held at a bound when it is past it by more than this.
pub const BOUND_SLACK: f64 = 1e-9;

/// The most active-set steps per handle (each adds or removes one held vertex); measured
/// 3–270 on the critter rigs at 5k–20k vertices. Past it the solve is left unconstrained (and
/// clamped by the caller).
pub const MAX_BOUND_STEPS: usize = 2000;

/// Holds `x` (the unconstrained solution on the factored support, in the support's order) at
/// its bounds where it leaves them (see the module doc); returns how many vertices are held,
/// or `None` when the steps ran out or the held set's matrix lost definiteness (then `x` is
/// left as it was).
pub fn hold_bounds(factor: &PatternCholesky<'_>, x: &mut [f64]) -> Option<usize> {
    let n = x.len();
    let x0 = x.to_vec();
    // Held vertices (support positions), the bound each is held at (+1: one, −1: zero),
    // their columns of H⁻¹ and their multipliers (sign-free).
    let mut held: Vec<usize> = Vec::new();
    let mut signs: Vec<f64> = Vec::new();
    let mut columns: Vec<Vec<f64>> = Vec::new();
    let mut mu: Vec<f64> = Vec::new();
    let mut is_held = vec![false; n];
    let mut current = x0.clone();
    for _ in 0..MAX_BOUND_STEPS {
        let (mut worst, mut at) = (BOUND_SLACK, usize::MAX);
        for (k, &v) in current.iter().enumerate() {
            let past = (v - 1.0).max(-v);
            if past > worst && !is_held[k] {
                (worst, at) = (past, k);
            }
        }
        if at == usize::MAX {
            x.copy_from_slice(&current);
            return Some(held.len());
        }
        let mut column = vec![0.0; n];
        column[at] = 1.0;
        factor.solve_in_place(&mut column);
        held.push(at);
        signs.push(if current[at] > 0.5 { 1.0 } else { -1.0 });
        is_held[at] = true;
        columns.push(column);
        mu.push(0.0);
        // The multipliers of the held set, stepping back while one would turn negative.
        while !held.is_empty() {
            let p = held.len();
            let m = DMatrix::from_fn(p, p, |r, c| signs[r] * signs[c] * columns[c][held[r]]);
            // The bound is 1 for sign +1, 0 for sign −1: (1 + sign) / 2.
            let rhs = DVector::from_fn(p, |r, _| signs[r] * (x0[held[r]] - 0.5 * (1.0 + signs[r])));
            let z = m.cholesky()?.solve(&rhs);
            if z.iter().all(|&v| v > 0.0) {
                mu.copy_from_slice(z.as_slice());
                break;
            }
            let alpha = z
                .iter()
                .zip(&mu)
                .filter(|(&zk, _)| zk <= 0.0)
                .map(|(&zk, &mk)| mk / (mk - zk))
                .fold(1.0, f64::min);
            for (mk, &zk) in mu.iter_mut().zip(z.iter()) {
                *mk += alpha * (zk - *mk);
            }
            let mut k = 0;
            while k < held.len() {
                if mu[k] <= 0.0 {
                    is_held[held[k]] = false;
                    held.swap_remove(k);
                    signs.swap_remove(k);
                    columns.swap_remove(k);
                    mu.swap_remove(k);
                } else {
                    k += 1;
                }
            }
        }
        // x = x₀ − Σ λ_k H⁻¹ e_k.
        current.copy_from_slice(&x0);
        for ((column, &m), &s) in columns.iter().zip(&mu).zip(&signs) {
            let lambda = s * m;
            for (v, &c) in current.iter_mut().zip(column) {
                *v -= lambda * c;
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weights::sparse::SharedPattern;
    use sprs::TriMat;

    /// The 1D bi-Laplacian-like matrix of a chain: a dense check of the bounded solve.
    #[test]
    fn the_bounded_problem_on_a_chain_is_solved_exactly() {
        let n = 40;
        let mut t = TriMat::new((n, n));
        // H = D² + εI with D the chain's second difference: positive definite.
        let d = |i: usize, j: usize| -> f64 {
            if i == j {
                2.0
            } else if i.abs_diff(j) == 1 {
                -1.0
            } else {
                0.0
            }
        };
        let dense: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        (0..n).map(|k| d(i, k) * d(k, j)).sum::<f64>()
                            + if i == j { 1e-3 } else { 0.0 }
                    })
                    .collect()
            })
            .collect();
        for (i, row) in dense.iter().enumerate() {
            for (j, &v) in row.iter().enumerate() {
                if v != 0.0 {
                    t.add_triplet(i, j, v);
                }
            }
        }
        let h = t.to_csr();
        let keep: Vec<usize> = (0..n).collect();
        let pattern = SharedPattern::new(&h, &keep).unwrap();
        let factor = pattern.factor(&pattern.values).unwrap();
        // A load that pushes the middle above one and the ends below zero.
        let b: Vec<f64> = (0..n)
            .map(|i| if (15..25).contains(&i) { 0.05 } else { -0.01 })
            .collect();
        let mut x = b.clone();
        factor.solve_in_place(&mut x);
        assert!(x.iter().any(|&v| v > 1.0) && x.iter().any(|&v| v < 0.0));
        let held = hold_bounds(&factor, &mut x).unwrap();
        assert!(held > 0);
        // KKT of min ½ xᵀHx − bᵀx on [0, 1]: the gradient Hx − b is zero inside, ≥ 0 at
        // zero, ≤ 0 at one.
        for (i, (&xi, row)) in x.iter().zip(&dense).enumerate() {
            assert!((-1e-9..=1.0 + 1e-9).contains(&xi), "{i}: {xi}");
            let g: f64 = row.iter().zip(&x).map(|(a, b)| a * b).sum::<f64>() - b[i];
            if xi > 1e-9 && xi < 1.0 - 1e-9 {
                assert!(g.abs() < 1e-9, "{i}: {g}");
            } else if xi <= 1e-9 {
                assert!(g > -1e-9, "{i}: {g}");
            } else {
                assert!(g < 1e-9, "{i}: {g}");
            }
        }
    }
}
