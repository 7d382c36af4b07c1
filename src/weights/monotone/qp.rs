//! One handle's QP for the monotone solve (step 3 of the parent module): the parts shared by
//! every handle ([`Problem`]: the bi-Laplacian, free vertices, clarabel's scaled P), the linear
//! term from the fixed values, and the solve by clarabel (interior point) with the ties as
//! equalities and the bounds and inequalities as a nonnegative cone.

use super::constraints::Reference;
use super::extrema::Rings;
use super::MonotoneOptions;
use crate::weights::solve::{BoundaryConditions, Domain};
use crate::weights::sparse::SolveError;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use sprs::CsMat;
use std::collections::BTreeSet;

/// The parts of the QP shared by every handle.
pub(super) struct Problem {
    /// The bi-Laplacian Q.
    pub(super) q: CsMat<f64>,
    /// Free vertices, ascending, and each vertex's position among them (`usize::MAX`: fixed).
    pub(super) free: Vec<usize>,
    pub(super) column_of: Vec<usize>,
    pub(super) is_fixed: Vec<bool>,
    /// The upper triangle of Q[free, free] · `scale`, clarabel's P.
    pub(super) p: CscMatrix<f64>,
    /// Scales the objective to unit diagonal magnitude: the minimizer is unchanged and
    /// clarabel's absolute gap tolerance means the same on any mesh size.
    pub(super) scale: f64,
    pub(super) rings: Rings,
}

impl Problem {
    pub(super) fn new(domain: &Domain, bc: &BoundaryConditions) -> Self {
        let q = domain.bilaplacian();
        let n = q.rows();
        let mut is_fixed = vec![false; n];
        for &v in &bc.vertices {
            is_fixed[v] = true;
        }
        let free: Vec<usize> = (0..n).filter(|&i| !is_fixed[i]).collect();
        let mut column_of = vec![usize::MAX; n];
        for (c, &i) in free.iter().enumerate() {
            column_of[i] = c;
        }
        let largest_diagonal = free
            .iter()
            .filter_map(|&i| q.get(i, i))
            .fold(0.0, |a: f64, &b| a.max(b.abs()));
        let scale = if largest_diagonal > 0.0 {
            1.0 / largest_diagonal
        } else {
            1.0
        };
        let (mut pi, mut pj, mut pv) = (Vec::new(), Vec::new(), Vec::new());
        for (r, &i) in free.iter().enumerate() {
            let Some(row) = q.outer_view(i) else { continue };
            for (k, &value) in row.iter() {
                let c = column_of[k];
                if c != usize::MAX && c >= r {
                    pi.push(r);
                    pj.push(c);
                    pv.push(value * scale);
                }
            }
        }
        let p = CscMatrix::new_from_triplets(free.len(), free.len(), pi, pj, pv);
        let rings = Rings::from_pattern(&domain.stiffness);
        Problem {
            q,
            free,
            column_of,
            is_fixed,
            p,
            scale,
            rings,
        }
    }
}

/// clarabel's linear term: Q[free, fixed] · (fixed values), scaled like P. `values` holds the
/// fixed values at fixed vertices.
pub(super) fn linear_term(problem: &Problem, values: &[f64]) -> Vec<f64> {
    problem
        .free
        .iter()
        .map(|&i| {
            problem.q.outer_view(i).map_or(0.0, |row| {
                row.iter()
                    .filter(|&(k, _)| problem.is_fixed[k])
                    .map(|(k, &value)| value * values[k])
                    .sum::<f64>()
                    * problem.scale
            })
        })
        .collect()
}

/// Solves one handle's QP; returns the full column (fixed values from the reference, free
/// values clamped to [0, 1]) and whether clarabel reached only reduced accuracy.
pub(super) fn solve_qp(
    problem: &Problem,
    reference: &Reference,
    linear: &[f64],
    inequalities: &BTreeSet<(usize, usize)>,
    options: &MonotoneOptions,
) -> Result<(Vec<f64>, bool), SolveError> {
    let f = problem.free.len();
    let mut w: Vec<f64> = reference
        .value
        .iter()
        .zip(&problem.is_fixed)
        .map(|(&x, &fixed)| if fixed { x } else { 0.0 })
        .collect();
    if f == 0 {
        return Ok((w, false));
    }
    let (mut ai, mut aj, mut av) = (Vec::new(), Vec::new(), Vec::new());
    let mut b = Vec::new();
    // One row w(a) − w(b) (+ slack) = rhs, the fixed ends moved to the right-hand side; none
    // when both ends are fixed (nothing to constrain).
    let mut difference_row = |lo: usize, hi: usize, b: &mut Vec<f64>| {
        if problem.is_fixed[lo] && problem.is_fixed[hi] {
            return;
        }
        let row = b.len();
        let mut rhs = 0.0;
        for (vertex, sign) in [(lo, 1.0), (hi, -1.0)] {
            match problem.column_of[vertex] {
                usize::MAX => rhs -= sign * w[vertex],
                c => {
                    ai.push(row);
                    aj.push(c);
                    av.push(sign);
                }
            }
        }
        b.push(rhs);
    };
    // Rows: the ties (zero cone), then −w ≤ 0, w ≤ 1 and the inequalities (nonnegative cone).
    for &(lo, hi) in &reference.ties {
        difference_row(lo, hi, &mut b);
    }
    let equalities = b.len();
    for &(lo, hi) in inequalities {
        difference_row(lo, hi, &mut b);
    }
    for c in 0..f {
        let row = b.len();
        ai.extend([row, row + 1]);
        aj.extend([c, c]);
        av.extend([-1.0, 1.0]);
        b.extend([0.0, 1.0]);
    }
    let rows = b.len();
    let a = CscMatrix::new_from_triplets(rows, f, ai, aj, av);
    let mut cones = Vec::new();
    if equalities > 0 {
        cones.push(SupportedConeT::ZeroConeT(equalities));
    }
    cones.push(SupportedConeT::NonnegativeConeT(rows - equalities));
    let tol = options.solver_tolerance;
    let settings = DefaultSettings::<f64> {
        verbose: false,
        max_iter: options.max_solver_iterations,
        tol_gap_abs: tol,
        tol_gap_rel: tol,
        tol_feas: tol,
        // Handles already run in parallel; a sequential factorization per solve keeps the
        // cores for them and the results deterministic.
        max_threads: 1,
        ..DefaultSettings::default()
    };
    let mut solver = DefaultSolver::new(&problem.p, linear, &a, &b, &cones, settings)
        .map_err(|e| SolveError::Assembly(format!("clarabel: {e:?}")))?;
    solver.solve();
    let status = solver.solution.status;
    if !matches!(status, SolverStatus::Solved | SolverStatus::AlmostSolved) {
        return Err(SolveError::Assembly(format!("clarabel: {status:?}")));
    }
    // Clamping is monotone, so it keeps every w(a) ≤ w(b) the solver satisfied.
    for (c, &i) in problem.free.iter().enumerate() {
        w[i] = solver.solution.x[c].clamp(0.0, 1.0);
    }
    Ok((w, status == SolverStatus::AlmostSolved))
}
