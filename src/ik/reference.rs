//! The full per-vertex ARAP deformation (Sorkine & Alexa 2007): the quality bound for the
//! skinning IK.
//!
//! In: skinned meshes (only their rest vertices and triangles are used), drags as
//! (mesh, triangle, barycentric coordinates, target px), a starting deformation. Out: deformed
//! vertex positions that minimize the per-vertex ARAP energy of [`super::arap`] with every vertex
//! free, the drags held by a stiff quadratic penalty. No skinning subspace restricts it, so its
//! energy is a lower bound for any rig's: the ratio says how much a richer handle set would buy.
//! Meshes are independent here (nothing couples separate layers but the skinning).

use super::arap::{cotangent_edges, vertex_rotations, WeightedEdge};
use super::subspace::SkinnedMesh;
use crate::geom::Point;
use crate::weights::sparse::SubmatrixCholesky;
use sprs::TriMat;

/// A drag on one mesh: the point with barycentric coordinates `barycentric` in `triangle`.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshDrag {
    pub mesh: usize,
    pub triangle: usize,
    pub barycentric: [f64; 3],
    pub target: Point,
}

/// Penalty on a drag's squared distance, relative to the largest Laplacian diagonal.
pub const DRAG_PENALTY: f64 = 1e6;
/// Keeps a mesh without drags where it starts (rigid motions cost it nothing).
pub const ANCHOR_PENALTY: f64 = 1e-9;

/// Minimizes the per-vertex ARAP energy of every mesh from `start` (one position list per mesh)
/// for `iterations` local/global steps or until the energy stops falling by more than
/// `relative_tolerance`. Returns the deformed positions and the total energy, px².
pub fn full_arap(
    meshes: &[SkinnedMesh],
    drags: &[MeshDrag],
    start: &[Vec<Point>],
    iterations: usize,
    relative_tolerance: f64,
) -> (Vec<Vec<Point>>, f64) {
    let mut out = Vec::with_capacity(meshes.len());
    let mut total = 0.0;
    for (m, mesh) in meshes.iter().enumerate() {
        let mine: Vec<&MeshDrag> = drags.iter().filter(|d| d.mesh == m).collect();
        let (positions, energy) =
            deform_one(mesh, &mine, &start[m], iterations, relative_tolerance);
        total += energy;
        out.push(positions);
    }
    (out, total)
}

fn deform_one(
    mesh: &SkinnedMesh,
    drags: &[&MeshDrag],
    start: &[Point],
    iterations: usize,
    relative_tolerance: f64,
) -> (Vec<Point>, f64) {
    let n = mesh.rest.len();
    let edges = cotangent_edges(&mesh.rest, &mesh.triangles);
    let energy = |p: &[Point]| super::arap::arap_energy(&mesh.rest, p, &edges);
    if drags.is_empty() || n == 0 {
        return (start.to_vec(), energy(start));
    }
    let mut diagonal = vec![0.0; n];
    for e in &edges {
        diagonal[e.i as usize] += e.weight;
        diagonal[e.j as usize] += e.weight;
    }
    let scale = diagonal.iter().cloned().fold(0.0, f64::max).max(1e-12);
    let omega = DRAG_PENALTY * scale;
    // System: (2 L + ω Σ d dᵀ + anchor) v′ = b + ω Σ d · target.
    let mut tri = TriMat::new((n, n));
    for e in &edges {
        let (i, j) = (e.i as usize, e.j as usize);
        tri.add_triplet(i, i, 2.0 * e.weight);
        tri.add_triplet(j, j, 2.0 * e.weight);
        tri.add_triplet(i, j, -2.0 * e.weight);
        tri.add_triplet(j, i, -2.0 * e.weight);
    }
    for i in 0..n {
        tri.add_triplet(i, i, ANCHOR_PENALTY * scale);
    }
    for d in drags {
        let t = mesh.triangles[d.triangle];
        for a in 0..3 {
            for b in 0..3 {
                tri.add_triplet(
                    t[a] as usize,
                    t[b] as usize,
                    omega * d.barycentric[a] * d.barycentric[b],
                );
            }
        }
    }
    let matrix = tri.to_csr();
    let keep: Vec<usize> = (0..n).collect();
    let Ok(factor) = SubmatrixCholesky::new(&matrix, &keep) else {
        return (start.to_vec(), energy(start));
    };
    let mut positions = start.to_vec();
    let mut last = energy(&positions);
    for _ in 0..iterations {
        let rotations = vertex_rotations(&mesh.rest, &positions, &edges);
        let mut rhs = vec![0.0; 2 * n];
        add_rotated_edges(&edges, &mesh.rest, &rotations, &mut rhs, n);
        for i in 0..n {
            rhs[i] += ANCHOR_PENALTY * scale * start[i].x;
            rhs[n + i] += ANCHOR_PENALTY * scale * start[i].y;
        }
        for d in drags {
            for (a, &v) in mesh.triangles[d.triangle].iter().enumerate() {
                rhs[v as usize] += omega * d.barycentric[a] * d.target.x;
                rhs[n + v as usize] += omega * d.barycentric[a] * d.target.y;
            }
        }
        factor.solve_in_place(&mut rhs);
        positions = (0..n).map(|i| Point::new(rhs[i], rhs[n + i])).collect();
        let now = energy(&positions);
        if (last - now).abs() <= relative_tolerance * last.max(1e-300) {
            last = now;
            break;
        }
        last = now;
    }
    (positions, last)
}

/// b_i = Σ_j w_ij (R_i + R_j)(v_i − v_j), x components in `rhs[..n]`, y in `rhs[n..]`.
fn add_rotated_edges(
    edges: &[WeightedEdge],
    rest: &[Point],
    rotations: &[nalgebra::Matrix2<f64>],
    rhs: &mut [f64],
    n: usize,
) {
    for e in edges {
        let (i, j) = (e.i as usize, e.j as usize);
        let b = (rotations[i] + rotations[j]) * (rest[i] - rest[j]) * e.weight;
        rhs[i] += b.x;
        rhs[n + i] += b.y;
        rhs[j] -= b.x;
        rhs[n + j] -= b.y;
    }
}
