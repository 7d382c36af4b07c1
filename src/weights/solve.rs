//! Harmonic, biharmonic and bounded biharmonic weights over a discretized domain.
//!
//! In: a [`Domain`] (cotangent stiffness K and lumped mass M of a mesh, flat or 5D-lifted) and
//! [`BoundaryConditions`] (the weight vector fixed at every handle vertex). Out: a dense
//! [`WeightMatrix`], one column per handle.
//!
//! - Harmonic: minimize wᵀ K w per handle (a Laplace solve).
//! - Biharmonic: minimize wᵀ K M⁻¹ K w per handle (a bi-Laplace solve), no bounds.
//! - Bounded biharmonic (Jacobson, Baran, Popović & Sorkine 2011, "Bounded Biharmonic Weights
//!   for Real-Time Deformation"): the biharmonic energy subject to 0 ≤ w ≤ 1, per handle, then
//!   rows normalized to sum to one. Solved by a primal–dual interior-point method (Mehrotra's
//!   predictor–corrector) started from the unconstrained biharmonic solution; its Newton
//!   systems all share one sparsity pattern, analyzed once. (A primal–dual active-set method
//!   was tried first: on the bi-Laplacian, which is not an M-matrix, it cycled.) Handles solve
//!   in parallel (rayon).
//!
//! Also tried and measured slower (see ARCHITECTURE.md, "weights: what did not pay"): a
//! Goldfarb–Idnani dual active-set method over one shared factorization of H with the columns
//! of H⁻¹ it needs (it needs thousands: the unconstrained minimum violates a bound on about
//! half the vertices, and the dual path visits far more bounds than end up active), also
//! seeded from a few interior-point iterations; a forced simplicial factorization; a
//! breadth-first nested-dissection ordering instead of faer's AMD.
//!
//! Every vertex of every connected piece of the domain must be reached by some handle vertex;
//! otherwise the systems are singular and the solve reports [`SolveError::Unreachable`].

use super::laplacian::{cotangent_stiffness, squared_edge_lengths, voronoi_mass};
use super::sparse::{mat_vec, sandwich_diagonal, SharedPattern, SolveError, SubmatrixCholesky};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sprs::CsMat;

/// The discretized weight domain.
#[derive(Clone, Debug)]
pub struct Domain {
    /// Cotangent stiffness K = −L (symmetric positive semi-definite).
    pub stiffness: CsMat<f64>,
    /// Lumped mixed-Voronoi mass per vertex.
    pub mass: Vec<f64>,
}

impl Domain {
    /// A domain measured by its points' coordinates (2D: canvas px; 5D: the content-aware lift).
    pub fn new<const D: usize>(points: &[[f64; D]], triangles: &[[u32; 3]]) -> Self {
        let l2 = squared_edge_lengths(points, triangles);
        Domain {
            stiffness: cotangent_stiffness(points.len(), triangles, &l2),
            mass: voronoi_mass(points.len(), triangles, &l2),
        }
    }

    /// [`Domain::new`] of canvas positions (px).
    pub fn planar(points: &[crate::geom::Point], triangles: &[[u32; 3]]) -> Self {
        Domain::new(crate::geom::as_coordinate_arrays(points), triangles)
    }

    pub fn vertex_count(&self) -> usize {
        self.mass.len()
    }

    /// The bi-Laplacian Q = K M⁻¹ K.
    pub fn bilaplacian(&self) -> CsMat<f64> {
        // A vertex of no triangle has no mass; it is fixed by a handle or unreachable anyway.
        let inverse_mass: Vec<f64> = self
            .mass
            .iter()
            .map(|&m| if m > 0.0 { 1.0 / m } else { 0.0 })
            .collect();
        sandwich_diagonal(&self.stiffness, &inverse_mass)
    }
}

/// Weights fixed at handle vertices: `values[k * handle_count + j]` is handle j's weight at
/// vertex `vertices[k]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BoundaryConditions {
    pub handle_count: usize,
    pub vertices: Vec<usize>,
    pub values: Vec<f64>,
}

impl BoundaryConditions {
    /// Fixes `vertex` to weight 1 for `handle` and 0 for every other handle.
    pub fn fix_to_handle(&mut self, vertex: usize, handle: usize) {
        self.fix(vertex, &[(handle, 1.0)]);
    }

    /// Fixes `vertex` to the given (handle, weight) pairs, 0 for every other handle.
    pub fn fix(&mut self, vertex: usize, weights: &[(usize, f64)]) {
        self.vertices.push(vertex);
        let start = self.values.len();
        self.values.resize(start + self.handle_count, 0.0);
        for &(j, w) in weights {
            self.values[start + j] = w;
        }
    }
}

/// A dense n × m weight matrix, row-major: `get(i, j)` is handle j's weight at vertex i.
#[derive(Clone, Debug, PartialEq)]
pub struct WeightMatrix {
    pub vertex_count: usize,
    pub handle_count: usize,
    pub data: Vec<f64>,
}

impl WeightMatrix {
    pub fn get(&self, vertex: usize, handle: usize) -> f64 {
        self.data[vertex * self.handle_count + handle]
    }

    pub fn row(&self, vertex: usize) -> &[f64] {
        &self.data[vertex * self.handle_count..(vertex + 1) * self.handle_count]
    }

    pub fn column(&self, handle: usize) -> Vec<f64> {
        (0..self.vertex_count)
            .map(|i| self.get(i, handle))
            .collect()
    }

    pub(super) fn from_columns(vertex_count: usize, columns: &[Vec<f64>]) -> Self {
        let handle_count = columns.len();
        let mut data = vec![0.0; vertex_count * handle_count];
        for (j, col) in columns.iter().enumerate() {
            for (i, &v) in col.iter().enumerate() {
                data[i * handle_count + j] = v;
            }
        }
        WeightMatrix {
            vertex_count,
            handle_count,
            data,
        }
    }

    /// Scales every row to sum to one. Rows that sum to (almost) nothing are left as they are
    /// and returned, so the caller can fill them in.
    pub fn normalize_rows(&mut self) -> Vec<usize> {
        let mut empty = Vec::new();
        for i in 0..self.vertex_count {
            let row = &mut self.data[i * self.handle_count..(i + 1) * self.handle_count];
            let sum: f64 = row.iter().sum();
            if sum > EMPTY_ROW_SUM {
                row.iter_mut().for_each(|w| *w /= sum);
            } else {
                empty.push(i);
            }
        }
        empty
    }
}

/// A row summing to less than this has no meaningful direction to normalize.
pub const EMPTY_ROW_SUM: f64 = 1e-9;

/// Parameters of the bounded biharmonic solve (a primal–dual interior-point method).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct BbwOptions {
    /// Interior-point iterations per handle before giving up (the iterate is then clamped to
    /// the bounds and the handle reported as unconverged). Default 50.
    pub max_iterations: usize,
    /// Converged when the mean complementarity (x·z + (1−x)·w) / 2n falls below this, in the
    /// problem scaled so that the linear term's largest entry is 1. Default 1e-13.
    pub complementarity_tolerance: f64,
    /// … and the scaled gradient residual |Hx + g − z + w| below this in every row, or below
    /// that row's rounding floor where it is larger (see `residual_round_off`). Default 1e-10.
    pub residual_tolerance: f64,
    /// A row's gradient residual cannot be computed more exactly than a few rounding errors of
    /// its terms: its floor is this many machine epsilons of Σ_j |H_ij x_j| + |g_i| + z_i + w_i.
    /// Default 10 (measured: 0.1–4.5 once the residual stops falling). Handles with large
    /// |H||x| rows, such as the critter's hip bone and ring point (~3e6), never reach an
    /// absolute 1e-10 there and would run to the iteration limit; 0 turns the floor off.
    pub residual_round_off: f64,
    /// Weights this close to a bound are snapped onto it, so clamped regions are exactly 0 (or
    /// 1). Default 1e-8.
    pub snap_to_bound: f64,
}

impl Default for BbwOptions {
    fn default() -> Self {
        BbwOptions {
            max_iterations: 50,
            complementarity_tolerance: 1e-13,
            residual_tolerance: 1e-10,
            residual_round_off: 10.0,
            snap_to_bound: 1e-8,
        }
    }
}

/// How the bounded solve went, for reports and tests.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BbwReport {
    /// Interior-point iterations per handle.
    pub iterations: Vec<usize>,
    /// Handles that had not met the tolerances within the iteration limit.
    pub unconverged: Vec<usize>,
}

/// Free vertices (not fixed by a handle), in ascending order.
pub(super) fn free_vertices(n: usize, bc: &BoundaryConditions) -> Vec<usize> {
    let mut fixed = vec![false; n];
    for &v in &bc.vertices {
        fixed[v] = true;
    }
    (0..n).filter(|&i| !fixed[i]).collect()
}

/// Handle j's full-length weight column with the fixed values in place and zeros elsewhere.
pub(super) fn fixed_column(n: usize, bc: &BoundaryConditions, j: usize) -> Vec<f64> {
    let mut w = vec![0.0; n];
    for (k, &v) in bc.vertices.iter().enumerate() {
        w[v] = bc.values[k * bc.handle_count + j];
    }
    w
}

/// Fails when some vertex cannot be reached from a fixed vertex through the matrix's pattern
/// (the mesh's edges): the system would be singular there.
pub(super) fn check_reachable(a: &CsMat<f64>, bc: &BoundaryConditions) -> Result<(), SolveError> {
    let mut reached = vec![false; a.rows()];
    let mut stack: Vec<usize> = bc.vertices.clone();
    for &v in &stack {
        reached[v] = true;
    }
    while let Some(i) = stack.pop() {
        if let Some(row) = a.outer_view(i) {
            for (j, _) in row.iter() {
                if !reached[j] {
                    reached[j] = true;
                    stack.push(j);
                }
            }
        }
    }
    match reached.iter().filter(|&&r| !r).count() {
        0 => Ok(()),
        count => Err(SolveError::Unreachable { count }),
    }
}

/// Solves A[F, F] w_F = −A[F, :] w_fixed for every handle, with a shared factorization.
fn solve_quadratic(a: &CsMat<f64>, bc: &BoundaryConditions) -> Result<WeightMatrix, SolveError> {
    let n = a.rows();
    check_reachable(a, bc)?;
    let free = free_vertices(n, bc);
    let chol = SubmatrixCholesky::new(a, &free)?;
    let columns: Vec<Vec<f64>> = (0..bc.handle_count)
        .into_par_iter()
        .map(|j| {
            let mut w = fixed_column(n, bc, j);
            let aw = mat_vec(a, &w);
            let mut rhs: Vec<f64> = free.iter().map(|&i| -aw[i]).collect();
            chol.solve_in_place(&mut rhs);
            for (k, &i) in free.iter().enumerate() {
                w[i] = rhs[k];
            }
            w
        })
        .collect();
    Ok(WeightMatrix::from_columns(n, &columns))
}

/// Harmonic weights: per handle, minimize wᵀ K w with the boundary conditions. They sum to one
/// and stay in [0, 1] by the discrete maximum principle (on meshes without obtuse angles).
pub fn harmonic_weights(
    domain: &Domain,
    bc: &BoundaryConditions,
) -> Result<WeightMatrix, SolveError> {
    solve_quadratic(&domain.stiffness, bc)
}

/// Unconstrained biharmonic weights: per handle, minimize wᵀ K M⁻¹ K w. They sum to one but
/// overshoot [0, 1].
pub fn biharmonic_weights(
    domain: &Domain,
    bc: &BoundaryConditions,
) -> Result<WeightMatrix, SolveError> {
    solve_quadratic(&domain.bilaplacian(), bc)
}

/// Bounded biharmonic weights (not yet normalized: see [`WeightMatrix::normalize_rows`]).
///
/// Per handle, the box-constrained QP min ½ xᵀ H x + gᵀ x, 0 ≤ x ≤ 1 over the free vertices
/// (H = Q[F, F], g = Q[F, fixed] · fixed values) is solved by Mehrotra's predictor–corrector
/// interior-point method. Every Newton system is H plus a positive diagonal, so one symbolic
/// Cholesky analysis serves all handles and iterations; each iteration is one numeric
/// factorization and two solves.
pub fn bounded_biharmonic_weights(
    domain: &Domain,
    bc: &BoundaryConditions,
    options: &BbwOptions,
) -> Result<(WeightMatrix, BbwReport), SolveError> {
    let q = domain.bilaplacian();
    let n = q.rows();
    check_reachable(&q, bc)?;
    let free = free_vertices(n, bc);
    let pattern = SharedPattern::new(&q, &free)?;
    let unconstrained = pattern.factor_regularized(&pattern.values)?;
    // Per handle: the weight column, the iterations taken and whether they converged.
    type HandleSolve = (Vec<f64>, usize, bool);
    let results: Vec<Result<HandleSolve, SolveError>> = (0..bc.handle_count)
        .into_par_iter()
        .map(|j| {
            let mut w = fixed_column(n, bc, j);
            if w.iter().all(|&x| x == 0.0) {
                // Zero boundary values: zero is optimal and feasible.
                return Ok((w, 0, true));
            }
            let qw = mat_vec(&q, &w);
            let g: Vec<f64> = free.iter().map(|&i| qw[i]).collect();
            let mut start: Vec<f64> = g.iter().map(|v| -v).collect();
            unconstrained.solve_in_place(&mut start);
            let (x, iterations, converged) = box_qp_interior_point(&pattern, &g, &start, options)?;
            for (k, &i) in free.iter().enumerate() {
                w[i] = x[k];
            }
            Ok((w, iterations, converged))
        })
        .collect();
    let mut columns = Vec::with_capacity(bc.handle_count);
    let mut report = BbwReport::default();
    for (j, r) in results.into_iter().enumerate() {
        let (w, iterations, converged) = r?;
        columns.push(w);
        report.iterations.push(iterations);
        if !converged {
            report.unconverged.push(j);
        }
    }
    Ok((WeightMatrix::from_columns(n, &columns), report))
}

/// Whether every row's gradient residual `residual[i]` (of Hx + g − z + w) is below the
/// tolerance or that row's rounding floor (see [`BbwOptions::residual_round_off`]); `h_abs`
/// holds the scaled Hessian's absolute values.
#[allow(clippy::too_many_arguments)]
fn residual_converged(
    pattern: &SharedPattern,
    h_abs: &[f64],
    x: &[f64],
    g: &[f64],
    z: &[f64],
    w: &[f64],
    residual: &[f64],
    options: &BbwOptions,
) -> bool {
    if residual
        .iter()
        .all(|r| r.abs() < options.residual_tolerance)
    {
        return true;
    }
    let x_abs: Vec<f64> = x.iter().map(|v| v.abs()).collect();
    let hx_abs = pattern.mat_vec(h_abs, &x_abs);
    let round_off = options.residual_round_off * f64::EPSILON;
    (0..x.len()).all(|i| {
        let floor = round_off * (hx_abs[i] + g[i].abs() + z[i] + w[i]);
        residual[i].abs() < options.residual_tolerance.max(floor)
    })
}

/// Keeps interior-point iterates this far (relatively) from the bounds.
const FRACTION_TO_BOUNDARY: f64 = 0.995;
/// The starting point is the unconstrained solution pushed this far inside the box.
const START_MARGIN: f64 = 0.05;

/// Largest step α ≤ 1 keeping v + α·dv > 0 for every component, times the fraction-to-boundary.
fn max_step(v: impl Iterator<Item = (f64, f64)>) -> f64 {
    let limit = v
        .filter(|&(_, d)| d < 0.0)
        .map(|(x, d)| -x / d)
        .fold(f64::INFINITY, f64::min);
    (FRACTION_TO_BOUNDARY * limit).min(1.0)
}

/// The largest step along (dx, dz, dw) that keeps x, t = 1 − x, z and w positive.
fn step_length(
    x: &[f64],
    t: &[f64],
    z: &[f64],
    w: &[f64],
    dx: &[f64],
    dz: &[f64],
    dw: &[f64],
) -> f64 {
    let n = x.len();
    max_step((0..n).map(|i| (x[i], dx[i])))
        .min(max_step((0..n).map(|i| (t[i], -dx[i]))))
        .min(max_step((0..n).map(|i| (z[i], dz[i]))))
        .min(max_step((0..n).map(|i| (w[i], dw[i]))))
}

/// min ½ xᵀ H x + gᵀ x subject to 0 ≤ x ≤ 1, H given by `pattern` (SPD). Returns x, the
/// iterations taken and whether the tolerances were met.
fn box_qp_interior_point(
    pattern: &SharedPattern,
    g: &[f64],
    start: &[f64],
    options: &BbwOptions,
) -> Result<(Vec<f64>, usize, bool), SolveError> {
    let n = g.len();
    // Scale so the linear term's largest entry is 1: gradients and multipliers are then of
    // order one, and the absolute tolerances mean the same on any mesh and canvas size.
    let g_max = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if g_max == 0.0 {
        // H is positive definite: with no pull from the fixed values, zero is the optimum.
        return Ok((vec![0.0; n], 0, true));
    }
    let scale = 1.0 / g_max;
    let h: Vec<f64> = pattern.values.iter().map(|v| v * scale).collect();
    let g: Vec<f64> = g.iter().map(|v| v * scale).collect();
    let h_abs: Vec<f64> = h.iter().map(|v| v.abs()).collect();
    let mut x: Vec<f64> = start
        .iter()
        .map(|v| v.clamp(START_MARGIN, 1.0 - START_MARGIN))
        .collect();
    // The upper slack t = 1 − x is carried on its own: computed as 1 − x it would round to
    // zero for weights within 1e-16 of one.
    let mut t: Vec<f64> = x.iter().map(|v| 1.0 - v).collect();
    let mut z = vec![1.0; n];
    let mut w = vec![1.0; n];
    let mut values = h.clone();
    let mut converged = false;
    let mut iterations = 0;
    while iterations < options.max_iterations {
        let hx = pattern.mat_vec(&h, &x);
        let gradient: Vec<f64> = hx.iter().zip(&g).map(|(a, b)| a + b).collect();
        let mu = (0..n).map(|i| x[i] * z[i] + t[i] * w[i]).sum::<f64>() / (2 * n).max(1) as f64;
        if mu < options.complementarity_tolerance && {
            let residual: Vec<f64> = (0..n).map(|i| gradient[i] - z[i] + w[i]).collect();
            residual_converged(pattern, &h_abs, &x, &g, &z, &w, &residual, options)
        } {
            converged = true;
            break;
        }
        values.copy_from_slice(&h);
        for i in 0..n {
            values[pattern.diagonal[i]] += z[i] / x[i] + w[i] / t[i];
        }
        // Near the end the barrier terms span many orders of magnitude; if the factorization
        // breaks down there, the iterate is as good as this arithmetic allows.
        let Ok(chol) = pattern.factor(&values) else {
            break;
        };
        iterations += 1;
        // Predictor: the pure Newton (affine-scaling) direction.
        let mut dx_aff: Vec<f64> = gradient.iter().map(|v| -v).collect();
        chol.solve_in_place(&mut dx_aff);
        let dz_aff: Vec<f64> = (0..n).map(|i| -z[i] - z[i] / x[i] * dx_aff[i]).collect();
        let dw_aff: Vec<f64> = (0..n).map(|i| -w[i] + w[i] / t[i] * dx_aff[i]).collect();
        let alpha_aff = step_length(&x, &t, &z, &w, &dx_aff, &dz_aff, &dw_aff);
        let mu_aff = (0..n)
            .map(|i| {
                let (xa, ta) = (x[i] + alpha_aff * dx_aff[i], t[i] - alpha_aff * dx_aff[i]);
                xa * (z[i] + alpha_aff * dz_aff[i]) + ta * (w[i] + alpha_aff * dw_aff[i])
            })
            .sum::<f64>()
            / (2 * n) as f64;
        let sigma_mu = (mu_aff / mu).powi(3) * mu;
        // Corrector: centering plus the second-order term of the complementarity.
        let mut dx: Vec<f64> = (0..n)
            .map(|i| {
                -gradient[i] + sigma_mu / x[i]
                    - sigma_mu / t[i]
                    - dx_aff[i] * dz_aff[i] / x[i]
                    - dx_aff[i] * dw_aff[i] / t[i]
            })
            .collect();
        chol.solve_in_place(&mut dx);
        let dz: Vec<f64> = (0..n)
            .map(|i| (sigma_mu - x[i] * z[i] - dx_aff[i] * dz_aff[i] - z[i] * dx[i]) / x[i])
            .collect();
        let dw: Vec<f64> = (0..n)
            .map(|i| (sigma_mu - t[i] * w[i] + dx_aff[i] * dw_aff[i] + w[i] * dx[i]) / t[i])
            .collect();
        let alpha = step_length(&x, &t, &z, &w, &dx, &dz, &dw);
        if !alpha.is_finite() || alpha <= 0.0 {
            break;
        }
        for i in 0..n {
            x[i] += alpha * dx[i];
            t[i] -= alpha * dx[i];
            z[i] += alpha * dz[i];
            w[i] += alpha * dw[i];
        }
    }
    for v in &mut x {
        *v = if *v < options.snap_to_bound {
            0.0
        } else if *v > 1.0 - options.snap_to_bound {
            1.0
        } else {
            *v
        };
    }
    Ok((x, iterations, converged))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A regular grid of (n+1)² vertices over [0, side]², split into right triangles.
    pub(crate) fn grid(n: usize, side: f64) -> (Vec<[f64; 2]>, Vec<[u32; 3]>) {
        let h = side / n as f64;
        let mut v = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                v.push([i as f64 * h, j as f64 * h]);
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut t = Vec::new();
        for j in 0..n {
            for i in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (v, t)
    }

    /// The largest difference between two weight matrices' entries.
    pub(crate) fn largest_difference(a: &WeightMatrix, b: &WeightMatrix) -> f64 {
        a.data
            .iter()
            .zip(&b.data)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    /// Three point handles on a 20×20 grid: two close together, one far.
    pub(crate) fn three_points() -> (Domain, BoundaryConditions, usize) {
        let n = 20;
        let (v, t) = grid(n, 1.0);
        let id = |i: usize, j: usize| j * (n + 1) + i;
        let mut bc = BoundaryConditions {
            handle_count: 3,
            ..Default::default()
        };
        bc.fix_to_handle(id(3, 3), 0);
        bc.fix_to_handle(id(6, 4), 1);
        bc.fix_to_handle(id(16, 15), 2);
        (Domain::new(&v, &t), bc, v.len())
    }

    #[test]
    fn harmonic_and_biharmonic_interpolate_and_sum_to_one() {
        let (domain, bc, n) = three_points();
        for w in [
            harmonic_weights(&domain, &bc).unwrap(),
            biharmonic_weights(&domain, &bc).unwrap(),
        ] {
            for i in 0..n {
                assert!((w.row(i).iter().sum::<f64>() - 1.0).abs() < 1e-9);
            }
            assert_eq!(w.row(bc.vertices[1]), &[0.0, 1.0, 0.0]);
        }
        // Biharmonic weights overshoot the bounds somewhere; that is what BBW fixes.
        let b = biharmonic_weights(&domain, &bc).unwrap();
        assert!(b.data.iter().any(|&x| x < -1e-6));
    }

    #[test]
    fn bounded_weights_respect_bounds_and_interpolate() {
        let (domain, bc, n) = three_points();
        let (mut w, report) =
            bounded_biharmonic_weights(&domain, &bc, &BbwOptions::default()).unwrap();
        assert!(report.unconverged.is_empty(), "{report:?}");
        assert!(w.data.iter().all(|&x| (0.0..=1.0).contains(&x)));
        assert!(w.normalize_rows().is_empty());
        for i in 0..n {
            assert!((w.row(i).iter().sum::<f64>() - 1.0).abs() < 1e-9);
        }
        for (k, &v) in bc.vertices.iter().enumerate() {
            for j in 0..3 {
                assert_eq!(w.get(v, j), if j == k { 1.0 } else { 0.0 });
            }
        }
    }

    #[test]
    fn unreachable_piece_is_reported_not_panicked() {
        // Two separate triangles, a handle on one only.
        let v = [
            [0.0, 0.0],
            [1.0, 0.0],
            [0.0, 1.0],
            [5.0, 0.0],
            [6.0, 0.0],
            [5.0, 1.0],
        ];
        let t = [[0, 1, 2], [3, 4, 5]];
        let mut bc = BoundaryConditions {
            handle_count: 1,
            ..Default::default()
        };
        bc.fix_to_handle(0, 0);
        let r = harmonic_weights(&Domain::new(&v, &t), &bc);
        assert_eq!(r.err(), Some(SolveError::Unreachable { count: 3 }));
    }
}
