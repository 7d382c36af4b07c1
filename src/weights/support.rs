//! Bounded biharmonic weights from a close guess: one solve per handle on the guess's support.
//!
//! A bounded biharmonic weight is, where it is strictly between its bounds, the solution of
//! the unconstrained biharmonic equation with the weight held at its bound outside that
//! region. So if the region where handle j's weight is strictly inside (0, 1) were known, one
//! sparse Cholesky solve of Q[S_j, S_j] (Q the bi-Laplacian, S_j the region's free vertices)
//! with the bounds held outside would give the fine solution exactly. Weights carried from a coarse
//! solve of the same domain ([`super::two_level`]) give that region closely: where the carried
//! weight is more than a small floor ([`SUPPORT_FLOOR`]) inside both bounds (interpolation
//! smears a thin fringe past the true edge, which the floor cuts), it is solved once, with
//! zero held below the floor and one above one minus the floor. Where that solve leaves
//! [0, 1] (the plateau at one around an interior point handle or a bone, which the coarse
//! solve does not resolve, and dips below zero near bones), the bounded problem on the support
//! is solved exactly by a Schur complement over the same factorization ([`super::bounds`]),
//! then the result is clamped to [0, 1]. Unlike active-set iterations on the whole mesh
//! ([`super::active_set`]), nothing has to settle: the error left is where the carried
//! support's edge misses the fine solution's, where the weight is near zero anyway.
//!
//! Cost per handle: one numeric factorization of its support only (about half the mesh on the
//! benchmark sprites with 10 handles), over a fill-reducing order computed once for the whole
//! mesh and restricted to each support, so no per-handle minimum-degree analysis.
//!
//! In: the fine [`Domain`], its [`BoundaryConditions`], the guess (one row per vertex), and
//! the support floor. Out: the weight columns clamped to [0, 1] (rows not yet normalized).

use super::bounds::hold_bounds;
use super::solve::{check_reachable, fixed_column, free_vertices};
use super::solve::{BoundaryConditions, Domain, WeightMatrix};
use super::sparse::{fill_reducing_rank, mat_vec, SharedPattern, SolveError};
use rayon::prelude::*;
use sprs::CsMat;

/// Default support floor: a free vertex whose guessed weight exceeds this is solved for, the
/// others are held at zero. Measured on the critter at 5k, 20k and 50k vertices with 10
/// handles from a 500-vertex coarse solve: 1e-3 leaves max |Δw| 0.013–0.016 against the exact
/// solve, 1e-2 leaves 0.06–0.08 (the true support reaches into the carried weights' 1e-3–1e-2
/// fringe), 0 solves on nearly every vertex (the interpolated fringe covers the mesh) and
/// leaves overshoot below zero past the support's edge.
pub const SUPPORT_FLOOR: f64 = 1e-3;

/// One solve per handle on the support of `guess` (see the module doc); vertices fixed by
/// `bc` keep their values.
pub fn support_bbw(
    domain: &Domain,
    bc: &BoundaryConditions,
    guess: &WeightMatrix,
    support_floor: f64,
) -> Result<WeightMatrix, SolveError> {
    SupportSolver::new(domain, bc)?.solve(guess, support_floor)
}

/// What [`support_bbw`] prepares before it sees the guess (the bi-Laplacian and one
/// fill-reducing order of the whole mesh), so that a caller can prepare it while the guess is
/// still being computed (the coarse solve, [`super::two_level`]).
pub struct SupportSolver {
    q: CsMat<f64>,
    bc: BoundaryConditions,
    free: Vec<usize>,
    rank: Vec<usize>,
}

impl SupportSolver {
    pub fn new(domain: &Domain, bc: &BoundaryConditions) -> Result<Self, SolveError> {
        let q = domain.bilaplacian();
        check_reachable(&q, bc)?;
        let free = free_vertices(q.rows(), bc);
        let rank = fill_reducing_rank(&q, &free)?;
        Ok(SupportSolver {
            q,
            bc: bc.clone(),
            free,
            rank,
        })
    }

    /// [`support_bbw`] with `guess` (one row per vertex of the domain).
    pub fn solve(
        &self,
        guess: &WeightMatrix,
        support_floor: f64,
    ) -> Result<WeightMatrix, SolveError> {
        let (q, bc, free, rank) = (&self.q, &self.bc, &self.free, &self.rank);
        let n = q.rows();
        let columns: Vec<Result<Vec<f64>, SolveError>> = (0..bc.handle_count)
            .into_par_iter()
            .map(|j| {
                let mut w = fixed_column(n, bc, j);
                if w.iter().all(|&x| x == 0.0) {
                    // Zero boundary values: zero is optimal and feasible.
                    return Ok(w);
                }
                // Held at one where the guess is within the floor of it (a handle alone in a
                // region of the domain owns it), at zero below the floor, solved in between.
                let mut support = Vec::new();
                for &i in free {
                    let g = guess.get(i, j);
                    if g >= 1.0 - support_floor {
                        w[i] = 1.0;
                    } else if g > support_floor {
                        support.push(i);
                    }
                }
                if support.is_empty() {
                    return Ok(w);
                }
                // Q[S, S] x = −Q[S, held] · held values (the held zeros add nothing).
                let qw = mat_vec(q, &w);
                let mut x: Vec<f64> = support.iter().map(|&i| -qw[i]).collect();
                let pattern = SharedPattern::with_rank(q, &support, rank)?;
                let factor = pattern.factor_regularized(&pattern.values)?;
                factor.solve_in_place(&mut x);
                // Where the solve leaves its bounds, hold it at them (the bounded problem on
                // this support, solved exactly); when the steps run out, clamped as it is.
                hold_bounds(&factor, &mut x);
                for (&i, v) in support.iter().zip(x) {
                    w[i] = v.clamp(0.0, 1.0);
                }
                Ok(w)
            })
            .collect();
        let columns = columns.into_iter().collect::<Result<Vec<_>, _>>()?;
        Ok(WeightMatrix::from_columns(n, &columns))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weights::solve::tests::{largest_difference, three_points};
    use crate::weights::solve::{bounded_biharmonic_weights, BbwOptions};

    #[test]
    fn on_the_exact_support_one_solve_gives_the_exact_weights() {
        let (domain, bc, n) = three_points();
        let (exact, _) = bounded_biharmonic_weights(&domain, &bc, &BbwOptions::default()).unwrap();
        // The exact weights' own support: the solve reproduces them (up to the interior
        // point's tolerance).
        let same = support_bbw(&domain, &bc, &exact, 1e-7).unwrap();
        let d = largest_difference(&same, &exact);
        assert!(d < 1e-4, "{d}");
        assert_eq!(same.vertex_count, n);
        // A guess off by up to 0.05 inside (floor, 1 − floor) (a coarse solve's error) with
        // the same sets: the solve reads only the sets, not the values.
        let floor = 1e-3;
        let mut rough = exact.clone();
        for (i, x) in rough.data.iter_mut().enumerate() {
            if *x > floor && *x < 1.0 - floor {
                *x = (*x + 0.05 * ((i % 7) as f64 / 7.0 - 0.5))
                    .clamp(2.0 * floor, 1.0 - 2.0 * floor);
            }
        }
        assert!(largest_difference(&rough, &exact) > 0.02);
        let from_rough = support_bbw(&domain, &bc, &rough, floor).unwrap();
        let from_exact = support_bbw(&domain, &bc, &exact, floor).unwrap();
        assert_eq!(from_rough, from_exact);
        // Holding the fringe below the floor at zero costs little.
        let d = largest_difference(&from_exact, &exact);
        assert!(d < 0.05, "{d}");
    }
}
