//! Bounded biharmonic weights by a general-purpose QP solver (clarabel, interior point): the
//! reference the fast active-set solver in [`super::solve`] is checked against.
//!
//! In: a [`Domain`] and [`BoundaryConditions`]. Out: the per-handle bounded solutions (not
//! normalized), or with [`partition_of_unity`] set, the exact variant of Jacobson et al. 2011
//! that solves all handles in one QP with Σ_j w_j = 1 as a constraint.

use super::solve::{BoundaryConditions, Domain, WeightMatrix};
use super::sparse::SolveError;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};

/// Interior-point tolerances: tight, since this is the yardstick.
const REFERENCE_TOLERANCE: f64 = 1e-10;

/// Solves the bounded biharmonic QP with clarabel. With `partition_of_unity`, all handles in one
/// problem with rows constrained to sum to one; otherwise one problem per handle.
pub fn bounded_biharmonic_reference(
    domain: &Domain,
    bc: &BoundaryConditions,
    partition_of_unity: bool,
) -> Result<WeightMatrix, SolveError> {
    let q = domain.bilaplacian();
    let n = q.rows();
    let m = bc.handle_count;
    let mut fixed = vec![None; n];
    for (k, &v) in bc.vertices.iter().enumerate() {
        fixed[v] = Some(k);
    }
    let free: Vec<usize> = (0..n).filter(|&i| fixed[i].is_none()).collect();
    let mut column_of = vec![usize::MAX; n];
    for (c, &i) in free.iter().enumerate() {
        column_of[i] = c;
    }
    let f = free.len();
    let handles_per_problem = if partition_of_unity { m } else { 1 };
    let problems: Vec<Vec<usize>> = if partition_of_unity {
        vec![(0..m).collect()]
    } else {
        (0..m).map(|j| vec![j]).collect()
    };

    let mut data = vec![0.0; n * m];
    for (k, &v) in bc.vertices.iter().enumerate() {
        data[v * m..(v + 1) * m].copy_from_slice(&bc.values[k * m..(k + 1) * m]);
    }
    for handles in problems {
        // Unknowns: block b holds handle handles[b]'s weights on the free vertices.
        let size = f * handles_per_problem;
        let (mut pi, mut pj, mut pv) = (Vec::new(), Vec::new(), Vec::new());
        let mut linear = vec![0.0; size];
        for (b, &h) in handles.iter().enumerate() {
            for (r, &i) in free.iter().enumerate() {
                let Some(row) = q.outer_view(i) else { continue };
                for (j, &value) in row.iter() {
                    match fixed[j] {
                        Some(k) => linear[b * f + r] += value * bc.values[k * m + h],
                        None if column_of[j] >= r => {
                            pi.push(b * f + r);
                            pj.push(b * f + column_of[j]);
                            pv.push(value);
                        }
                        None => {}
                    }
                }
            }
        }
        let p = CscMatrix::new_from_triplets(size, size, pi, pj, pv);
        // Rows: [Σ_j w_j = 1 per free vertex (zero cone)], −w ≤ 0, w ≤ 1 (nonnegative cone).
        let (mut ai, mut aj, mut av, mut b_vec) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut cones = Vec::new();
        if partition_of_unity {
            for r in 0..f {
                for b in 0..handles_per_problem {
                    ai.push(r);
                    aj.push(b * f + r);
                    av.push(1.0);
                }
                b_vec.push(1.0);
            }
            cones.push(SupportedConeT::ZeroConeT(f));
        }
        let offset = b_vec.len();
        for x in 0..size {
            ai.extend([offset + x, offset + size + x]);
            aj.extend([x, x]);
            av.extend([-1.0, 1.0]);
        }
        b_vec.extend(std::iter::repeat_n(0.0, size));
        b_vec.extend(std::iter::repeat_n(1.0, size));
        cones.push(SupportedConeT::NonnegativeConeT(2 * size));
        let a = CscMatrix::new_from_triplets(b_vec.len(), size, ai, aj, av);
        let settings = DefaultSettings::<f64> {
            verbose: false,
            tol_gap_abs: REFERENCE_TOLERANCE,
            tol_gap_rel: REFERENCE_TOLERANCE,
            tol_feas: REFERENCE_TOLERANCE,
            ..DefaultSettings::default()
        };
        let mut solver = DefaultSolver::new(&p, &linear, &a, &b_vec, &cones, settings)
            .map_err(|e| SolveError::Assembly(format!("{e:?}")))?;
        solver.solve();
        if !matches!(
            solver.solution.status,
            SolverStatus::Solved | SolverStatus::AlmostSolved
        ) {
            return Err(SolveError::Assembly(format!(
                "clarabel: {:?}",
                solver.solution.status
            )));
        }
        for (b, &h) in handles.iter().enumerate() {
            for (r, &i) in free.iter().enumerate() {
                data[i * m + h] = solver.solution.x[b * f + r].clamp(0.0, 1.0);
            }
        }
    }
    Ok(WeightMatrix {
        vertex_count: n,
        handle_count: m,
        data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weights::solve::tests::three_points;
    use crate::weights::{bounded_biharmonic_weights, BbwOptions};

    #[test]
    fn active_set_matches_clarabel() {
        let (domain, bc, _) = three_points();
        let (fast, _) = bounded_biharmonic_weights(&domain, &bc, &BbwOptions::default()).unwrap();
        let reference = bounded_biharmonic_reference(&domain, &bc, false).unwrap();
        let worst = fast
            .data
            .iter()
            .zip(&reference.data)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-4,
            "active set vs clarabel: max difference {worst}"
        );
    }

    #[test]
    fn partition_of_unity_variant_sums_to_one_and_is_close() {
        let (domain, bc, n) = three_points();
        let exact = bounded_biharmonic_reference(&domain, &bc, true).unwrap();
        for i in 0..n {
            assert!((exact.row(i).iter().sum::<f64>() - 1.0).abs() < 1e-6);
        }
        let (mut fast, _) =
            bounded_biharmonic_weights(&domain, &bc, &BbwOptions::default()).unwrap();
        fast.normalize_rows();
        // The two formulations are different problems (the paper found them visually alike):
        // they agree on average, and both interpolate and stay in bounds.
        let diffs: Vec<f64> = fast
            .data
            .iter()
            .zip(&exact.data)
            .map(|(a, b)| (a - b).abs())
            .collect();
        let mean = diffs.iter().sum::<f64>() / diffs.len() as f64;
        let worst = diffs.iter().cloned().fold(0.0, f64::max);
        eprintln!("normalized per-handle BBW vs partition-of-unity QP: mean difference {mean:.4}, max {worst:.4}");
        assert!(mean < 0.05, "mean difference {mean}");
        assert!(exact.data.iter().all(|&x| (0.0..=1.0).contains(&x)));
        for (k, &v) in bc.vertices.iter().enumerate() {
            assert!((exact.get(v, k) - 1.0).abs() < 1e-12);
        }
    }
}
