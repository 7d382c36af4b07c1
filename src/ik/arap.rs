//! The per-vertex as-rigid-as-possible energy (Sorkine & Alexa 2007) of a 2D triangle mesh.
//!
//! In: rest and deformed vertex positions (canvas px) and the triangles. Out: edge weights,
//! best-fitting rotations and the energy
//!
//! E = Σᵢ Σⱼ∈N(i) wᵢⱼ ‖(v′ᵢ − v′ⱼ) − Rᵢ (vᵢ − vⱼ)‖²  (px²),
//!
//! where wᵢⱼ is half the sum of the cotangents of the angles opposite edge ij, clamped at zero so
//! that obtuse triangles cannot make the energy negative, and Rᵢ is the rotation that best maps
//! vertex i's rest spokes onto its deformed ones. This is the yardstick the skinning IK is
//! measured with; [`crate::ik::fast`] minimizes a reduced version of the same energy.

use crate::geom::Point;
use nalgebra::Matrix2;

/// An undirected mesh edge (`i < j`) with its clamped cotangent weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WeightedEdge {
    pub i: u32,
    pub j: u32,
    pub weight: f64,
}

/// Clamped cotangent weights of every edge of `triangles`, sorted by (i, j). Edges whose weight
/// clamps to zero are kept (with weight 0) so that the edge list is the mesh's.
pub fn cotangent_edges(rest: &[Point], triangles: &[[u32; 3]]) -> Vec<WeightedEdge> {
    let mut half: Vec<(u32, u32, f64)> = Vec::with_capacity(triangles.len() * 3);
    for t in triangles {
        for k in 0..3 {
            let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let (pa, pb, pc) = (rest[a as usize], rest[b as usize], rest[c as usize]);
            // The angle at c is opposite edge ab.
            let (u, v) = (pa - pc, pb - pc);
            let cross = (u.x * v.y - u.y * v.x).abs();
            let cot = if cross > 0.0 { u.dot(&v) / cross } else { 0.0 };
            half.push((a.min(b), a.max(b), 0.5 * cot));
        }
    }
    half.sort_by_key(|x| (x.0, x.1));
    let mut edges: Vec<WeightedEdge> = Vec::with_capacity(half.len() / 2 + 1);
    for (i, j, w) in half {
        match edges.last_mut() {
            Some(e) if e.i == i && e.j == j => e.weight += w,
            _ => edges.push(WeightedEdge { i, j, weight: w }),
        }
    }
    for e in &mut edges {
        e.weight = e.weight.max(0.0);
    }
    edges
}

/// The rotation R maximizing tr(R·C) for a 2×2 matrix C (the closed form of the 2×2 SVD
/// step: for R(θ) = [[cos θ, −sin θ], [sin θ, cos θ]], tr(R·C) = cos θ (C₀₀ + C₁₁) +
/// sin θ (C₀₁ − C₁₀)). A zero C gives the identity.
pub fn best_rotation(c: &Matrix2<f64>) -> Matrix2<f64> {
    let (x, y) = (c[(0, 0)] + c[(1, 1)], c[(0, 1)] - c[(1, 0)]);
    let r = x.hypot(y);
    if r == 0.0 || !r.is_finite() {
        return Matrix2::identity();
    }
    let (cos, sin) = (x / r, y / r);
    Matrix2::new(cos, -sin, sin, cos)
}

/// The rotation nearest to the linear map `l` (its polar factor), for projecting a handle's
/// linear part onto rigid motions.
pub fn nearest_rotation(l: &Matrix2<f64>) -> Matrix2<f64> {
    // Nearest rotation = argmax tr(Rᵀ L) = argmax tr(R Lᵀ).
    best_rotation(&l.transpose())
}

/// Per-vertex ARAP energy of `deformed` against `rest` over `edges` (see the module doc), px².
pub fn arap_energy(rest: &[Point], deformed: &[Point], edges: &[WeightedEdge]) -> f64 {
    let rotations = vertex_rotations(rest, deformed, edges);
    let mut energy = 0.0;
    for e in edges {
        let (i, j) = (e.i as usize, e.j as usize);
        let (r, d) = (rest[i] - rest[j], deformed[i] - deformed[j]);
        energy += e.weight
            * ((d - rotations[i] * r).norm_squared() + (d - rotations[j] * r).norm_squared());
    }
    energy
}

/// The best rotation per vertex: the one mapping its weighted rest spokes onto the deformed ones.
pub fn vertex_rotations(
    rest: &[Point],
    deformed: &[Point],
    edges: &[WeightedEdge],
) -> Vec<Matrix2<f64>> {
    let mut covariance = vec![Matrix2::zeros(); rest.len()];
    for e in edges {
        let (i, j) = (e.i as usize, e.j as usize);
        let (r, d) = (rest[i] - rest[j], deformed[i] - deformed[j]);
        // Maximize Σ w dᵀ R r = tr(R · Σ w r dᵀ).
        let c = e.weight * r * d.transpose();
        covariance[i] += c;
        covariance[j] += c;
    }
    covariance.iter().map(best_rotation).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> (Vec<Point>, Vec<[u32; 3]>) {
        let rest = vec![
            Point::new(0.0, 0.0),
            Point::new(10.0, 0.0),
            Point::new(10.0, 10.0),
            Point::new(0.0, 10.0),
            Point::new(5.0, 5.0),
        ];
        let triangles = vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
        (rest, triangles)
    }

    #[test]
    fn right_isoceles_weights() {
        let (rest, triangles) = square();
        let edges = cotangent_edges(&rest, &triangles);
        assert_eq!(edges.len(), 8);
        // Outer edges face a right angle at the center: cot 90° = 0.
        let outer = edges.iter().find(|e| (e.i, e.j) == (0, 1)).unwrap();
        assert!(outer.weight.abs() < 1e-12);
        // Spokes: two 45° angles, cot 45° = 1, half each.
        let spoke = edges.iter().find(|e| (e.i, e.j) == (0, 4)).unwrap();
        assert!((spoke.weight - 1.0).abs() < 1e-12);
    }

    #[test]
    fn rigid_motion_costs_nothing_and_stretch_does() {
        let (rest, triangles) = square();
        let edges = cotangent_edges(&rest, &triangles);
        let r = Matrix2::new(0.6, -0.8, 0.8, 0.6);
        let moved: Vec<Point> = rest
            .iter()
            .map(|p| Point::from(r * p.coords) + nalgebra::Vector2::new(3.0, -7.0))
            .collect();
        assert!(arap_energy(&rest, &moved, &edges) < 1e-18);
        let stretched: Vec<Point> = rest.iter().map(|p| Point::new(1.5 * p.x, p.y)).collect();
        assert!(arap_energy(&rest, &stretched, &edges) > 1.0);
    }

    #[test]
    fn best_rotation_recovers_a_rotation() {
        let r = Matrix2::new(0.6, -0.8, 0.8, 0.6);
        // tr(R C) is largest for R = Cᵀ's rotation when C = Rᵀ·S with S symmetric positive.
        let c = r.transpose() * Matrix2::new(2.0, 0.3, 0.3, 1.0);
        assert!((best_rotation(&c) - r).norm() < 1e-12);
        assert!((nearest_rotation(&(r * 3.0)) - r).norm() < 1e-12);
    }
}
