//! Skinning: rest vertices + sparse weights + one affine map per handle → posed vertices.
//!
//! In: rest positions (canvas px), [`SkinWeights`] (each vertex's non-zero weights, rows summing
//! to one), and one [`Affine`] per handle (rest canvas → posed canvas). Out: posed positions.
//! Linear blend skinning: v' = Σ_j w_ij (A_j v + t_j), evaluated as v + Σ_j w_ij (A_j v + t_j − v)
//! so that identity transforms give back the rest positions bit for bit, whatever rounding the
//! weights' sum carries. Large meshes split across threads.
//!
//! For skinning the same mesh frame after frame, [`LbsPlan`] ([`plan`]) lays the weights out once
//! (fixed influences per vertex, f32, blocks of 16 vertices) and skins in f32 several times
//! faster than [`linear_blend`]. Posing takes the plan ([`crate::scene::Scene`] keeps one per
//! part): render, the editor and the export's bake all skin with it. [`linear_blend`] stays the
//! tests' f64 reference; dual-quaternion and stretchable blending are f64 only.
//!
//! Dual-quaternion blending ([`dual_quaternion_blend`], Kavan, Collins, Žára & O'Sullivan 2008)
//! avoids LBS's collapse at strongly rotated joints: each transform is split by polar
//! decomposition into a rotation and a stretch; stretches blend linearly in the rest frame,
//! rotations and translations blend as unit dual quaternions (in 2D: a half-angle unit complex
//! number and a two-component dual part).

use crate::geom::Point;
use crate::rig::pose::{Affine, BoneStretch};
use rayon::prelude::*;

pub mod plan;
pub use plan::{LbsPlan, PlanError};

/// Sparse weights in compressed rows: vertex i's influences are
/// `handles[offsets[i]..offsets[i+1]]` with `weights[..]` alongside.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SkinWeights {
    pub offsets: Vec<u32>,
    pub handles: Vec<u32>,
    pub weights: Vec<f64>,
}

impl SkinWeights {
    /// From per-vertex lists of (handle, weight).
    pub fn from_rows(rows: &[Vec<(u32, f64)>]) -> Self {
        let mut s = SkinWeights {
            offsets: Vec::with_capacity(rows.len() + 1),
            ..Default::default()
        };
        s.offsets.push(0);
        for row in rows {
            for &(h, w) in row {
                s.handles.push(h);
                s.weights.push(w);
            }
            s.offsets.push(s.handles.len() as u32);
        }
        s
    }

    pub fn vertex_count(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Vertex i's influences.
    pub fn row(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let range = self.offsets[i] as usize..self.offsets[i + 1] as usize;
        self.handles[range.clone()]
            .iter()
            .map(|&h| h as usize)
            .zip(self.weights[range].iter().copied())
    }
}

/// A vertex's `row` of (handle, weight) kept as a runtime with at most `max_influences`
/// influences per vertex keeps it: the positive weights, strongest first (ties by handle, so the
/// choice is deterministic), the `max_influences` strongest (all when `None`), renormalized to
/// sum to one. Empty when no weight is positive. The one rule of every export that limits
/// influences (Spine's `--max-influences`, glTF's four) and of the scenes that play them.
pub fn strongest_influences<H: Copy + Ord>(
    row: &[(H, f64)],
    max_influences: Option<usize>,
) -> Vec<(H, f64)> {
    let mut kept: Vec<(H, f64)> = row.iter().copied().filter(|&(_, w)| w > 0.0).collect();
    kept.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    if let Some(k) = max_influences {
        kept.truncate(k);
    }
    let total: f64 = kept.iter().map(|&(_, w)| w).sum();
    if total.is_nan() || total <= 0.0 {
        return Vec::new();
    }
    for (_, w) in &mut kept {
        *w /= total;
    }
    kept
}

/// Runs `f` on every (index, (rest, out)) pair, across threads for large meshes.
fn for_each_vertex<F>(rest: &[Point], out: &mut [Point], f: F)
where
    F: Fn((usize, (&Point, &mut Point))) + Sync + Send,
{
    if rest.len() >= PARALLEL_MIN_VERTICES {
        rest.par_iter()
            .zip(out.par_iter_mut())
            .enumerate()
            .for_each(f);
    } else {
        rest.iter().zip(out.iter_mut()).enumerate().for_each(f);
    }
}

/// Below this many vertices, threads cost more than they save.
const PARALLEL_MIN_VERTICES: usize = 8192;

/// Linear blend skinning of `rest` into `out` (same length).
pub fn linear_blend(
    rest: &[Point],
    weights: &SkinWeights,
    transforms: &[Affine],
    out: &mut [Point],
) {
    let blend = |(i, (p, o)): (usize, (&Point, &mut Point))| {
        let (mut dx, mut dy) = (0.0, 0.0);
        for (h, w) in weights.row(i) {
            let t = &transforms[h];
            dx += w * ((t.linear[(0, 0)] - 1.0) * p.x + t.linear[(0, 1)] * p.y + t.translation.x);
            dy += w * (t.linear[(1, 0)] * p.x + (t.linear[(1, 1)] - 1.0) * p.y + t.translation.y);
        }
        *o = Point::new(p.x + dx, p.y + dy);
    };
    for_each_vertex(rest, out, blend);
}

/// Linear blend skinning where some handles are stretchable bones: column j with
/// `stretches[j] = Some(s)` contributes `s.rigid(v) + e_j(v) · s.stretch` (see
/// [`BoneStretch`]) instead of its transform; the other columns blend as in [`linear_blend`].
pub fn stretchable_blend(
    rest: &[Point],
    weights: &SkinWeights,
    transforms: &[Affine],
    stretches: &[Option<BoneStretch>],
    out: &mut [Point],
) {
    let blend = |(i, (p, o)): (usize, (&Point, &mut Point))| {
        let mut d = crate::geom::Vec2::zeros();
        for (h, w) in weights.row(i) {
            let moved = match stretches.get(h).copied().flatten() {
                Some(s) => s.rigid.apply(*p) + s.stretch * s.endpoint_weight(*p),
                None => transforms[h].apply(*p),
            };
            d += w * (moved - p);
        }
        *o = p + d;
    };
    for_each_vertex(rest, out, blend);
}

/// How handle transformations blend.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Blend {
    /// Linear blend skinning: fast, exact for affine handles; joints thin when twisted far.
    #[default]
    Linear,
    /// Dual-quaternion skinning: keeps limbs' thickness at strongly rotated joints.
    Dqs,
    /// Linear blending with stretchable bones: a bone scaled along its length stretches its
    /// limb and carries what lies past its tail ([`stretchable_blend`]).
    Stretch,
}

/// Skins `rest` into `out` with the chosen blending.
pub fn skin(
    rest: &[Point],
    weights: &SkinWeights,
    transforms: &[Affine],
    blend: Blend,
    out: &mut [Point],
) {
    match blend {
        // Without per-bone stretch data, stretchable blending is linear blending.
        Blend::Linear | Blend::Stretch => linear_blend(rest, weights, transforms, out),
        Blend::Dqs => dual_quaternion_blend(rest, weights, transforms, out),
    }
}

/// A 2D rigid motion as a unit dual quaternion: rotation (cos φ/2, sin φ/2) about the canvas
/// normal, dual part (dx, dy) = ½ t·q. Canvas angles φ follow the matrix convention of
/// [`Affine::linear`] (y down).
#[derive(Clone, Copy, Debug, PartialEq)]
struct DualQuaternion2 {
    c: f64,
    s: f64,
    dx: f64,
    dy: f64,
}

/// Polar decomposition of a handle's transform: rotation angle (canvas matrix convention),
/// the stretch left after the rotation (Rᵀ A), and the translation.
fn split_rigid(t: &Affine) -> (f64, nalgebra::Matrix2<f64>, crate::geom::Vec2) {
    let a = &t.linear;
    let phi = (a[(1, 0)] - a[(0, 1)]).atan2(a[(0, 0)] + a[(1, 1)]);
    let (sin, cos) = phi.sin_cos();
    let r_transpose = nalgebra::Matrix2::new(cos, sin, -sin, cos);
    (phi, r_transpose * a, t.translation)
}

impl DualQuaternion2 {
    fn from_rotation_translation(phi: f64, t: crate::geom::Vec2) -> Self {
        let (s, c) = (0.5 * phi).sin_cos();
        DualQuaternion2 {
            c,
            s,
            dx: 0.5 * (c * t.x + s * t.y),
            dy: 0.5 * (c * t.y - s * t.x),
        }
    }

    /// Applies the normalized blend to `p`.
    fn apply_normalized(&self, p: Point) -> Point {
        let n = self.c.hypot(self.s);
        let (c, s, dx, dy) = (self.c / n, self.s / n, self.dx / n, self.dy / n);
        let (cos, sin) = (c * c - s * s, 2.0 * c * s);
        let t = crate::geom::Vec2::new(2.0 * (c * dx - s * dy), 2.0 * (s * dx + c * dy));
        Point::new(cos * p.x - sin * p.y + t.x, sin * p.x + cos * p.y + t.y)
    }
}

/// Dual-quaternion skinning of `rest` into `out` (same length).
pub fn dual_quaternion_blend(
    rest: &[Point],
    weights: &SkinWeights,
    transforms: &[Affine],
    out: &mut [Point],
) {
    let parts: Vec<(DualQuaternion2, nalgebra::Matrix2<f64>)> = transforms
        .iter()
        .map(|t| {
            let (phi, stretch, translation) = split_rigid(t);
            (
                DualQuaternion2::from_rotation_translation(phi, translation),
                stretch,
            )
        })
        .collect();
    let blend = |(i, (p, o)): (usize, (&Point, &mut Point))| {
        let mut pivot: Option<DualQuaternion2> = None;
        let mut sum = DualQuaternion2 {
            c: 0.0,
            s: 0.0,
            dx: 0.0,
            dy: 0.0,
        };
        let (mut sx, mut sy) = (0.0, 0.0);
        for (h, w) in weights.row(i) {
            let (q, stretch) = &parts[h];
            // q and −q are the same motion: align every term with the first one.
            let first = *pivot.get_or_insert(*q);
            let w = if first.c * q.c + first.s * q.s < 0.0 {
                -w
            } else {
                w
            };
            sum.c += w * q.c;
            sum.s += w * q.s;
            sum.dx += w * q.dx;
            sum.dy += w * q.dy;
            let w = w.abs();
            sx += w * ((stretch[(0, 0)] - 1.0) * p.x + stretch[(0, 1)] * p.y);
            sy += w * (stretch[(1, 0)] * p.x + (stretch[(1, 1)] - 1.0) * p.y);
        }
        *o = if sum.c == 0.0 && sum.s == 0.0 {
            *p
        } else {
            sum.apply_normalized(Point::new(p.x + sx, p.y + sy))
        };
    };
    for_each_vertex(rest, out, blend);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Vec2;
    use crate::rig::pose::rotation;

    #[test]
    fn identity_and_rigid_transforms_are_reproduced() {
        let rest: Vec<Point> = (0..50)
            .map(|i| Point::new(i as f64, (i * 7 % 13) as f64))
            .collect();
        let rows: Vec<Vec<(u32, f64)>> = (0..50)
            .map(|i| vec![(0, i as f64 / 49.0), (1, 1.0 - i as f64 / 49.0)])
            .collect();
        let weights = SkinWeights::from_rows(&rows);
        let mut out = vec![Point::origin(); 50];
        linear_blend(
            &rest,
            &weights,
            &[Affine::identity(), Affine::identity()],
            &mut out,
        );
        assert_eq!(out, rest);
        // The same rigid motion on every handle moves every vertex rigidly.
        let rigid = Affine {
            linear: rotation(30.0),
            translation: Vec2::new(4.0, -2.0),
        };
        linear_blend(&rest, &weights, &[rigid, rigid], &mut out);
        for (p, q) in rest.iter().zip(&out) {
            assert!((rigid.apply(*p) - q).norm() < 1e-12);
        }
        dual_quaternion_blend(&rest, &weights, &[rigid, rigid], &mut out);
        for (p, q) in rest.iter().zip(&out) {
            assert!((rigid.apply(*p) - q).norm() < 1e-9);
        }
        dual_quaternion_blend(
            &rest,
            &weights,
            &[Affine::identity(), Affine::identity()],
            &mut out,
        );
        assert_eq!(out, rest);
    }

    #[test]
    fn dual_quaternions_keep_volume_where_linear_blending_collapses() {
        // A vertex half-way between two handles, one turned by 180°: LBS collapses it onto the
        // pivot, DQS turns it by 90° at its full distance.
        let rest = [Point::new(10.0, 0.0)];
        let weights = SkinWeights::from_rows(&[vec![(0, 0.5), (1, 0.5)]]);
        let turn = Affine {
            linear: rotation(180.0),
            translation: Vec2::zeros(),
        };
        let mut out = [Point::origin()];
        linear_blend(&rest, &weights, &[Affine::identity(), turn], &mut out);
        assert!(out[0].coords.norm() < 1e-9);
        dual_quaternion_blend(&rest, &weights, &[Affine::identity(), turn], &mut out);
        assert!((out[0].coords.norm() - 10.0).abs() < 1e-9, "{:?}", out[0]);
    }

    #[test]
    fn stretchable_bones_carry_what_lies_past_the_tail() {
        use crate::rig::pose::{bone_stretches, handle_transforms, BonePose, Pose};
        use crate::rig::{Bone, Handles};
        let handles = Handles {
            bones: vec![Bone {
                name: "b".into(),
                parent: None,
                head: Point::new(0.0, 0.0),
                tail: Point::new(10.0, 0.0),
            }],
            ..Default::default()
        };
        let mut pose = Pose::default();
        pose.bones.insert(
            "b".into(),
            BonePose {
                scale: [2.0, 1.0],
                rotate: 90.0,
                ..Default::default()
            },
        );
        let transforms = handle_transforms(&handles, &pose).unwrap();
        let stretches = bone_stretches(&handles, &pose).unwrap();
        let rest = [
            Point::new(5.0, 2.0),
            Point::new(15.0, 0.0),
            Point::new(-3.0, 0.0),
        ];
        let weights = SkinWeights::from_rows(&[vec![(0, 1.0)], vec![(0, 1.0)], vec![(0, 1.0)]]);
        let (mut plain, mut stretched) = ([Point::origin(); 3], [Point::origin(); 3]);
        linear_blend(&rest, &weights, &transforms, &mut plain);
        stretchable_blend(&rest, &weights, &transforms, &stretches, &mut stretched);
        // Along the bone both agree: the limb stretches evenly.
        assert!((plain[0] - stretched[0]).norm() < 1e-9);
        // Past the tail, LBS keeps scaling (15 → 30 along the turned bone); the stretchable
        // bone moves the point with the tail (to 20 + 5).
        assert!(
            (plain[1] - Point::new(0.0, -30.0)).norm() < 1e-9,
            "{:?}",
            plain[1]
        );
        assert!(
            (stretched[1] - Point::new(0.0, -25.0)).norm() < 1e-9,
            "{:?}",
            stretched[1]
        );
        // Behind the head, nothing stretches.
        assert!(
            (stretched[2] - Point::new(0.0, 3.0)).norm() < 1e-9,
            "{:?}",
            stretched[2]
        );
    }

    #[test]
    fn dual_quaternions_carry_scale() {
        let rest = [Point::new(3.0, 4.0)];
        let weights = SkinWeights::from_rows(&[vec![(0, 1.0)]]);
        let t = Affine {
            linear: rotation(30.0) * nalgebra::Matrix2::new(2.0, 0.0, 0.0, 0.5),
            translation: Vec2::new(1.0, 2.0),
        };
        let mut out = [Point::origin()];
        dual_quaternion_blend(&rest, &weights, &[t], &mut out);
        assert!((out[0] - t.apply(rest[0])).norm() < 1e-9);
    }
}
