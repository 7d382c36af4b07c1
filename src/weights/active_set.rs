//! Bounded biharmonic weights from a close guess: primal–dual active-set iterations.
//!
//! The bounded QP of each handle, min ½ xᵀ H x + gᵀ x with 0 ≤ x ≤ 1 (H = Q[F, F] over the free
//! vertices, g = Q[F, fixed] · fixed values, as in [`super::solve::bounded_biharmonic_weights`]),
//! is solved by the primal–dual active-set method (Hintermüller, Ito & Kunisch 2002, a
//! semismooth Newton method): guess which vertices sit on a bound, solve the equality-
//! constrained problem, move to the bound the vertices that crossed it and release those whose
//! multiplier has the wrong sign, until the sets repeat. From the sets of a good guess (weights
//! solved on a coarse mesh of the same domain, [`super::two_level`]) it settles in a few
//! iterations, each one numeric Cholesky factorization over the one symbolic analysis every
//! handle shares. Vertices on a bound are held there by a stiff diagonal penalty, which keeps
//! the matrix's pattern.
//!
//! In: the [`Domain`], the [`BoundaryConditions`], a guess over every vertex and an iteration
//! limit. Out: the weight columns, clamped to [0, 1] (not yet normalized), and the handles whose
//! sets had not settled at the limit.

use super::solve::{
    check_reachable, fixed_column, free_vertices, BoundaryConditions, Domain, WeightMatrix,
};
use super::sparse::{mat_vec, SharedPattern, SolveError};
use rayon::prelude::*;

/// A guess within this of a bound puts its vertex on that bound.
pub const ON_BOUND: f64 = 1e-6;

/// A vertex on a bound is held there by adding this many times its diagonal entry to it: its
/// value then misses the bound by about 1e-10 of its neighbours' pull, below what the weights'
/// clamping and `min_weight` see.
pub const BOUND_PENALTY: f64 = 1e10;

/// A free vertex moves to a bound when it crosses it by more than this, and a vertex on a
/// bound is released when its multiplier has the wrong sign by more than this fraction of the
/// linear term's largest entry.
pub const SET_SLACK: f64 = 1e-9;

/// The polished weights and the handles whose active sets had not settled.
pub fn active_set_bbw(
    domain: &Domain,
    bc: &BoundaryConditions,
    guess: &WeightMatrix,
    max_iterations: usize,
) -> Result<(WeightMatrix, Vec<usize>), SolveError> {
    let q = domain.bilaplacian();
    let n = q.rows();
    check_reachable(&q, bc)?;
    let free = free_vertices(n, bc);
    let pattern = SharedPattern::new(&q, &free)?;
    let results: Vec<Result<(Vec<f64>, bool), SolveError>> = (0..bc.handle_count)
        .into_par_iter()
        .map(|j| {
            let mut w = fixed_column(n, bc, j);
            if w.iter().all(|&x| x == 0.0) {
                // Zero boundary values: zero is optimal and feasible.
                return Ok((w, true));
            }
            let qw = mat_vec(&q, &w);
            let g: Vec<f64> = free.iter().map(|&i| qw[i]).collect();
            let start: Vec<f64> = free.iter().map(|&i| guess.get(i, j)).collect();
            let (x, settled) = solve_handle(&pattern, &g, &start, max_iterations)?;
            for (k, &i) in free.iter().enumerate() {
                w[i] = x[k];
            }
            Ok((w, settled))
        })
        .collect();
    let mut columns = Vec::with_capacity(bc.handle_count);
    let mut unsettled = Vec::new();
    for (j, r) in results.into_iter().enumerate() {
        let (w, settled) = r?;
        columns.push(w);
        if !settled {
            unsettled.push(j);
        }
    }
    Ok((WeightMatrix::from_columns(n, &columns), unsettled))
}

/// Which bound a free vertex sits on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Bound {
    Free,
    Lower,
    Upper,
}

/// One handle's active-set iterations from `start`; returns x clamped to [0, 1] and whether
/// the sets settled.
fn solve_handle(
    pattern: &SharedPattern,
    g: &[f64],
    start: &[f64],
    max_iterations: usize,
) -> Result<(Vec<f64>, bool), SolveError> {
    let mut sets: Vec<Bound> = start
        .iter()
        .map(|&x| {
            if x <= ON_BOUND {
                Bound::Lower
            } else if x >= 1.0 - ON_BOUND {
                Bound::Upper
            } else {
                Bound::Free
            }
        })
        .collect();
    let mut x = start.to_vec();
    let mut settled = false;
    for _ in 0..max_iterations {
        let mut values = pattern.values.clone();
        let mut rhs: Vec<f64> = g.iter().map(|v| -v).collect();
        for (k, set) in sets.iter().enumerate() {
            if *set == Bound::Free {
                continue;
            }
            let penalty = BOUND_PENALTY * pattern.values[pattern.diagonal[k]];
            values[pattern.diagonal[k]] += penalty;
            if *set == Bound::Upper {
                rhs[k] += penalty;
            }
        }
        pattern.factor(&values)?.solve_in_place(&mut rhs);
        x = rhs;
        // The multipliers: the gradient of the unpenalized energy.
        let gradient: Vec<f64> = pattern
            .mat_vec(&pattern.values, &x)
            .iter()
            .zip(g)
            .map(|(hx, g)| hx + g)
            .collect();
        // Degenerate vertices (on a bound with a zero multiplier, deep in a region where a
        // weight vanishes) would flip on rounding: only clear violations move a vertex.
        let grad_slack = SET_SLACK * g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let next: Vec<Bound> = sets
            .iter()
            .zip(x.iter().zip(&gradient))
            .map(|(&set, (&x, &grad))| match set {
                // On a bound: stays while its multiplier pushes against the bound.
                Bound::Lower if grad >= -grad_slack => Bound::Lower,
                Bound::Upper if grad <= grad_slack => Bound::Upper,
                Bound::Lower | Bound::Upper => Bound::Free,
                // Free: goes to the bound it crossed.
                Bound::Free if x < -SET_SLACK => Bound::Lower,
                Bound::Free if x > 1.0 + SET_SLACK => Bound::Upper,
                Bound::Free => Bound::Free,
            })
            .collect();
        if next == sets {
            settled = true;
            break;
        }
        sets = next;
    }
    Ok((x.iter().map(|v| v.clamp(0.0, 1.0)).collect(), settled))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weights::solve::tests::{largest_difference, three_points};
    use crate::weights::solve::{bounded_biharmonic_weights, BbwOptions};

    #[test]
    fn from_a_rough_guess_the_sets_settle_on_the_interior_point_answer() {
        let (domain, bc, n) = three_points();
        let (exact, _) = bounded_biharmonic_weights(&domain, &bc, &BbwOptions::default()).unwrap();
        // From the answer itself: settles at once, on it.
        let (same, unsettled) = active_set_bbw(&domain, &bc, &exact, 3).unwrap();
        assert!(unsettled.is_empty());
        assert!(
            largest_difference(&same, &exact) < 1e-4,
            "{}",
            largest_difference(&same, &exact)
        );
        // From the answer blurred (a coarse solve's error): a few iterations.
        let mut rough = exact.clone();
        for (i, x) in rough.data.iter_mut().enumerate() {
            *x = (*x + 0.05 * ((i % 7) as f64 / 7.0 - 0.5)).clamp(0.0, 1.0);
        }
        let (polished, unsettled) = active_set_bbw(&domain, &bc, &rough, 20).unwrap();
        assert!(unsettled.is_empty(), "{unsettled:?}");
        let d = largest_difference(&polished, &exact);
        assert!(d < 1e-4, "{d}");
        assert_eq!(polished.vertex_count, n);
    }
}
