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
//!   rows normalized to sum to one. Solved by a primal–dual active-set method (Hintermüller, Ito
//!   & Kunisch 2002) warm-started from the unconstrained biharmonic solution: each iteration
//!   clamps the vertices that violate a bound or whose multiplier says they stay clamped, and
//!   solves the bi-Laplace system on the rest. Handles solve in parallel (rayon).
//!
//! Every vertex of every connected piece of the domain must be reached by some handle vertex;
//! otherwise the systems are singular and the solve reports [`SolveError::Unreachable`].

use super::laplacian::{cotangent_stiffness, squared_edge_lengths, voronoi_mass};
use super::sparse::{mat_vec, sandwich_diagonal, SolveError, SubmatrixCholesky};
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

    fn from_columns(vertex_count: usize, columns: &[Vec<f64>]) -> Self {
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

/// Parameters of the bounded biharmonic solve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BbwOptions {
    /// Active-set iterations per handle before giving up on exact convergence (the result is
    /// then clamped to the bounds). Default 40.
    pub max_active_set_iterations: usize,
    /// A weight counts as violating a bound when it is beyond it by more than this. Default 1e-10.
    pub bound_tolerance: f64,
}

impl Default for BbwOptions {
    fn default() -> Self {
        BbwOptions {
            max_active_set_iterations: 40,
            bound_tolerance: 1e-10,
        }
    }
}

/// How the bounded solve went, for reports and tests.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BbwReport {
    /// Active-set iterations per handle.
    pub iterations: Vec<usize>,
    /// Handles whose active set had not settled within the iteration limit.
    pub unconverged: Vec<usize>,
}

/// Free vertices (not fixed by a handle), in ascending order.
fn free_vertices(n: usize, bc: &BoundaryConditions) -> Vec<usize> {
    let mut fixed = vec![false; n];
    for &v in &bc.vertices {
        fixed[v] = true;
    }
    (0..n).filter(|&i| !fixed[i]).collect()
}

/// Handle j's full-length weight column with the fixed values in place and zeros elsewhere.
fn fixed_column(n: usize, bc: &BoundaryConditions, j: usize) -> Vec<f64> {
    let mut w = vec![0.0; n];
    for (k, &v) in bc.vertices.iter().enumerate() {
        w[v] = bc.values[k * bc.handle_count + j];
    }
    w
}

/// Fails when some vertex cannot be reached from a fixed vertex through the matrix's pattern
/// (the mesh's edges): the system would be singular there.
fn check_reachable(a: &CsMat<f64>, bc: &BoundaryConditions) -> Result<(), SolveError> {
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
pub fn bounded_biharmonic_weights(
    domain: &Domain,
    bc: &BoundaryConditions,
    options: &BbwOptions,
) -> Result<(WeightMatrix, BbwReport), SolveError> {
    let q = domain.bilaplacian();
    let n = q.rows();
    let free = free_vertices(n, bc);
    let start = solve_quadratic(&q, bc)?;
    let results: Vec<Result<(Vec<f64>, usize, bool), SolveError>> = (0..bc.handle_count)
        .into_par_iter()
        .map(|j| bounded_column(&q, &free, start.column(j), options))
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

/// Which bound, if any, a free vertex is clamped to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Clamp {
    None,
    Lower,
    Upper,
}

/// One handle's bounded solve by primal–dual active sets, from the unconstrained solution `w`
/// (which already holds the fixed values). Returns the column, the iterations and whether the
/// active set settled.
fn bounded_column(
    q: &CsMat<f64>,
    free: &[usize],
    mut w: Vec<f64>,
    options: &BbwOptions,
) -> Result<(Vec<f64>, usize, bool), SolveError> {
    let tol = options.bound_tolerance;
    let mut clamp = vec![Clamp::None; w.len()];
    let mut gradient = mat_vec(q, &w);
    for iteration in 1..=options.max_active_set_iterations {
        // A clamped vertex stays clamped while its multiplier (the gradient) pushes it against
        // the bound; a free vertex becomes clamped when it crosses a bound.
        let mut changed = false;
        for &i in free {
            let next = match clamp[i] {
                Clamp::Lower if gradient[i] > 0.0 => Clamp::Lower,
                Clamp::Upper if gradient[i] < 0.0 => Clamp::Upper,
                Clamp::Lower | Clamp::Upper => Clamp::None,
                Clamp::None if w[i] < -tol => Clamp::Lower,
                Clamp::None if w[i] > 1.0 + tol => Clamp::Upper,
                Clamp::None => Clamp::None,
            };
            changed |= next != clamp[i];
            clamp[i] = next;
        }
        if !changed {
            clamp_to_bounds(&mut w, free);
            return Ok((w, iteration - 1, true));
        }
        for &i in free {
            match clamp[i] {
                Clamp::Lower => w[i] = 0.0,
                Clamp::Upper => w[i] = 1.0,
                Clamp::None => {}
            }
        }
        let inactive: Vec<usize> = free
            .iter()
            .copied()
            .filter(|&i| clamp[i] == Clamp::None)
            .collect();
        if !inactive.is_empty() {
            let chol = SubmatrixCholesky::new(q, &inactive)?;
            for &i in &inactive {
                w[i] = 0.0;
            }
            let qw = mat_vec(q, &w);
            let mut rhs: Vec<f64> = inactive.iter().map(|&i| -qw[i]).collect();
            chol.solve_in_place(&mut rhs);
            for (k, &i) in inactive.iter().enumerate() {
                w[i] = rhs[k];
            }
        }
        gradient = mat_vec(q, &w);
    }
    clamp_to_bounds(&mut w, free);
    Ok((w, options.max_active_set_iterations, false))
}

fn clamp_to_bounds(w: &mut [f64], free: &[usize]) {
    for &i in free {
        w[i] = w[i].clamp(0.0, 1.0);
    }
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
