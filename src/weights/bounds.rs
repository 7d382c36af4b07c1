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
//! most violating vertices (a block of up to [`BLOCK_ADD`], or one when a block makes no
//! progress), step back while a multiplier would change sign (its vertex leaves P), so it ends
//! in finitely many steps. The entries of H⁻¹ come from forward solves along the elimination
//! tree ([`super::inverse_entries`], a few percent of a solve per vertex), and each step's
//! new x from one backward solve; the dense system is |P|², |P| a few dozen.
//!
//! In: the factored support matrix, x₀ (in the support's order). Out: x within the bounds up
//! to [`BOUND_SLACK`], the held vertices exactly on theirs, and how many are held.

use super::inverse_entries::{ForwardColumn, InverseEntries};
use super::sparse::PatternCholesky;
use nalgebra::{DMatrix, DVector};
use std::collections::HashMap;

/// A solved vertex is held at a bound when it is past it by more than this.
pub const BOUND_SLACK: f64 = 1e-9;

/// The most vertices added per handle over all active-set steps (one vertex per step took
/// 3–270 steps on the critter rigs at 5k–20k vertices). Past it the solve is left
/// unconstrained (and clamped by the caller).
pub const MAX_BOUND_STEPS: usize = 2000;

/// The most violating vertices added to the held set at once. Lawson and Hanson add one per
/// step, and each step costs a backward solve over the whole support; the vertices around a
/// handle overshoot together (a plateau at one), so adding the worst of them in one step and
/// letting the step-back release those that do not belong takes a few steps instead of one per
/// held vertex. When no vertex of a block stays held, the next step adds one, as Lawson and
/// Hanson do, which is what guarantees progress.
pub const BLOCK_ADD: usize = 64;

/// Holds `x` (the unconstrained solution on the factored support, in the support's order) at
/// its bounds where it leaves them (see the module doc); returns how many vertices are held,
/// or `None` when the steps ran out or the held set's matrix lost definiteness (then `x` is
/// left as it was).
pub fn hold_bounds(factor: &PatternCholesky<'_>, x: &mut [f64]) -> Option<usize> {
    let n = x.len();
    let inverse = InverseEntries::new(factor)?;
    let x0 = x.to_vec();
    let past = |v: f64| (v - 1.0).max(-v);
    let mut held = Held::default();
    let mut is_held = vec![false; n];
    // Forward columns L⁻¹ eₖ and entries of H⁻¹, kept once computed: a vertex the step-back
    // releases is often held again.
    let mut forward: HashMap<usize, ForwardColumn> = HashMap::new();
    let mut entries: HashMap<(usize, usize), f64> = HashMap::new();
    let mut current = x0.clone();
    let (mut steps, mut one_at_a_time) = (0, false);
    while steps < MAX_BOUND_STEPS {
        let mut violators: Vec<usize> = (0..n)
            .filter(|&k| !is_held[k] && past(current[k]) > BOUND_SLACK)
            .collect();
        if violators.is_empty() {
            x.copy_from_slice(&current);
            return Some(held.vertex.len());
        }
        violators.sort_by(|&a, &b| {
            past(current[b])
                .total_cmp(&past(current[a]))
                .then(a.cmp(&b))
        });
        violators.truncate(if one_at_a_time { 1 } else { BLOCK_ADD });
        steps += violators.len();
        let before = held.vertex.len();
        for &k in &violators {
            forward.entry(k).or_insert_with(|| inverse.forward(k));
            held.push(k, if current[k] > 0.5 { 1.0 } else { -1.0 });
            is_held[k] = true;
        }
        // Added vertices whose multiplier comes out negative would leave their bound at once:
        // they are not added.
        let mut z = loop {
            let z = held.multipliers(&x0, &forward, &mut entries)?;
            let keep: Vec<bool> = (0..z.len()).map(|r| r < before || z[r] > 0.0).collect();
            if keep.iter().all(|&k| k) {
                break z;
            }
            for (r, _) in keep.iter().enumerate().filter(|(_, &k)| !k) {
                is_held[held.vertex[r]] = false;
            }
            held.retain(&keep);
        };
        if held.vertex.len() == before {
            if one_at_a_time {
                // Rounding: the worst violator's multiplier is not positive; what is held so
                // far stands and the caller clamps the rest.
                x.copy_from_slice(&current);
                return Some(held.vertex.len());
            }
            one_at_a_time = true;
            continue;
        }
        one_at_a_time = false;
        // Step back while a multiplier would turn negative (Lawson and Hanson).
        loop {
            if z.iter().all(|&v| v > 0.0) {
                held.mu.copy_from_slice(&z);
                break;
            }
            let alpha = z
                .iter()
                .zip(&held.mu)
                .filter(|(&zk, _)| zk <= 0.0)
                .map(|(&zk, &mk)| mk / (mk - zk))
                .fold(1.0, f64::min);
            for (mk, &zk) in held.mu.iter_mut().zip(&z) {
                *mk += alpha * (zk - *mk);
            }
            let keep: Vec<bool> = held.mu.iter().map(|&m| m > 0.0).collect();
            for (r, _) in keep.iter().enumerate().filter(|(_, &k)| !k) {
                is_held[held.vertex[r]] = false;
            }
            held.retain(&keep);
            if held.vertex.is_empty() {
                break;
            }
            z = held.multipliers(&x0, &forward, &mut entries)?;
        }
        // x = x₀ − H⁻¹ Σ λₖ eₖ, one backward solve.
        let terms: Vec<(&ForwardColumn, f64)> = held
            .vertex
            .iter()
            .zip(held.sign.iter().zip(&held.mu))
            .filter_map(|(k, (s, m))| Some((forward.get(k)?, s * m)))
            .collect();
        let shift = inverse.combination(&terms);
        for ((c, &x0k), &d) in current.iter_mut().zip(&x0).zip(&shift) {
            *c = x0k - d;
        }
    }
    None
}

/// The held vertices (support positions), the bound each is held at (+1: one, −1: zero) and
/// their multipliers (sign-free, positive).
#[derive(Default)]
struct Held {
    vertex: Vec<usize>,
    sign: Vec<f64>,
    mu: Vec<f64>,
}

impl Held {
    fn push(&mut self, k: usize, sign: f64) {
        self.vertex.push(k);
        self.sign.push(sign);
        self.mu.push(0.0);
    }

    fn retain(&mut self, keep: &[bool]) {
        let mut at = 0;
        for (r, &k) in keep.iter().enumerate() {
            if k {
                self.vertex[at] = self.vertex[r];
                self.sign[at] = self.sign[r];
                self.mu[at] = self.mu[r];
                at += 1;
            }
        }
        self.vertex.truncate(at);
        self.sign.truncate(at);
        self.mu.truncate(at);
    }

    /// The multipliers that put every held vertex exactly on its bound: the solution z of
    /// (S E_Pᵀ H⁻¹ E_P S) z = S (x₀[P] − bound), S the signs; `None` when that matrix is not
    /// positive definite.
    fn multipliers(
        &self,
        x0: &[f64],
        forward: &HashMap<usize, ForwardColumn>,
        entries: &mut HashMap<(usize, usize), f64>,
    ) -> Option<Vec<f64>> {
        let p = self.vertex.len();
        let mut m = DMatrix::zeros(p, p);
        for r in 0..p {
            for c in 0..=r {
                let (a, b) = (self.vertex[r], self.vertex[c]);
                let key = (a.min(b), a.max(b));
                let entry = match entries.get(&key) {
                    Some(&e) => e,
                    None => {
                        let e = forward.get(&a)?.dot(forward.get(&b)?);
                        entries.insert(key, e);
                        e
                    }
                };
                m[(r, c)] = self.sign[r] * self.sign[c] * entry;
                m[(c, r)] = m[(r, c)];
            }
        }
        // The bound is 1 for sign +1, 0 for sign −1: (1 + sign) / 2.
        let rhs = DVector::from_fn(p, |r, _| {
            let (k, s) = (self.vertex[r], self.sign[r]);
            s * (x0[k] - 0.5 * (1.0 + s))
        });
        Some(m.cholesky()?.solve(&rhs).as_slice().to_vec())
    }
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
