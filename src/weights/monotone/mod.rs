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
//! triangles, what the Laplacian couples), as in the other solvers of [`crate::weights::solve`].
//!
//! [`bounded_biharmonic_weights`]: crate::weights::solve::bounded_biharmonic_weights
//!
//! The pieces: [`extrema`] finds strict local extrema (the measure, and the repair rounds'
//! trigger); [`constraints`] builds the reference order, its ties and inequalities, and repairs
//! it; [`qp`] assembles and solves one handle's QP with clarabel.

mod constraints;
mod extrema;
mod qp;

pub use extrema::{count_spurious_extrema, spurious_extrema_per_handle, EXTREMUM_TOLERANCE};

use super::solve::{harmonic_weights, BoundaryConditions, Domain, WeightMatrix};
use super::sparse::SolveError;
use constraints::{constraint_edges, reference_domain, repair, Reference};
use extrema::spurious_extrema;
use qp::{linear_term, solve_qp, Problem};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;

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

#[cfg(test)]
mod tests {
    use super::*;
    pub(super) use crate::weights::solve::tests::grid;
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
    pub(super) fn point_handles(points: &[[f64; 2]], at: &[[f64; 2]]) -> BoundaryConditions {
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
