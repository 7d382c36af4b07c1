//! The monotone solve's constraints, per handle: the reference order (harmonic weights on a
//! positive-weight domain), its tie classes (equalities), the inequalities along mesh edges
//! that copy its order, and the repair of a vertex left a spurious extremum. See the parent
//! module's documentation, steps 1, 2 and 4.

use super::extrema::Extremum;
use super::qp::Problem;
use super::{MonotoneConstraints, MonotoneOptions};
use crate::weights::solve::Domain;
use sprs::TriMat;
use std::collections::BTreeSet;

/// The least weight an edge has in the reference domain, relative to the mean cotangent weight:
/// enough to keep every vertex attached, too little to change the order where weights are
/// positive already.
const MIN_REFERENCE_EDGE_WEIGHT: f64 = 1e-6;

/// How far a repaired reference value is moved past its extreme neighbour, relative to that
/// neighbour's magnitude (at least 1): enough to be strict in f64, too little to reorder others.
const REFERENCE_NUDGE: f64 = 1e-12;

/// Whether vertex a comes before vertex b in the reference order: by value, ties by index.
pub(super) fn precedes(r: &[f64], a: usize, b: usize) -> bool {
    r[a] < r[b] || (r[a] == r[b] && a < b)
}

/// The domain whose harmonic weights give the reference order: the cotangent stiffness with
/// every edge weight made positive. The cotangent weight of an edge is negative where its two
/// opposite angles sum past π (obtuse boundary triangles, non-Delaunay meshes, the 5D lift),
/// and there harmonic weights can have local extrema of their own; with positive weights every
/// free value is a strict average of its neighbours, so the discrete maximum principle holds.
/// Elsewhere the weights, and so the order, are unchanged. Each edge gets at least
/// [`MIN_REFERENCE_EDGE_WEIGHT`] of the mean weight, so no vertex is cut loose.
pub(super) fn reference_domain(domain: &Domain) -> Domain {
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
pub(super) struct Reference {
    /// Per vertex, its tie class (a representative vertex).
    pub(super) class: Vec<usize>,
    /// Per vertex, its class's reference value: the fixed value if the class holds a fixed
    /// vertex, else the mean harmonic weight over the class.
    pub(super) value: Vec<f64>,
    /// Edges spanning the classes: w(a) = w(b) for each.
    pub(super) ties: Vec<(usize, usize)>,
}

impl Reference {
    /// Joins adjacent vertices whose `harmonic` values differ by at most `tie_tolerance`,
    /// unless that would join two different fixed values.
    pub(super) fn new(problem: &Problem, harmonic: &[f64], tie_tolerance: f64) -> Self {
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

/// The inequalities w(a) ≤ w(b), as (a, b), between vertices of different tie classes: the
/// up-front graph of `options.constraints`, plus every edge at each repaired vertex. Each goes
/// up the reference order, and at least one end is free.
pub(super) fn constraint_edges(
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
pub(super) fn repair(
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

#[cfg(test)]
mod tests {
    use super::super::tests::{grid, point_handles};
    use super::super::{
        count_spurious_extrema, monotone_bounded_biharmonic_weights, monotone_column,
        MonotoneConstraints, MonotoneOptions,
    };
    use super::*;
    use crate::weights::solve::{harmonic_weights, BoundaryConditions, WeightMatrix};
    use crate::weights::{bounded_biharmonic_weights, BbwOptions};

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
}
