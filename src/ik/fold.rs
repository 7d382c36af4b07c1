//! Fold guard: keeps the skinned triangles positively oriented.
//!
//! In: the rig's skinned meshes (rest vertices in canvas px, triangles, weights over the m handle
//! columns) and, per solve, the stacked handle transforms T (3m × 2, as in [`super::subspace`]).
//! Out: the checked triangles whose posed area fell below a share of their rest area, and, for
//! each triangle the solver guards, the linear map U (2 × 3m) with Jᵀ = U T, J the triangle's
//! posed-from-rest Jacobian.
//!
//! Why: the ARAP energy measures distortion, not orientation. Restricted to linear blend skinning,
//! its optimum for a large drag can fold a limb's blend zone over (a waist bent past a right
//! angle, a leg squashed between a pinned foot and a pressed-down hip): the reduced optimum
//! itself inverts triangles there. The solver therefore checks orientation after its iterations
//! and, for every triangle found (nearly) folded, adds a per-triangle rigidity term
//! λ‖J − R‖²_F (Liu, Zhang, Xu, Gotsman & Gortler 2008, "A Local/Global Approach to Mesh
//! Parameterization": the triangle-based ARAP energy; R is the triangle's cluster rotation), then
//! iterates again; a triangle still folded has its λ raised tenfold. This is an active-set
//! variant of the collocation idea of Poranne & Lipman 2014 ("Provably Good Planar Mappings"):
//! orientation is enforced only where it is about to fail, so a frame that folds nothing pays only
//! the check.
//!
//! Which triangles are checked: a triangle whose three vertices all follow one handle with weight
//! one has J equal to that handle's linear part, so one such triangle per handle stands for all
//! of them; every blended triangle is a candidate, and when there are more candidates than the
//! budget, those whose weights change fastest (where linear blending creases) are kept.

use crate::geom::{triangle_area2, Point, Vec2};
use nalgebra::{DMatrix, Matrix2};

use super::subspace::SkinnedMesh;

/// One checked triangle.
#[derive(Clone, Debug)]
struct Checked {
    /// Indices into [`FoldCheck::vertices`].
    corners: [u32; 3],
    /// Twice the rest signed area, px².
    rest_area2: f64,
    /// Inverse of the rest edge matrix [b − a, c − a].
    rest_inverse: Matrix2<f64>,
    /// Rest area, px².
    area: f64,
    /// The cluster of its first vertex, whose rotation the guard pulls toward.
    cluster: u32,
}

/// A vertex of a checked triangle: rest position and sparse weights.
#[derive(Clone, Debug)]
struct CheckedVertex {
    rest: Point,
    weights: Vec<(u32, f64)>,
}

/// The triangles the solver watches, prepared once per rig.
#[derive(Clone, Debug, Default)]
pub struct FoldCheck {
    vertices: Vec<CheckedVertex>,
    triangles: Vec<Checked>,
    column_count: usize,
    /// The checked vertices' skinning rows (n × 3m), when the weights are dense enough that
    /// one matrix product poses them faster than the sparse rows do.
    dense_rows: Option<DMatrix<f64>>,
}

/// Above this share of non-zero weights per checked vertex, the check poses its vertices by
/// one dense matrix product (vectorized) instead of row by row.
const DENSE_SHARE: f64 = 0.25;

/// A triangle that folded (or nearly): its index among the checked ones and its posed / rest
/// area ratio.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fold {
    pub triangle: usize,
    pub area_ratio: f64,
}

impl FoldCheck {
    /// Chooses the checked triangles of `meshes` (see the module doc), at most `budget` blended
    /// ones; `clusters` numbers the meshes' vertices back to back. A zero budget checks nothing.
    pub fn new(
        meshes: &[SkinnedMesh],
        column_count: usize,
        clusters: &[u32],
        budget: usize,
    ) -> Self {
        if budget == 0 {
            return FoldCheck::default();
        }
        // (risk, mesh, triangle, base): blended candidates; and per column its largest rigid one.
        let mut blended: Vec<(f64, usize, usize, usize)> = Vec::new();
        let mut rigid: Vec<Option<(f64, usize, usize, usize)>> = vec![None; column_count];
        let mut base = 0;
        for (mi, mesh) in meshes.iter().enumerate() {
            for (ti, t) in mesh.triangles.iter().enumerate() {
                let [a, b, c] = t.map(|v| mesh.rest[v as usize]);
                let area2 = triangle_area2(a, b, c);
                if area2.abs() < 1e-12 {
                    continue;
                }
                let rows = t.map(|v| &mesh.weights[v as usize]);
                let single = |r: &Vec<(u32, f64)>| match r.as_slice() {
                    [(j, w)] if (*w - 1.0).abs() < 1e-12 => Some(*j),
                    _ => None,
                };
                let one = single(rows[0]);
                if one.is_some() && rows.iter().all(|r| single(r) == one) {
                    let j = one.unwrap_or(0) as usize;
                    if rigid[j].is_none_or(|r| area2.abs() > r.0) {
                        rigid[j] = Some((area2.abs(), mi, ti, base));
                    }
                    continue;
                }
                // Σⱼ |∇wⱼ| over the triangle (px⁻¹): how fast blending changes across it.
                let inverse = edge_inverse(a, b, c);
                let mut gradient = std::collections::BTreeMap::<u32, Vec2>::new();
                for (k, row) in rows.iter().enumerate() {
                    // ∇ of the hat function of corner k in the rest frame.
                    let g = match k {
                        0 => Vec2::new(
                            -(inverse[(0, 0)] + inverse[(1, 0)]),
                            -(inverse[(0, 1)] + inverse[(1, 1)]),
                        ),
                        1 => Vec2::new(inverse[(0, 0)], inverse[(0, 1)]),
                        _ => Vec2::new(inverse[(1, 0)], inverse[(1, 1)]),
                    };
                    for &(j, w) in row.iter() {
                        *gradient.entry(j).or_insert_with(Vec2::zeros) += w * g;
                    }
                }
                let risk: f64 = gradient.values().map(|g| g.norm()).sum();
                blended.push((risk, mi, ti, base));
            }
            base += mesh.rest.len();
        }
        // Most at risk first; ties by position, so the choice is deterministic.
        blended.sort_by(|x, y| y.0.total_cmp(&x.0).then((x.1, x.2).cmp(&(y.1, y.2))));
        blended.truncate(budget);
        let mut chosen: Vec<(usize, usize, usize)> = rigid
            .iter()
            .flatten()
            .chain(&blended)
            .map(|&(_, m, t, b)| (m, t, b))
            .collect();
        chosen.sort_unstable();
        let mut check = FoldCheck {
            column_count,
            ..FoldCheck::default()
        };
        let mut index = std::collections::BTreeMap::<usize, u32>::new();
        for (m, t, base) in chosen {
            let mesh = &meshes[m];
            let tri = mesh.triangles[t];
            let corners = tri.map(|v| {
                *index.entry(base + v as usize).or_insert_with(|| {
                    check.vertices.push(CheckedVertex {
                        rest: mesh.rest[v as usize],
                        weights: mesh.weights[v as usize].clone(),
                    });
                    (check.vertices.len() - 1) as u32
                })
            });
            let [a, b, c] = tri.map(|v| mesh.rest[v as usize]);
            let rest_area2 = triangle_area2(a, b, c);
            check.triangles.push(Checked {
                corners,
                rest_area2,
                rest_inverse: edge_inverse(a, b, c),
                area: 0.5 * rest_area2.abs(),
                cluster: clusters.get(base + tri[0] as usize).copied().unwrap_or(0),
            });
        }
        let nonzero: usize = check.vertices.iter().map(|v| v.weights.len()).sum();
        let n = check.vertices.len();
        if n > 0 && nonzero as f64 > DENSE_SHARE * (n * column_count) as f64 {
            let mut rows = DMatrix::<f64>::zeros(n, 3 * column_count);
            for (i, v) in check.vertices.iter().enumerate() {
                for &(j, w) in &v.weights {
                    let r = 3 * j as usize;
                    rows[(i, r)] = w * v.rest.x;
                    rows[(i, r + 1)] = w * v.rest.y;
                    rows[(i, r + 2)] = w;
                }
            }
            check.dense_rows = Some(rows);
        }
        check
    }

    /// How many triangles are checked.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Whether nothing is checked.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The checked triangles whose posed / rest area ratio under `t` is below `min_ratio`.
    pub fn folds(&self, t: &DMatrix<f64>, min_ratio: f64) -> Vec<Fold> {
        if let Some(rows) = &self.dense_rows {
            let p = rows * t;
            let posed: Vec<Point> = (0..p.nrows())
                .map(|i| Point::new(p[(i, 0)], p[(i, 1)]))
                .collect();
            return self.folds_at(&posed, min_ratio);
        }
        let (t0, t1) = t.as_slice().split_at(t.nrows());
        let posed: Vec<Point> = self
            .vertices
            .iter()
            .map(|v| {
                let (mut x, mut y) = (0.0, 0.0);
                for &(j, w) in &v.weights {
                    let r = 3 * j as usize;
                    let (a, b, c) = (w * v.rest.x, w * v.rest.y, w);
                    x += a * t0[r] + b * t0[r + 1] + c * t0[r + 2];
                    y += a * t1[r] + b * t1[r + 1] + c * t1[r + 2];
                }
                Point::new(x, y)
            })
            .collect();
        self.folds_at(&posed, min_ratio)
    }

    /// The checked triangles below `min_ratio` with their vertices at `posed`.
    fn folds_at(&self, posed: &[Point], min_ratio: f64) -> Vec<Fold> {
        self.triangles
            .iter()
            .enumerate()
            .filter_map(|(k, tri)| {
                let [a, b, c] = tri.corners.map(|v| posed[v as usize]);
                let now = (b - a).perp(&(c - a));
                let ratio = now / tri.rest_area2;
                (ratio < min_ratio).then_some(Fold {
                    triangle: k,
                    area_ratio: ratio,
                })
            })
            .collect()
    }

    /// Checked triangle `k`'s U (2 × 3m, Jᵀ = U T), its rest area (px²) and its cluster.
    pub fn jacobian_map(&self, k: usize) -> (DMatrix<f64>, f64, usize) {
        let tri = &self.triangles[k];
        let dim = 3 * self.column_count;
        // Rows of [ΔM_b; ΔM_c] with ΔM = M_corner − M_a.
        let mut delta = DMatrix::<f64>::zeros(2, dim);
        let a = &self.vertices[tri.corners[0] as usize];
        for (row, corner) in [tri.corners[1], tri.corners[2]].iter().enumerate() {
            for (v, sign) in [(&self.vertices[*corner as usize], 1.0), (a, -1.0)] {
                for &(j, w) in &v.weights {
                    let r = 3 * j as usize;
                    delta[(row, r)] += sign * w * v.rest.x;
                    delta[(row, r + 1)] += sign * w * v.rest.y;
                    delta[(row, r + 2)] += sign * w;
                }
            }
        }
        // J = [d_b d_c] · rest_inverse, so Jᵀ = rest_inverseᵀ · [d_bᵀ; d_cᵀ] = rest_inverseᵀ Δ T.
        let r = tri.rest_inverse.transpose();
        let u = DMatrix::from_column_slice(2, 2, r.as_slice()) * delta;
        (u, tri.area, tri.cluster as usize)
    }
}

/// Inverse of the edge matrix [b − a, c − a] (columns), rows giving the hat gradients of b and c.
fn edge_inverse(a: Point, b: Point, c: Point) -> Matrix2<f64> {
    let (e1, e2) = (b - a, c - a);
    let m = Matrix2::new(e1.x, e2.x, e1.y, e2.y);
    m.try_inverse().unwrap_or_else(Matrix2::zeros)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square of two triangles blended between two handles along x.
    fn square() -> SkinnedMesh {
        SkinnedMesh {
            rest: vec![
                Point::new(0.0, 0.0),
                Point::new(10.0, 0.0),
                Point::new(10.0, 10.0),
                Point::new(0.0, 10.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            weights: vec![
                vec![(0, 1.0)],
                vec![(1, 1.0)],
                vec![(1, 1.0)],
                vec![(0, 1.0)],
            ],
        }
    }

    #[test]
    fn jacobian_map_matches_the_posed_triangle() {
        let mesh = square();
        let check = FoldCheck::new(std::slice::from_ref(&mesh), 2, &[0, 0, 1, 1], 16);
        assert_eq!(check.len(), 2);
        // Handle 1 moves right by 5 and turns a little; handle 0 stays.
        let mut t = DMatrix::<f64>::zeros(6, 2);
        t[(0, 0)] = 1.0;
        t[(1, 1)] = 1.0;
        let (c, s) = (0.9f64.cos(), 0.9f64.sin());
        t[(3, 0)] = c;
        t[(4, 0)] = -s;
        t[(3, 1)] = s;
        t[(4, 1)] = c;
        t[(5, 0)] = 5.0;
        for k in 0..2 {
            let (u, area, _) = check.jacobian_map(k);
            assert!((area - 50.0).abs() < 1e-12);
            let jt = &u * &t;
            let det = jt[(0, 0)] * jt[(1, 1)] - jt[(0, 1)] * jt[(1, 0)];
            let fold = check.folds(&t, f64::INFINITY)[k];
            assert!((det - fold.area_ratio).abs() < 1e-9, "{det} vs {fold:?}");
            // The sparse rows pose the vertices alike.
            let sparse = FoldCheck {
                dense_rows: None,
                ..check.clone()
            };
            assert!(check.dense_rows.is_some());
            assert!((sparse.folds(&t, f64::INFINITY)[k].area_ratio - det).abs() < 1e-9);
        }
    }

    #[test]
    fn a_folded_blend_is_found() {
        let mesh = square();
        let check = FoldCheck::new(std::slice::from_ref(&mesh), 2, &[0, 0, 1, 1], 16);
        // Handle 1 carried 20 px to the left, past handle 0: the blended square turns over.
        let mut t = DMatrix::<f64>::zeros(6, 2);
        for j in 0..2 {
            t[(3 * j, 0)] = 1.0;
            t[(3 * j + 1, 1)] = 1.0;
        }
        assert!(check.folds(&t, 0.1).is_empty());
        t[(5, 0)] = -20.0;
        let folds = check.folds(&t, 0.1);
        assert_eq!(folds.len(), 2);
        assert!(folds.iter().all(|f| f.area_ratio < 0.0));
    }
}
