//! Discrete Laplacian and mass of a triangle mesh, from its edge lengths.
//!
//! In: the number of vertices, the triangles, and for each triangle the squared lengths of the
//! edges opposite its three corners (px², or any unit: the 5D lift of content-aware weights
//! measures edges in (x, y, s·r, s·g, s·b)). Out:
//!
//! - [`cotangent_stiffness`]: the positive semi-definite stiffness matrix K = −L, where L is the
//!   cotangent Laplacian (Pinkall & Polthier 1993; libigl's `cotmatrix`):
//!   K_ij = −½ (cot α_ij + cot β_ij), K_ii = −Σ_j K_ij. Rows sum to zero.
//! - [`voronoi_mass`]: the lumped mixed-Voronoi mass of Meyer, Desbrun, Schröder & Barr 2003
//!   (libigl's `massmatrix` default): Voronoi areas on non-obtuse triangles, and on obtuse ones
//!   half the area to the obtuse corner and a quarter to the others. Sums to the mesh area.
//!
//! Everything is computed from edge lengths alone (angles by the law of cosines, areas by
//! Kahan's stable Heron formula), so the same code measures the flat mesh and its 5D lift.

use sprs::{CsMat, TriMat};

/// The area below which a triangle counts as degenerate, relative to its longest edge squared.
/// Such triangles contribute nothing: their cotangents would be unbounded.
pub const DEGENERATE_AREA_RATIO: f64 = 1e-12;

/// Squared lengths of the edges opposite corners 0, 1, 2 of every triangle of a flat mesh.
pub fn squared_edge_lengths<const D: usize>(
    points: &[[f64; D]],
    triangles: &[[u32; 3]],
) -> Vec<[f64; 3]> {
    let d2 = |a: u32, b: u32| {
        let (p, q) = (&points[a as usize], &points[b as usize]);
        (0..D).map(|k| (p[k] - q[k]) * (p[k] - q[k])).sum::<f64>()
    };
    triangles
        .iter()
        .map(|&[a, b, c]| [d2(b, c), d2(c, a), d2(a, b)])
        .collect()
}

/// Area of a triangle from its squared edge lengths (Kahan's formula, stable for needles).
pub fn triangle_area(l2: [f64; 3]) -> f64 {
    let mut l = l2.map(f64::sqrt);
    l.sort_by(|a, b| b.total_cmp(a));
    let [a, b, c] = l;
    let s = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
    0.25 * s.max(0.0).sqrt()
}

/// Whether a triangle (squared edge lengths) is degenerate: it contributes nothing to the
/// stiffness, so it joins none of its vertices for the solve.
pub fn is_degenerate(l2: [f64; 3]) -> bool {
    corner_cotangents(l2).is_none()
}

/// Cotangents of the angles at corners 0, 1, 2, or `None` for a degenerate triangle.
fn corner_cotangents(l2: [f64; 3]) -> Option<[f64; 3]> {
    let area = triangle_area(l2);
    let longest = l2.iter().cloned().fold(0.0, f64::max);
    // Written to also reject a NaN area or length.
    if !matches!(
        area.partial_cmp(&(DEGENERATE_AREA_RATIO * longest)),
        Some(std::cmp::Ordering::Greater)
    ) {
        return None;
    }
    // cot(angle at k) = (l_i² + l_j² − l_k²) / (4 · area), with l_k opposite corner k.
    Some([0, 1, 2].map(|k| (l2[(k + 1) % 3] + l2[(k + 2) % 3] - l2[k]) / (4.0 * area)))
}

/// The cotangent stiffness K = −L (n × n, symmetric positive semi-definite, CSR).
pub fn cotangent_stiffness(n: usize, triangles: &[[u32; 3]], l2: &[[f64; 3]]) -> CsMat<f64> {
    let mut k = TriMat::with_capacity((n, n), 12 * triangles.len());
    for (t, lengths) in triangles.iter().zip(l2) {
        let Some(cot) = corner_cotangents(*lengths) else {
            continue;
        };
        for c in 0..3 {
            // The edge opposite corner c joins the other two corners.
            let (i, j) = (t[(c + 1) % 3] as usize, t[(c + 2) % 3] as usize);
            let w = 0.5 * cot[c];
            k.add_triplet(i, j, -w);
            k.add_triplet(j, i, -w);
            k.add_triplet(i, i, w);
            k.add_triplet(j, j, w);
        }
    }
    k.to_csr()
}

/// The lumped mixed-Voronoi mass of every vertex (length n, px² in the flat case).
pub fn voronoi_mass(n: usize, triangles: &[[u32; 3]], l2: &[[f64; 3]]) -> Vec<f64> {
    let mut mass = vec![0.0; n];
    for (t, lengths) in triangles.iter().zip(l2) {
        let area = triangle_area(*lengths);
        let Some(cot) = corner_cotangents(*lengths) else {
            // A sliver still has (nearly no) area: share it evenly so no vertex is massless.
            for &v in t {
                mass[v as usize] += area / 3.0;
            }
            continue;
        };
        if let Some(obtuse) = (0..3).find(|&c| cot[c] < 0.0) {
            for c in 0..3 {
                mass[t[c] as usize] += if c == obtuse { area / 2.0 } else { area / 4.0 };
            }
        } else {
            for c in 0..3 {
                // Corner c's Voronoi share: ⅛ (|e_cj|² cot k + |e_ck|² cot j) over its two edges.
                let (j, k) = ((c + 1) % 3, (c + 2) % 3);
                // |e_ck| is opposite corner j, |e_cj| opposite corner k.
                mass[t[c] as usize] += (lengths[k] * cot[k] + lengths[j] * cot[j]) / 8.0;
            }
        }
    }
    mass
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weights::solve::tests::grid;

    #[test]
    fn stiffness_rows_sum_to_zero_and_kill_linear_functions() {
        let (v, t) = grid(6, 3.0);
        let l2 = squared_edge_lengths(&v, &t);
        let k = cotangent_stiffness(v.len(), &t, &l2);
        let linear: Vec<f64> = v.iter().map(|p| 2.0 * p[0] - 0.5 * p[1] + 1.0).collect();
        let kx = mat_vec(&k, &linear);
        // Interior rows of K times a linear function vanish (linear precision).
        for (i, p) in v.iter().enumerate() {
            let interior = p[0] > 0.0 && p[0] < 3.0 && p[1] > 0.0 && p[1] < 3.0;
            if interior {
                assert!(kx[i].abs() < 1e-12, "row {i}: {}", kx[i]);
            }
        }
        for row in k.outer_iterator() {
            assert!(row.data().iter().sum::<f64>().abs() < 1e-12);
        }
    }

    fn mat_vec(a: &CsMat<f64>, x: &[f64]) -> Vec<f64> {
        a.outer_iterator()
            .map(|row| row.iter().map(|(j, v)| v * x[j]).sum())
            .collect()
    }

    #[test]
    fn mass_sums_to_area_on_acute_and_obtuse_triangles() {
        let (v, t) = grid(5, 2.0);
        let l2 = squared_edge_lengths(&v, &t);
        let m = voronoi_mass(v.len(), &t, &l2);
        assert!((m.iter().sum::<f64>() - 4.0).abs() < 1e-12);
        // An obtuse triangle: half its area to the obtuse corner.
        let v = [[0.0, 0.0], [4.0, 0.0], [2.0, 0.5]];
        let t = [[0, 1, 2]];
        let m = voronoi_mass(3, &t, &squared_edge_lengths(&v, &t));
        assert!((m[2] - 0.5).abs() < 1e-12 && (m[0] - 0.25).abs() < 1e-12);
    }

    #[test]
    fn degenerate_triangles_add_no_stiffness() {
        let v = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]];
        let t = [[0, 1, 2]];
        let k = cotangent_stiffness(3, &t, &squared_edge_lengths(&v, &t));
        assert_eq!(k.nnz(), 0);
    }
}
