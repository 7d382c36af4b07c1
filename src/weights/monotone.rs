//! Monotone bounded biharmonic weights: bounded biharmonic weights without spurious local
//! extrema.
//!
//! In: a [`Domain`], [`BoundaryConditions`] and [`MonotoneOptions`]. Out: a [`WeightMatrix`],
//! one column per handle, not normalized (like [`bounded_biharmonic_weights`]; see
//! [`WeightMatrix::normalize_rows`]), and a [`MonotoneReport`]. Also [`count_spurious_extrema`],
//! the measure the method is judged by.
//!
//! Bounded biharmonic weights minimize wᵀ K M⁻¹ K w under 0 ≤ w ≤ 1, but higher-order energies
//! oscillate: a weight can rise again far from its handle, a bump that drags a patch of the
//! shape along with a handle it should have stopped following. Harmonic weights cannot do that
//! (the discrete maximum principle: every free value is an average of its neighbours). Jacobson,
//! Weinkauf & Sorkine 2012, "Smooth Shape-Aware Functions with Controlled Extrema" (SGP), copy
//! the harmonic weights' monotonicity into the biharmonic problem as linear inequalities along
//! mesh edges. Per handle j, here:
//!
//! 1. The reference is the harmonic weight h_j ([`harmonic_weights`]), computed with every
//!    cotangent edge weight made positive: negative weights (edges whose opposite angles sum
//!    past π: obtuse boundary triangles, the 5D content-aware lift) void the discrete maximum
//!    principle and give h_j extrema of its own, while a Laplacian with positive weights makes
//!    every free value a strict average of its neighbours. Adjacent vertices whose h_j differ
//!    by at most [`MonotoneOptions::tie_tolerance`] are joined into tie classes, and their
//!    weights are made equal (one equality per spanning edge). Ties are where h_j carries
//!    no order to copy: regions that other handles' geometry cuts off from handle j (h_j is 0
//!    there, up to rounding, e.g. along a thin tail past the next bone), regions enclosed by
//!    handle j (1), and exact symmetries. Without this, such regions get no constraint and the
//!    biharmonic energy bends them into bumps. A class never joins two different fixed values.
//!    Each class gets one reference value r (its fixed value, else the mean of h_j), and the
//!    vertices are ordered by (r, vertex index).
//! 2. Inequalities ([`MonotoneConstraints::SteepestEdges`], the default): every free vertex i is
//!    constrained against its neighbour of largest r in another class, w(i) ≤ w(up), and its
//!    neighbour of smallest r, w(down) ≤ w(i), where those lie above and below i. This is the
//!    "one in, one out" monotonicity graph of the paper's implementation (gptoolbox's
//!    `monotonic_biharmonic`, `monotonicity_matrix(…, 'OneInOneOut', true)`). It is enough: a
//!    free vertex with a neighbour constrained to be at least as high (or equal) cannot be a
//!    strict local maximum, nor one with a neighbour constrained at most as high a strict
//!    minimum. It is also far looser than constraining every edge
//!    ([`MonotoneConstraints::AllEdges`]), which imposes the whole harmonic level-set
//!    structure on the result.
//! 3. The QP min wᵀ Q w (Q = K M⁻¹ K), 0 ≤ w ≤ 1, w fixed at handle vertices, and the
//!    constraints, is solved by clarabel (interior point). Handles solve in parallel (rayon).
//! 4. Repair rounds (the "iterated" part, at most [`MonotoneOptions::max_repair_rounds`]): the
//!    solution is checked for strict local extrema off fixed vertices. Each offending vertex gets
//!    an inequality along every incident edge, in reference order. Where the reference itself
//!    peaks or dips at the vertex (which the positive weights rule out up to rounding), no edge
//!    there goes uphill, so the vertex's reference value is moved just past its extreme
//!    neighbour first. Then the problem is solved again, until no extremum is left or the round
//!    limit is hit; the report says what remains. With the reference above, the rounds are a
//!    safety net: none of the test meshes, nor the bundled character's parts (flat or lifted),
//!    needs one.
//!
//! The paper also re-derives the graph from the previous solution to relax the harmonic order.
//! That is not done here: a bounded solution has plateaus clamped at exactly 0 where its own
//! order says nothing, and the vertices in them would lose their constraints. The harmonic
//! order is always safe instead: every equality joins one class and every inequality goes up
//! the order of r, and r equals the fixed values at fixed vertices, so w = clamp(r, 0, 1)
//! satisfies all constraints and clarabel never sees an infeasible problem.
//!
//! The guarantee is per column. Normalizing rows afterwards (part weights do) divides each row by
//! its own sum, which can bend a column into new, small extrema where the sums vary (in the
//! tests: 1–3 per mesh, under 1e-3 deep, about as many as normalized plain BBW keeps).
//! Enforcing Σ_j w_j = 1 inside one joint QP would keep the guarantee, at m times the size.
//!
//! Mesh edges come from the stiffness matrix's pattern (the edges of the non-degenerate
//! triangles, what the Laplacian couples), as in the other solvers of [`super::solve`].
//!
//! [`bounded_biharmonic_weights`]: super::solve::bounded_biharmonic_weights

use super::solve::{harmonic_weights, BoundaryConditions, Domain, WeightMatrix};
use super::sparse::SolveError;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sprs::{CsMat, TriMat};
use std::collections::BTreeSet;

/// The default tolerance of [`count_spurious_extrema`] and [`MonotoneOptions::extremum_tolerance`]:
/// a vertex is an extremum only when it beats every neighbour by more than this. Well above the
/// interior-point solver's accuracy, far below any bump a deformation would show.
pub const EXTREMUM_TOLERANCE: f64 = 1e-8;

/// The least weight an edge has in the reference domain, relative to the mean cotangent weight:
/// enough to keep every vertex attached, too little to change the order where weights are
/// positive already.
const MIN_REFERENCE_EDGE_WEIGHT: f64 = 1e-6;

/// How far a repaired reference value is moved past its extreme neighbour, relative to that
/// neighbour's magnitude (at least 1): enough to be strict in f64, too little to reorder others.
const REFERENCE_NUDGE: f64 = 1e-12;

/// Which mesh edges carry monotonicity constraints before any repair.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MonotoneConstraints {
    /// Per free vertex, its steepest uphill and steepest downhill edge in the harmonic
    /// reference (the paper's practical "one in, one out" graph).
    #[default]
    SteepestEdges,
    /// Every edge between tie classes: the full monotonicity graph. Stiffer, with over twice
    /// the inequalities.
    AllEdges,
}

/// Parameters of the monotone bounded biharmonic solve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MonotoneOptions {
    /// Which edges are constrained up front. Default: [`MonotoneConstraints::SteepestEdges`].
    pub constraints: MonotoneConstraints,
    /// Adjacent vertices whose harmonic weights differ by at most this are ties: their weights
    /// are made equal (see the module documentation). Default 1e-12, far below any weight that
    /// matters (part weights drop those under 1e-6) and above the solves' rounding.
    pub tie_tolerance: f64,
    /// Rounds of checking for spurious extrema and constraining the offending vertices, after
    /// the first solve. 0 solves once. Default 4.
    pub max_repair_rounds: usize,
    /// A free vertex is a spurious extremum when its weight beats every neighbour's by more
    /// than this. Default [`EXTREMUM_TOLERANCE`].
    pub extremum_tolerance: f64,
    /// clarabel's gap and feasibility tolerances. Default 1e-10, well below
    /// `extremum_tolerance` so constrained edges never read as extrema.
    pub solver_tolerance: f64,
    /// clarabel's iteration limit per solve. Default 200.
    pub max_solver_iterations: u32,
}

impl Default for MonotoneOptions {
    fn default() -> Self {
        MonotoneOptions {
            constraints: MonotoneConstraints::SteepestEdges,
            tie_tolerance: 1e-12,
            max_repair_rounds: 4,
            extremum_tolerance: EXTREMUM_TOLERANCE,
            solver_tolerance: 1e-10,
            max_solver_iterations: 200,
        }
    }
}

impl MonotoneOptions {
    fn validate(&self) -> Result<(), SolveError> {
        let invalid = |what: &str| Err(SolveError::Assembly(format!("monotone options: {what}")));
        if !(self.tie_tolerance.is_finite() && self.tie_tolerance >= 0.0) {
            return invalid("tie_tolerance must be finite and non-negative");
        }
        if !(self.extremum_tolerance.is_finite() && self.extremum_tolerance >= 0.0) {
            return invalid("extremum_tolerance must be finite and non-negative");
        }
        if !(self.solver_tolerance.is_finite() && self.solver_tolerance > 0.0) {
            return invalid("solver_tolerance must be finite and positive");
        }
        if self.max_solver_iterations == 0 {
            return invalid("max_solver_iterations must be at least 1");
        }
        Ok(())
    }
}

/// How the monotone solve went, per handle (indexed by weight column).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MonotoneReport {
    /// QP solves: 1 plus the repair rounds used (0 for a column fixed to one constant value,
    /// which needs no solve).
    pub solves: Vec<usize>,
    /// Monotonicity inequalities in the last solve.
    pub constraints: Vec<usize>,
    /// Equalities joining tie classes.
    pub equalities: Vec<usize>,
    /// Spurious extrema left in the returned column (at `extremum_tolerance`): 0 unless the
    /// round limit was hit.
    pub spurious_extrema: Vec<usize>,
    /// Handles whose last solve reached only clarabel's reduced accuracy.
    pub almost_solved: Vec<usize>,
}

/// Which way a vertex is a strict local extremum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Extremum {
    Maximum,
    Minimum,
}

/// Vertex 1-rings, compressed: the neighbours of i are `neighbors[start[i]..start[i + 1]]`.
struct Rings {
    start: Vec<usize>,
    neighbors: Vec<usize>,
}

impl Rings {
    /// From undirected edges (either orientation, repeats and loops allowed).
    fn from_edges(n: usize, edges: impl Iterator<Item = (usize, usize)>) -> Self {
        let mut directed: Vec<(usize, usize)> = edges
            .filter(|&(a, b)| a != b)
            .flat_map(|(a, b)| [(a, b), (b, a)])
            .collect();
        directed.sort_unstable();
        directed.dedup();
        let mut start = vec![0; n + 1];
        for &(a, _) in &directed {
            start[a + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        Rings {
            start,
            neighbors: directed.into_iter().map(|(_, b)| b).collect(),
        }
    }

    /// The triangles' edges; corners outside `0..n` are ignored.
    fn from_triangles(n: usize, triangles: &[[u32; 3]]) -> Self {
        Rings::from_edges(
            n,
            triangles
                .iter()
                .flat_map(|t| (0..3).map(move |k| (t[k] as usize, t[(k + 1) % 3] as usize)))
                .filter(|&(a, b)| a < n && b < n),
        )
    }

    /// The off-diagonal pattern of a square sparse matrix.
    fn from_pattern(a: &CsMat<f64>) -> Self {
        Rings::from_edges(
            a.rows(),
            a.outer_iterator().enumerate().flat_map(|(i, row)| {
                row.indices()
                    .iter()
                    .map(move |&k| (i, k))
                    .collect::<Vec<_>>()
            }),
        )
    }

    fn of(&self, i: usize) -> &[usize] {
        &self.neighbors[self.start[i]..self.start[i + 1]]
    }
}

/// Whether `w[i]` beats every neighbour by more than `tolerance`, and which way. A vertex
/// without neighbours is no extremum; neither is one level with some neighbour (a plateau, such
/// as a region clamped to 0).
fn strict_extremum(rings: &Rings, w: &[f64], i: usize, tolerance: f64) -> Option<Extremum> {
    let ring = rings.of(i);
    if ring.is_empty() {
        None
    } else if ring.iter().all(|&k| w[i] > w[k] + tolerance) {
        Some(Extremum::Maximum)
    } else if ring.iter().all(|&k| w[i] < w[k] - tolerance) {
        Some(Extremum::Minimum)
    } else {
        None
    }
}

/// Strict local extrema of `w` at vertices not fixed, in ascending vertex order.
fn spurious_extrema(
    rings: &Rings,
    w: &[f64],
    is_fixed: &[bool],
    tolerance: f64,
) -> Vec<(usize, Extremum)> {
    (0..w.len())
        .filter(|&i| !is_fixed[i])
        .filter_map(|i| strict_extremum(rings, w, i, tolerance).map(|e| (i, e)))
        .collect()
}

/// Per handle, the number of spurious extrema of its weight column: vertices not in `fixed`
/// whose weight is above every 1-ring neighbour's (a local maximum) or below every one's (a
/// local minimum) by more than `tolerance`. Mesh-boundary vertices count like any other;
/// plateaus (a vertex level with some neighbour, such as a region clamped to exactly 0) do not.
/// Triangle corners and fixed indices outside the matrix are ignored.
pub fn spurious_extrema_per_handle(
    mesh_triangles: &[[u32; 3]],
    w: &WeightMatrix,
    fixed: &[usize],
    tolerance: f64,
) -> Vec<usize> {
    let n = w.vertex_count;
    let rings = Rings::from_triangles(n, mesh_triangles);
    let mut is_fixed = vec![false; n];
    for &v in fixed.iter().filter(|&&v| v < n) {
        is_fixed[v] = true;
    }
    (0..w.handle_count)
        .map(|j| spurious_extrema(&rings, &w.column(j), &is_fixed, tolerance).len())
        .collect()
}

/// The spurious extrema of all handles' weights together (see [`spurious_extrema_per_handle`]),
/// at [`EXTREMUM_TOLERANCE`].
pub fn count_spurious_extrema(
    mesh_triangles: &[[u32; 3]],
    w: &WeightMatrix,
    fixed: &[usize],
) -> usize {
    spurious_extrema_per_handle(mesh_triangles, w, fixed, EXTREMUM_TOLERANCE)
        .iter()
        .sum()
}

/// Whether vertex a comes before vertex b in the reference order: by value, ties by index.
fn precedes(r: &[f64], a: usize, b: usize) -> bool {
    r[a] < r[b] || (r[a] == r[b] && a < b)
}

/// The parts of the QP shared by every handle.
struct Problem {
    /// The bi-Laplacian Q.
    q: CsMat<f64>,
    /// Free vertices, ascending, and each vertex's position among them (`usize::MAX`: fixed).
    free: Vec<usize>,
    column_of: Vec<usize>,
    is_fixed: Vec<bool>,
    /// The upper triangle of Q[free, free] · `scale`, clarabel's P.
    p: CscMatrix<f64>,
    /// Scales the objective to unit diagonal magnitude: the minimizer is unchanged and
    /// clarabel's absolute gap tolerance means the same on any mesh size.
    scale: f64,
    rings: Rings,
}

impl Problem {
    fn new(domain: &Domain, bc: &BoundaryConditions) -> Self {
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

/// The domain whose harmonic weights give the reference order: the cotangent stiffness with
/// every edge weight made positive. The cotangent weight of an edge is negative where its two
/// opposite angles sum past π (obtuse boundary triangles, non-Delaunay meshes, the 5D lift),
/// and there harmonic weights can have local extrema of their own; with positive weights every
/// free value is a strict average of its neighbours, so the discrete maximum principle holds.
/// Elsewhere the weights, and so the order, are unchanged. Each edge gets at least
/// [`MIN_REFERENCE_EDGE_WEIGHT`] of the mean weight, so no vertex is cut loose.
fn reference_domain(domain: &Domain) -> Domain {
    let k = &domain.stiffness;
    let n = k.rows();
    // Off-diagonal entries are minus the edge weights.
    let (mut total, mut count) = (0.0, 0usize);
    for (&value, (i, j)) in k.iter() {
        if i != j && value < 0.0 {
            total -= value;
            count += 1;
        }
    }
    let floor = if count > 0 {
        MIN_REFERENCE_EDGE_WEIGHT * total / count as f64
    } else {
        MIN_REFERENCE_EDGE_WEIGHT
    };
    let mut positive = TriMat::with_capacity((n, n), k.nnz());
    for (&value, (i, j)) in k.iter() {
        if i != j {
            let weight = (-value).max(floor);
            positive.add_triplet(i, j, -weight);
            positive.add_triplet(i, i, weight);
        }
    }
    Domain {
        stiffness: positive.to_csr(),
        mass: domain.mass.clone(),
    }
}

/// One handle's reference order: tie classes and one value per vertex.
struct Reference {
    /// Per vertex, its tie class (a representative vertex).
    class: Vec<usize>,
    /// Per vertex, its class's reference value: the fixed value if the class holds a fixed
    /// vertex, else the mean harmonic weight over the class.
    value: Vec<f64>,
    /// Edges spanning the classes: w(a) = w(b) for each.
    ties: Vec<(usize, usize)>,
}

impl Reference {
    /// Joins adjacent vertices whose `harmonic` values differ by at most `tie_tolerance`,
    /// unless that would join two different fixed values.
    fn new(problem: &Problem, harmonic: &[f64], tie_tolerance: f64) -> Self {
        let n = harmonic.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn root(parent: &mut [usize], mut i: usize) -> usize {
            while parent[i] != i {
                parent[i] = parent[parent[i]];
                i = parent[i];
            }
            i
        }
        // Per root: the fixed value its class holds, if any.
        let mut fixed_value: Vec<Option<f64>> = (0..n)
            .map(|i| problem.is_fixed[i].then_some(harmonic[i]))
            .collect();
        let mut ties = Vec::new();
        for a in 0..n {
            for &b in problem.rings.of(a) {
                if b < a || (harmonic[a] - harmonic[b]).abs() > tie_tolerance {
                    continue;
                }
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                if ra == rb {
                    continue;
                }
                let joined = match (fixed_value[ra], fixed_value[rb]) {
                    (Some(x), Some(y)) if x != y => continue,
                    (x, y) => x.or(y),
                };
                let (keep, gone) = (ra.min(rb), ra.max(rb));
                parent[gone] = keep;
                fixed_value[keep] = joined;
                ties.push((a, b));
            }
        }
        let class: Vec<usize> = (0..n).map(|i| root(&mut parent, i)).collect();
        let (mut sum, mut count) = (vec![0.0; n], vec![0usize; n]);
        for i in 0..n {
            sum[class[i]] += harmonic[i];
            count[class[i]] += 1;
        }
        let value = (0..n)
            .map(|i| {
                let c = class[i];
                fixed_value[c].unwrap_or(sum[c] / count[c] as f64)
            })
            .collect();
        Reference { class, value, ties }
    }
}

/// One handle's column: the weights, and its part of the report.
struct ColumnResult {
    w: Vec<f64>,
    solves: usize,
    constraints: usize,
    equalities: usize,
    spurious_extrema: usize,
    almost_solved: bool,
}

/// Monotone bounded biharmonic weights (Jacobson, Weinkauf & Sorkine 2012), not normalized: see
/// the module documentation for the algorithm. Fails like [`harmonic_weights`] when some vertex
/// is not reached by a handle, on invalid options, or when clarabel does not solve a problem.
pub fn monotone_bounded_biharmonic_weights(
    domain: &Domain,
    bc: &BoundaryConditions,
    options: &MonotoneOptions,
) -> Result<(WeightMatrix, MonotoneReport), SolveError> {
    options.validate()?;
    // Also checks that every vertex is reached, so the QPs below are bounded.
    let harmonic = harmonic_weights(&reference_domain(domain), bc)?;
    let problem = Problem::new(domain, bc);
    let n = problem.is_fixed.len();
    let m = bc.handle_count;
    let results: Vec<Result<ColumnResult, SolveError>> = (0..m)
        .into_par_iter()
        .map(|j| {
            let reference = Reference::new(&problem, &harmonic.column(j), options.tie_tolerance);
            monotone_column(&problem, reference, options)
        })
        .collect();
    let mut data = vec![0.0; n * m];
    let mut report = MonotoneReport::default();
    for (j, result) in results.into_iter().enumerate() {
        let column = result?;
        for (i, &x) in column.w.iter().enumerate() {
            data[i * m + j] = x;
        }
        report.solves.push(column.solves);
        report.constraints.push(column.constraints);
        report.equalities.push(column.equalities);
        report.spurious_extrema.push(column.spurious_extrema);
        if column.almost_solved {
            report.almost_solved.push(j);
        }
    }
    Ok((
        WeightMatrix {
            vertex_count: n,
            handle_count: m,
            data,
        },
        report,
    ))
}

/// One handle's monotone column from its reference order (built from harmonic weights in
/// production; any reference whose values equal the fixed values at fixed vertices keeps every
/// problem feasible).
fn monotone_column(
    problem: &Problem,
    mut reference: Reference,
    options: &MonotoneOptions,
) -> Result<ColumnResult, SolveError> {
    let fixed_values = || {
        problem
            .is_fixed
            .iter()
            .zip(&reference.value)
            .filter(|(&fixed, _)| fixed)
            .map(|(_, &x)| x)
    };
    let constant = fixed_values()
        .next()
        .filter(|&c| fixed_values().all(|x| x == c));
    if let Some(c) = constant {
        // All fixed values agree: the constant has zero energy, is monotone, and needs no solve.
        let w = problem
            .is_fixed
            .iter()
            .map(|&fixed| if fixed { c } else { c.clamp(0.0, 1.0) })
            .collect();
        return Ok(ColumnResult {
            w,
            solves: 0,
            constraints: 0,
            equalities: 0,
            spurious_extrema: 0,
            almost_solved: false,
        });
    }
    let linear = linear_term(problem, &reference.value);
    let mut repaired = BTreeSet::new();
    let mut round = 0;
    loop {
        let constraints = constraint_edges(problem, &reference, &repaired, options);
        let (w, almost_solved) = solve_qp(problem, &reference, &linear, &constraints, options)?;
        let extrema = spurious_extrema(
            &problem.rings,
            &w,
            &problem.is_fixed,
            options.extremum_tolerance,
        );
        let done = extrema.is_empty() || round == options.max_repair_rounds;
        if done || !repair(problem, &mut reference, &mut repaired, &extrema) {
            return Ok(ColumnResult {
                w,
                solves: round + 1,
                constraints: constraints.len(),
                equalities: reference
                    .ties
                    .iter()
                    .filter(|&&(a, b)| !(problem.is_fixed[a] && problem.is_fixed[b]))
                    .count(),
                spurious_extrema: extrema.len(),
                almost_solved,
            });
        }
        round += 1;
    }
}

/// clarabel's linear term: Q[free, fixed] · (fixed values), scaled like P. `values` holds the
/// fixed values at fixed vertices.
fn linear_term(problem: &Problem, values: &[f64]) -> Vec<f64> {
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

/// The inequalities w(a) ≤ w(b), as (a, b), between vertices of different tie classes: the
/// up-front graph of `options.constraints`, plus every edge at each repaired vertex. Each goes
/// up the reference order, and at least one end is free.
fn constraint_edges(
    problem: &Problem,
    reference: &Reference,
    repaired: &BTreeSet<usize>,
    options: &MonotoneOptions,
) -> BTreeSet<(usize, usize)> {
    let (r, class) = (&reference.value, &reference.class);
    let ordered = |a: usize, b: usize| if precedes(r, a, b) { (a, b) } else { (b, a) };
    let mut edges = BTreeSet::new();
    for &i in &problem.free {
        let mut across = problem
            .rings
            .of(i)
            .iter()
            .copied()
            .filter(|&k| class[k] != class[i]);
        match options.constraints {
            MonotoneConstraints::SteepestEdges => {
                let (mut up, mut down) = (None, None);
                for k in across {
                    if precedes(r, i, k) && up.is_none_or(|u| precedes(r, u, k)) {
                        up = Some(k);
                    }
                    if precedes(r, k, i) && down.is_none_or(|d| precedes(r, k, d)) {
                        down = Some(k);
                    }
                }
                edges.extend(up.map(|u| (i, u)));
                edges.extend(down.map(|d| (d, i)));
            }
            MonotoneConstraints::AllEdges => edges.extend(across.by_ref().map(|k| ordered(i, k))),
        }
    }
    for &i in repaired {
        for &k in problem.rings.of(i) {
            if class[k] != class[i] {
                edges.insert(ordered(i, k));
            }
        }
    }
    edges
}

/// Marks the offending vertices for constraints along all their edges, and moves the reference
/// value of a vertex past its extreme neighbour where the reference peaks or dips there itself.
/// Returns whether anything changed (if not, another solve would give the same answer).
fn repair(
    problem: &Problem,
    reference: &mut Reference,
    repaired: &mut BTreeSet<usize>,
    extrema: &[(usize, Extremum)],
) -> bool {
    let mut changed = false;
    for &(i, kind) in extrema {
        changed |= repaired.insert(i);
        let ring = problem.rings.of(i);
        let r = &mut reference.value;
        // A vertex tied to a neighbour is held level with it; only a class of its own can be
        // moved without moving other vertices.
        if ring
            .iter()
            .any(|&k| reference.class[k] == reference.class[i])
        {
            continue;
        }
        match kind {
            Extremum::Maximum if ring.iter().all(|&k| precedes(r, k, i)) => {
                let top = ring.iter().map(|&k| r[k]).fold(f64::NEG_INFINITY, f64::max);
                r[i] = top - REFERENCE_NUDGE * top.abs().max(1.0);
                changed = true;
            }
            Extremum::Minimum if ring.iter().all(|&k| precedes(r, i, k)) => {
                let bottom = ring.iter().map(|&k| r[k]).fold(f64::INFINITY, f64::min);
                r[i] = bottom + REFERENCE_NUDGE * bottom.abs().max(1.0);
                changed = true;
            }
            Extremum::Maximum | Extremum::Minimum => {}
        }
    }
    changed
}

/// Solves one handle's QP; returns the full column (fixed values from the reference, free
/// values clamped to [0, 1]) and whether clarabel reached only reduced accuracy.
fn solve_qp(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weights::solve::tests::grid;
    use crate::weights::{biharmonic_weights, bounded_biharmonic_weights, BbwOptions};

    /// Points and triangles.
    type Mesh = (Vec<[f64; 2]>, Vec<[u32; 3]>);

    /// The triangles of `(points, triangles)` whose centroid passes `keep`, with the vertices
    /// they use renumbered.
    fn cut((points, triangles): Mesh, keep: impl Fn([f64; 2]) -> bool) -> Mesh {
        let kept: Vec<[u32; 3]> = triangles
            .into_iter()
            .filter(|t| {
                let c = t.iter().fold([0.0, 0.0], |c, &v| {
                    let p = points[v as usize];
                    [c[0] + p[0] / 3.0, c[1] + p[1] / 3.0]
                });
                keep(c)
            })
            .collect();
        let mut index = vec![u32::MAX; points.len()];
        let mut out = Vec::new();
        for t in &kept {
            for &v in t {
                if index[v as usize] == u32::MAX {
                    index[v as usize] = out.len() as u32;
                    out.push(points[v as usize]);
                }
            }
        }
        let renumbered = kept.iter().map(|t| t.map(|v| index[v as usize])).collect();
        (out, renumbered)
    }

    /// One point handle per position, at the nearest vertex.
    fn point_handles(points: &[[f64; 2]], at: &[[f64; 2]]) -> BoundaryConditions {
        let mut bc = BoundaryConditions {
            handle_count: at.len(),
            ..Default::default()
        };
        for (j, a) in at.iter().enumerate() {
            let d = |p: &[f64; 2]| (p[0] - a[0]).powi(2) + (p[1] - a[1]).powi(2);
            let nearest = (0..points.len())
                .min_by(|&x, &y| d(&points[x]).total_cmp(&d(&points[y])))
                .unwrap();
            bc.fix_to_handle(nearest, j);
        }
        bc
    }

    /// A test domain, its triangles, point handles, and the shape's name.
    struct Case {
        name: &'static str,
        points: Vec<[f64; 2]>,
        triangles: Vec<[u32; 3]>,
        bc: BoundaryConditions,
    }

    /// Meshes of 1,280–1,680 vertices with point handles where plain BBW has spurious extrema
    /// (found by sampling handle positions; the counts are printed by the test).
    fn cases() -> Vec<Case> {
        let shapes: [(&str, Mesh, Vec<[f64; 2]>); 3] = [
            (
                "square",
                grid(40, 1.0),
                vec![
                    [0.9, 0.8],
                    [0.3, 0.35],
                    [0.65, 0.45],
                    [0.35, 0.5],
                    [0.45, 0.4],
                ],
            ),
            (
                "L",
                cut(grid(40, 1.0), |c| !(c[0] > 0.5 && c[1] > 0.5)),
                vec![[0.2, 0.05], [0.25, 0.25], [0.45, 0.35]],
            ),
            (
                "annulus",
                cut(grid(40, 1.0), |c| {
                    !((0.3..0.7).contains(&c[0]) && (0.3..0.7).contains(&c[1]))
                }),
                vec![[0.35, 0.9], [0.35, 0.95], [0.55, 0.8], [0.95, 0.45]],
            ),
        ];
        shapes
            .into_iter()
            .map(|(name, (points, triangles), at)| {
                let bc = point_handles(&points, &at);
                Case {
                    name,
                    points,
                    triangles,
                    bc,
                }
            })
            .collect()
    }

    #[test]
    fn monotone_weights_have_no_spurious_extrema() {
        for case in cases() {
            let Case {
                name,
                points,
                triangles,
                bc,
            } = &case;
            let domain = Domain::new(points, triangles);
            let count = |w: &WeightMatrix| count_spurious_extrema(triangles, w, &bc.vertices);

            let start = std::time::Instant::now();
            let (bbw, _) = bounded_biharmonic_weights(&domain, bc, &BbwOptions::default()).unwrap();
            let bbw_time = start.elapsed();
            let biharmonic = biharmonic_weights(&domain, bc).unwrap();
            let harmonic = harmonic_weights(&domain, bc).unwrap();
            let start = std::time::Instant::now();
            let (mut w, report) =
                monotone_bounded_biharmonic_weights(&domain, bc, &MonotoneOptions::default())
                    .unwrap();
            let monotone_time = start.elapsed();
            eprintln!(
                "{name} ({} vertices, {} handles): spurious extrema: BBW {} {:?}, biharmonic {}, \
                 harmonic {}, monotone {} (BBW {bbw_time:.0?}, monotone {monotone_time:.0?}; \
                 {report:?})",
                points.len(),
                bc.handle_count,
                count(&bbw),
                spurious_extrema_per_handle(triangles, &bbw, &bc.vertices, EXTREMUM_TOLERANCE),
                count(&biharmonic),
                count(&harmonic),
                count(&w),
            );
            assert!(
                count(&bbw) > 0,
                "{name}: plain BBW should show the artifact"
            );
            assert_eq!(count(&w), 0, "{name}");
            assert_eq!(report.spurious_extrema, vec![0; bc.handle_count], "{name}");
            assert!(report.almost_solved.is_empty(), "{name}: {report:?}");
            assert!(w.data.iter().all(|&x| (0.0..=1.0).contains(&x)), "{name}");
            for (k, &v) in bc.vertices.iter().enumerate() {
                for j in 0..bc.handle_count {
                    assert_eq!(w.get(v, j), if j == k { 1.0 } else { 0.0 }, "{name}");
                }
            }
            assert!(w.normalize_rows().is_empty(), "{name}: a row is all zero");
            for i in 0..w.vertex_count {
                let sum: f64 = w.row(i).iter().sum();
                assert!((sum - 1.0).abs() < 1e-9, "{name}: row {i} sums to {sum}");
            }
            // Normalizing divides each row by its own sum, which can bend a column into new
            // (small) extrema: report, not assert, what a caller sees after it, by size.
            let mut bbw = bbw;
            bbw.normalize_rows();
            let by_size = |w: &WeightMatrix| {
                [1e-8, 1e-6, 1e-4, 1e-3].map(|tol| {
                    spurious_extrema_per_handle(triangles, w, &bc.vertices, tol)
                        .iter()
                        .sum::<usize>()
                })
            };
            eprintln!(
                "{name}: after normalizing rows, extrema beyond 1e-8, 1e-6, 1e-4, 1e-3: \
                 BBW {:?}, monotone {:?}",
                by_size(&bbw),
                by_size(&w)
            );
        }
    }

    #[test]
    fn spurious_extrema_are_strict_free_and_beyond_the_tolerance() {
        let (_, t) = grid(4, 1.0);
        let id = |i: usize, j: usize| j * 5 + i;
        let column = |values: &[(usize, f64)]| {
            let mut data = vec![0.0; 25];
            for &(v, x) in values {
                data[v] = x;
            }
            WeightMatrix {
                vertex_count: 25,
                handle_count: 1,
                data,
            }
        };
        // All zero: one plateau, no extremum.
        assert_eq!(count_spurious_extrema(&t, &column(&[]), &[]), 0);
        // An interior bump is a maximum, unless it is fixed.
        let bump = column(&[(id(2, 2), 0.5)]);
        assert_eq!(count_spurious_extrema(&t, &bump, &[]), 1);
        assert_eq!(count_spurious_extrema(&t, &bump, &[id(2, 2)]), 0);
        // Below the tolerance it is noise.
        let noise = column(&[(id(2, 2), 0.1 * EXTREMUM_TOLERANCE)]);
        assert_eq!(count_spurious_extrema(&t, &noise, &[]), 0);
        // A bump two vertices wide is a plateau on top: not strict.
        let wide = column(&[(id(2, 2), 0.5), (id(3, 2), 0.5)]);
        assert_eq!(count_spurious_extrema(&t, &wide, &[]), 0);
        // Boundary vertices count; a dip is a minimum.
        let mut corner = column(&[(id(0, 0), 1.0)]);
        assert_eq!(count_spurious_extrema(&t, &corner, &[]), 1);
        corner.data.iter_mut().for_each(|x| *x = 1.0 - *x);
        assert_eq!(count_spurious_extrema(&t, &corner, &[]), 1);
        // Indices outside the matrix are ignored, not a panic.
        assert_eq!(count_spurious_extrema(&[[0, 1, 99]], &bump, &[1000]), 0);
    }

    /// A strip 2 cells tall with a chain of bones along its middle row, like a thin tail: the
    /// top and bottom rows meet only through the bones, so each handle's harmonic weight decays
    /// geometrically along them and reaches 0 (up to rounding) a few bones away.
    fn bone_chain() -> (Vec<[f64; 2]>, Vec<[u32; 3]>, BoundaryConditions) {
        const COLUMNS: usize = 80;
        const BONES: usize = 4;
        let id = |i: usize, j: usize| (j * (COLUMNS + 1) + i) as u32;
        let points = (0..3)
            .flat_map(|j| (0..=COLUMNS).map(move |i| [i as f64, j as f64]))
            .collect();
        let mut triangles = Vec::new();
        for j in 0..2 {
            for i in 0..COLUMNS {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let mut bc = BoundaryConditions {
            handle_count: BONES,
            ..Default::default()
        };
        let per_bone = COLUMNS / BONES;
        for i in 0..=COLUMNS {
            let bone = (i / per_bone).min(BONES - 1);
            if i % per_bone == 0 && i > 0 && i < COLUMNS {
                // A joint, shared by the bones on either side, across the whole strip.
                for j in 0..3 {
                    bc.fix(id(i, j) as usize, &[(bone - 1, 0.5), (bone, 0.5)]);
                }
            } else {
                bc.fix_to_handle(id(i, 1) as usize, bone);
            }
        }
        (points, triangles, bc)
    }

    #[test]
    fn ties_level_regions_the_reference_cannot_order() {
        let (v, t, bc) = bone_chain();
        let domain = Domain::new(&v, &t);
        let (bbw, _) = bounded_biharmonic_weights(&domain, &bc, &BbwOptions::default()).unwrap();
        let (w, report) =
            monotone_bounded_biharmonic_weights(&domain, &bc, &MonotoneOptions::default()).unwrap();
        // Without tie classes (a negative tolerance joins nothing) the far rows are ordered by
        // rounding noise, and one solve bends them into bumps.
        let problem = Problem::new(&domain, &bc);
        let harmonic = harmonic_weights(&reference_domain(&domain), &bc).unwrap();
        let once = MonotoneOptions {
            max_repair_rounds: 0,
            ..Default::default()
        };
        let untied: usize = (0..bc.handle_count)
            .map(|j| {
                let reference = Reference::new(&problem, &harmonic.column(j), -1.0);
                monotone_column(&problem, reference, &once)
                    .unwrap()
                    .spurious_extrema
            })
            .sum();
        eprintln!(
            "bone chain ({} vertices): spurious extrema: BBW {}, monotone {} ({report:?}), \
             monotone without ties, one solve: {untied}",
            v.len(),
            count_spurious_extrema(&t, &bbw, &bc.vertices),
            count_spurious_extrema(&t, &w, &bc.vertices),
        );
        assert_eq!(count_spurious_extrema(&t, &w, &bc.vertices), 0);
        assert!(report.equalities.iter().all(|&e| e > 0));
        assert!(untied > 0);
        // Where a bone's harmonic weight is exactly 0 (cut off by joints), the tied weight is 0
        // up to the solver's tolerance.
        let far = 2 * 81 + 80;
        eprintln!(
            "bone 0's weight at the far end: BBW {:.1e}, monotone {:.1e}",
            bbw.get(far, 0),
            w.get(far, 0)
        );
        assert!(w.get(far, 0) < 1e-9);
    }

    #[test]
    fn the_reference_keeps_the_maximum_principle_on_a_lifted_mesh() {
        // A grid lifted to 5D by noisy "colors", as content-aware weights do: many edges get
        // negative cotangent weights, and plain harmonic weights get extrema of their own.
        let (v, t) = grid(30, 1.0);
        // Lift per color channel: a few times the grid spacing, so most triangles are far
        // from Delaunay in 5D.
        const LIFT: f64 = 0.2;
        let mut seed: u64 = 2;
        let mut noise = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let lifted: Vec<[f64; 5]> = v
            .iter()
            .map(|p| [p[0], p[1], LIFT * noise(), LIFT * noise(), LIFT * noise()])
            .collect();
        let domain = Domain::new(&lifted, &t);
        let bc = point_handles(&v, &[[0.2, 0.2], [0.8, 0.3], [0.5, 0.8], [0.3, 0.6]]);
        let harmonic = harmonic_weights(&domain, &bc).unwrap();
        let reference = harmonic_weights(&reference_domain(&domain), &bc).unwrap();
        let (bbw, _) = bounded_biharmonic_weights(&domain, &bc, &BbwOptions::default()).unwrap();
        let (w, report) =
            monotone_bounded_biharmonic_weights(&domain, &bc, &MonotoneOptions::default()).unwrap();
        let count = |w: &WeightMatrix| count_spurious_extrema(&t, w, &bc.vertices);
        eprintln!(
            "lifted grid ({} vertices): spurious extrema: harmonic {}, reference {}, BBW {}, \
             monotone {} ({report:?})",
            v.len(),
            count(&harmonic),
            count(&reference),
            count(&bbw),
            count(&w)
        );
        assert!(count(&harmonic) > 0);
        assert_eq!(count(&reference), 0);
        assert_eq!(count(&w), 0);
    }

    #[test]
    fn repair_rounds_move_a_reference_that_peaks_itself() {
        // A reference with a peak at a free vertex (what the positive-weight reference rules
        // out, and rounding might not): no edge there goes uphill, and the biharmonic energy
        // bends the corner of this layout into a maximum, until the repair moves the reference.
        let (v, t) = grid(24, 1.0);
        let bc = point_handles(
            &v,
            &[[0.5, 0.125], [0.125, 0.5], [0.875, 0.875], [0.125, 0.125]],
        );
        let domain = Domain::new(&v, &t);
        let problem = Problem::new(&domain, &bc);
        let harmonic = harmonic_weights(&domain, &bc).unwrap();
        let peaked = || {
            let mut reference = Reference::new(&problem, &harmonic.column(3), -1.0);
            let corner = 0;
            let top = problem
                .rings
                .of(corner)
                .iter()
                .map(|&k| reference.value[k])
                .fold(0.0, f64::max);
            reference.value[corner] = top + 0.1;
            reference
        };
        let once = MonotoneOptions {
            max_repair_rounds: 0,
            ..Default::default()
        };
        let first = monotone_column(&problem, peaked(), &once).unwrap();
        let fixed = monotone_column(&problem, peaked(), &MonotoneOptions::default()).unwrap();
        eprintln!(
            "peaked reference: one solve leaves {}, repair leaves {} after {} solves",
            first.spurious_extrema, fixed.spurious_extrema, fixed.solves
        );
        assert!(first.spurious_extrema > 0);
        assert_eq!(fixed.spurious_extrema, 0);

        // The full graph works too, with over twice the inequalities.
        let (_, steepest) =
            monotone_bounded_biharmonic_weights(&domain, &bc, &MonotoneOptions::default()).unwrap();
        let all = MonotoneOptions {
            constraints: MonotoneConstraints::AllEdges,
            ..Default::default()
        };
        let (w_all, all_report) = monotone_bounded_biharmonic_weights(&domain, &bc, &all).unwrap();
        eprintln!("all edges: {all_report:?}");
        assert_eq!(count_spurious_extrema(&t, &w_all, &bc.vertices), 0);
        assert!(all_report.constraints[0] > 2 * steepest.constraints[0]);
    }

    #[test]
    fn untouched_handle_is_zero_without_a_solve_and_bad_options_are_errors() {
        let (v, t) = grid(10, 1.0);
        let domain = Domain::new(&v, &t);
        let mut bc = BoundaryConditions {
            handle_count: 3,
            ..Default::default()
        };
        bc.fix_to_handle(0, 0);
        bc.fix_to_handle(120, 1);
        let (w, report) =
            monotone_bounded_biharmonic_weights(&domain, &bc, &MonotoneOptions::default()).unwrap();
        assert!(w.column(2).iter().all(|&x| x == 0.0));
        assert_eq!(report.solves[2], 0);
        for bad in [
            MonotoneOptions {
                tie_tolerance: -1.0,
                ..Default::default()
            },
            MonotoneOptions {
                extremum_tolerance: f64::NAN,
                ..Default::default()
            },
            MonotoneOptions {
                solver_tolerance: 0.0,
                ..Default::default()
            },
            MonotoneOptions {
                max_solver_iterations: 0,
                ..Default::default()
            },
        ] {
            assert!(monotone_bounded_biharmonic_weights(&domain, &bc, &bad).is_err());
        }
    }

    #[test]
    fn options_deserialize_with_defaults() {
        let o: MonotoneOptions =
            serde_json::from_str(r#"{"constraints": "all_edges", "max_repair_rounds": 2}"#)
                .unwrap();
        assert_eq!(o.constraints, MonotoneConstraints::AllEdges);
        assert_eq!(o.max_repair_rounds, 2);
        assert_eq!(o.extremum_tolerance, EXTREMUM_TOLERANCE);
        let w: crate::weights::WeightOptions =
            serde_json::from_str(r#"{"monotone": true}"#).unwrap();
        assert!(w.monotone);
        let w: crate::weights::WeightOptions = serde_json::from_str("{}").unwrap();
        assert!(!w.monotone);
    }
}
