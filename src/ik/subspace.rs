//! The as-rigid-as-possible energy of a skinned shape, reduced to its skinning transformations.
//!
//! In: the rig's skinned meshes (rest vertices in canvas px, triangles, each vertex's weights over
//! the rig's m handle columns) and a clustering of the vertices. Out: the small dense matrices of
//! Fast Automatic Skinning Transformations (Jacobson, Baran, Kavan, Popović & Sorkine 2012):
//! with the handles' affine maps stacked as T (3m × 2; rows 3j, 3j+1, 3j+2 hold handle j's
//! linear part's row entries and translation for the output coordinate of the column), every
//! skinned vertex is v′ᵢ = Mᵢ T with Mᵢ = [wᵢⱼ xᵢ, wᵢⱼ yᵢ, wᵢⱼ]ⱼ, and the clustered ARAP energy
//!
//! E(T, R) = Σᵢ Σⱼ∈N(i) wᵢⱼ ‖(v′ᵢ − v′ⱼ) − R_g(i) (vᵢ − vⱼ)‖²
//!         = tr(Tᵀ A T) − 2 tr(Tᵀ B R) + c,
//!
//! where g(i) is vertex i's cluster and R stacks the transposed cluster rotations (2r × 2). A is
//! 3m × 3m and B is 3m × 2r: after this precomputation an energy evaluation no longer touches
//! the mesh. The lumped-mass Gram matrix G = Σᵢ massᵢ Mᵢᵀ Mᵢ measures handle motion by the area
//! it moves (px² · px²), for the pull toward a reference pose and for momentum.

use super::arap::cotangent_edges;
use crate::geom::Point;
use nalgebra::DMatrix;

/// One skinned mesh of the rig.
#[derive(Clone, Debug)]
pub struct SkinnedMesh {
    pub rest: Vec<Point>,
    pub triangles: Vec<[u32; 3]>,
    /// Vertex i's non-zero weights as (rig column, weight), rows summing to one.
    pub weights: Vec<Vec<(u32, f64)>>,
}

/// The reduced energy's matrices.
#[derive(Clone, Debug)]
pub struct Subspace {
    pub column_count: usize,
    pub cluster_count: usize,
    /// 3m × 3m, symmetric positive semi-definite.
    pub a: DMatrix<f64>,
    /// 3m × 2r.
    pub b: DMatrix<f64>,
    /// 3m × 3m lumped-mass Gram matrix.
    pub gram: DMatrix<f64>,
    /// Σ over directed edges of w‖e‖², px²: the energy of the rest pose's rotation term.
    pub energy_constant: f64,
}

/// Vertex i's row Mᵢ of the skinning matrix, written densely into `out` (length 3m).
pub fn skinning_row(p: Point, weights: &[(u32, f64)], out: &mut [f64]) {
    out.iter_mut().for_each(|x| *x = 0.0);
    add_skinning_row(p, weights, 1.0, out);
}

/// `out += scale · Mᵢ`.
pub fn add_skinning_row(p: Point, weights: &[(u32, f64)], scale: f64, out: &mut [f64]) {
    for &(j, w) in weights {
        let j = 3 * j as usize;
        out[j] += scale * w * p.x;
        out[j + 1] += scale * w * p.y;
        out[j + 2] += scale * w;
    }
}

/// Builds A, B and G for `meshes` over `column_count` columns; `clusters` gives each vertex's
/// cluster, meshes' vertices numbered back to back.
pub fn reduce(
    meshes: &[SkinnedMesh],
    column_count: usize,
    clusters: &[u32],
    cluster_count: usize,
) -> Subspace {
    let n: usize = meshes.iter().map(|m| m.rest.len()).sum();
    let dim = 3 * column_count;
    // Stored transposed (one column per vertex) so that a vertex's row Mᵢ is contiguous: the
    // edge loops below touch two vertices at a time.
    let mut m_t = DMatrix::<f64>::zeros(dim, n);
    let mut lm_t = DMatrix::<f64>::zeros(dim, n);
    let mut mass_m_t = DMatrix::<f64>::zeros(dim, n);
    let mut b = DMatrix::<f64>::zeros(dim, 2 * cluster_count);
    let mut energy_constant = 0.0;
    let mut difference = vec![0.0; dim];
    let mut base = 0;
    for mesh in meshes {
        for (i, (p, w)) in mesh.rest.iter().zip(&mesh.weights).enumerate() {
            skinning_row(*p, w, m_t.column_mut(base + i).as_mut_slice());
        }
        let mut mass = vec![0.0; mesh.rest.len()];
        for t in &mesh.triangles {
            let [a, bb, c] = t.map(|v| mesh.rest[v as usize]);
            let area = 0.5 * ((bb - a).x * (c - a).y - (bb - a).y * (c - a).x).abs();
            for &v in t {
                mass[v as usize] += area / 3.0;
            }
        }
        for (i, m) in mass.iter().enumerate() {
            let row = m_t.column(base + i) * *m;
            mass_m_t.set_column(base + i, &row);
        }
        for e in cotangent_edges(&mesh.rest, &mesh.triangles) {
            if e.weight == 0.0 {
                continue;
            }
            let (i, j) = (e.i as usize, e.j as usize);
            let (gi, gj) = (base + i, base + j);
            let edge = mesh.rest[i] - mesh.rest[j];
            energy_constant += 2.0 * e.weight * edge.norm_squared();
            {
                let (mi, mj) = (m_t.column(gi), m_t.column(gj));
                for (k, d) in difference.iter_mut().enumerate() {
                    *d = e.weight * (mi[k] - mj[k]);
                }
            }
            for (k, &d) in difference.iter().enumerate() {
                lm_t[(k, gi)] += d;
                lm_t[(k, gj)] -= d;
            }
            // Directed i→j uses g(i)'s rotation with (Mᵢ − Mⱼ) and eᵢⱼ; j→i uses g(j)'s with the
            // opposite signs of both, so the same product.
            for cluster in [clusters[gi] as usize, clusters[gj] as usize] {
                let mut bx = b.column_mut(2 * cluster);
                for (k, &d) in difference.iter().enumerate() {
                    bx[k] += d * edge.x;
                }
                let mut by = b.column_mut(2 * cluster + 1);
                for (k, &d) in difference.iter().enumerate() {
                    by[k] += d * edge.y;
                }
            }
        }
        base += mesh.rest.len();
    }
    // Directed edges count each undirected edge twice: A = 2 Mᵀ L M.
    let a = (&m_t * lm_t.transpose()) * 2.0;
    let a = (&a + a.transpose()) * 0.5;
    let gram = &m_t * mass_m_t.transpose();
    let gram = (&gram + gram.transpose()) * 0.5;
    Subspace {
        column_count,
        cluster_count,
        a,
        b,
        gram,
        energy_constant,
    }
}
