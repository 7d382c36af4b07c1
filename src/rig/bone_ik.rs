//! Classic bone IK constraints, evaluated inside forward kinematics as game runtimes do.
//!
//! In: [`Handles`] with `ik` constraints and a [`Pose`]. Out: the pose with the constrained
//! bones' local rotations replaced, so that forward kinematics puts the end of each chain on
//! its target bone's head. Constraints apply in file order, each on the pose the previous ones
//! left.
//!
//! One- and two-bone constraints are Spine's IK constraint, computed as the official runtime
//! computes it (spine-core 4.2 `IkConstraint.apply1` / `apply2`, ported term by term), so that
//! a rig exported to Spine with its constraints plays as sinew plays it
//! (`tests/spine_runtime.rs` checks this against spine-core itself):
//!
//! - One bone: it turns so that its x axis points at the target.
//! - Two bones: the law of cosines places the elbow. `bend_positive` gives the child bone a
//!   positive (counter-clockwise on screen) local rotation, as Spine's `bendPositive` does: the
//!   elbow lies clockwise of the line from the chain's root to the target. `softness_px` eases
//!   the last stretch toward full extension so the limb does not snap straight; like Spine's
//!   `softness` it is measured in the frame of the chain root's parent (px while nothing above
//!   the chain is scaled) and scaled by the root's x scale times the mean of 1 and the child's x
//!   scale. The chain root's shear is dropped (Spine does so), and when the root's scale is not
//!   uniform the child's offset across the root is dropped too (Spine's non-uniform solver).
//! - `mix` blends each bone's *local* rotation from its forward-kinematics value (0) to the
//!   solved one (1), the difference wrapped once into [−180°, 180°] as Spine wraps it; the child
//!   blends relative to the already blended root. At mix 1 the chain bones' keyed rotations do
//!   not matter, at 0 the constraint does nothing (not even drop the shear).
//! - Longer chains (no Spine equivalent; the Spine export bakes them): FABRIK (Aristidou &
//!   Lasenby 2011) on the joint positions, then each bone turned by the change of its segment's
//!   world direction (exact while the ancestors' linear parts are similarities), `mix` blending
//!   those changes.
//!
//! The Spine port works in Spine's axes: world and bone frames with y flipped (sinew's y points
//! down), so that spine-core's formulas, signs and special cases carry over unchanged.

use super::frames::{
    bone_rest_frame, bone_world_frames, screen_angle_deg, Affine, Pose, PoseError,
};
pub use super::handles::BoneIk;
use super::handles::Handles;
use crate::geom::Point;

/// FABRIK iterations for chains longer than two bones.
pub const FABRIK_ITERATIONS: usize = 32;
/// FABRIK stops when the chain's end is this close to the target, px.
pub const FABRIK_TOLERANCE_PX: f64 = 1e-4;

/// `pose` with every IK constraint of `handles` applied (see the module doc). Bones a constraint
/// turns appear in the returned pose's `bones` even if `pose` did not name them.
pub fn constrained_pose(handles: &Handles, pose: &Pose) -> Result<Pose, PoseError> {
    let mut out = pose.clone();
    for constraint in &handles.ik {
        let index = |name: &str| {
            handles
                .bones
                .iter()
                .position(|b| b.name == name)
                .ok_or_else(|| PoseError::UnknownName {
                    kind: "bone",
                    name: name.to_string(),
                })
        };
        let chain: Vec<usize> = constraint
            .bones
            .iter()
            .map(|b| index(b))
            .collect::<Result<_, _>>()?;
        let target = index(&constraint.target)?;
        let mix = constraint.applied_mix();
        if mix == 0.0 {
            // Spine skips a constraint at mix 0 entirely.
            continue;
        }
        let frames = bone_world_frames(handles, &out)?;
        let goal = Point::from(frames[target].translation);
        match chain[..] {
            [] => return Err(PoseError::NonFinite(constraint.name.clone())),
            [bone] => {
                let local = SpineLocal::of(handles, &out, bone)?;
                let parent = parent_world(handles, &frames, bone);
                let turn = apply1(&local, &parent, spine_point(goal), mix);
                bone_pose(&mut out, handles, bone).rotate += turn;
            }
            [parent, child] => {
                let solved = apply2(
                    &SpineLocal::of(handles, &out, parent)?,
                    &SpineLocal::of(handles, &out, child)?,
                    &SpineWorld::from_canvas(&frames[parent]),
                    &parent_world(handles, &frames, parent),
                    bone_length(handles, child),
                    spine_point(goal),
                    constraint.bend_positive,
                    constraint.softness_px,
                    mix,
                );
                let rest_y = rest_local(handles, child)?.translation.y;
                let p = bone_pose(&mut out, handles, parent);
                p.rotate += solved.parent_turn_deg;
                if solved.parent_shear_dropped {
                    p.shear = [0.0, 0.0];
                }
                let c = bone_pose(&mut out, handles, child);
                c.rotate += solved.child_turn_deg;
                if let Some(y) = solved.child_y {
                    // Spine's local y is sinew's negated.
                    c.translate[1] = -y - rest_y;
                }
            }
            _ => fabrik_chain(handles, &mut out, &frames, &chain, goal, mix)?,
        }
    }
    Ok(out)
}

fn bone_pose<'a>(
    pose: &'a mut Pose,
    handles: &Handles,
    bone: usize,
) -> &'a mut super::frames::BonePose {
    pose.bones
        .entry(handles.bones[bone].name.clone())
        .or_default()
}

fn bone_length(handles: &Handles, bone: usize) -> f64 {
    let b = &handles.bones[bone];
    (b.tail - b.head).norm()
}

/// A bone's rest frame in its parent's rest frame (the canvas for a root bone), as
/// [`bone_world_frames`] composes it.
fn rest_local(handles: &Handles, bone: usize) -> Result<Affine, PoseError> {
    let b = &handles.bones[bone];
    let rest = bone_rest_frame(b.head, b.tail);
    match b
        .parent
        .as_deref()
        .and_then(|p| handles.bones.iter().find(|x| x.name == p))
    {
        Some(p) => Ok(bone_rest_frame(p.head, p.tail)
            .inverse()
            .ok_or_else(|| PoseError::Singular(b.name.clone()))?
            .then_after(&rest)),
        None => Ok(rest),
    }
}

/// The world frame of `bone`'s parent in Spine's axes (identity at the canvas origin for a root
/// bone: only differences of world positions enter the solvers).
fn parent_world(handles: &Handles, frames: &[Affine], bone: usize) -> SpineWorld {
    let parent = handles.bones[bone]
        .parent
        .as_deref()
        .and_then(|p| handles.bones.iter().position(|x| x.name == p));
    match parent {
        Some(p) => SpineWorld::from_canvas(&frames[p]),
        None => SpineWorld::from_canvas(&Affine::identity()),
    }
}

/// A canvas point in Spine's axes (y flipped).
fn spine_point(p: Point) -> Point {
    Point::new(p.x, -p.y)
}

/// A bone's applied local transform as spine-core holds it (`ax`, `ay`, `arotation`, …): in the
/// parent's frame with y up; rotation and shears in degrees, the rotation including the rest
/// angle.
#[derive(Clone, Copy, Debug)]
struct SpineLocal {
    x: f64,
    y: f64,
    rotation: f64,
    scale_x: f64,
    scale_y: f64,
    shear_x: f64,
}

impl SpineLocal {
    fn of(handles: &Handles, pose: &Pose, bone: usize) -> Result<Self, PoseError> {
        let rest = rest_local(handles, bone)?;
        let local = pose
            .bones
            .get(&handles.bones[bone].name)
            .cloned()
            .unwrap_or_default();
        Ok(SpineLocal {
            x: rest.translation.x + local.translate[0],
            y: -(rest.translation.y + local.translate[1]),
            rotation: screen_angle_deg(rest.linear.column(0).into()) + local.rotate,
            scale_x: local.scale[0],
            scale_y: local.scale[1],
            shear_x: local.shear[0],
        })
    }
}

/// A world transform as spine-core holds it: `a b c d worldX worldY`, y up.
#[derive(Clone, Copy, Debug)]
struct SpineWorld {
    a: f64,
    b: f64,
    c: f64,
    d: f64,
    x: f64,
    y: f64,
}

impl SpineWorld {
    /// `world_from_bone` on the canvas, conjugated by the y flip.
    fn from_canvas(f: &Affine) -> Self {
        SpineWorld {
            a: f.linear[(0, 0)],
            b: -f.linear[(0, 1)],
            c: -f.linear[(1, 0)],
            d: f.linear[(1, 1)],
            x: f.translation.x,
            y: -f.translation.y,
        }
    }
}

/// Spine's single wrap of a rotation difference (`if > 180 −= 360 else if < −180 += 360`).
fn wrap_once(mut a: f64) -> f64 {
    if a > 180.0 {
        a -= 360.0;
    } else if a < -180.0 {
        a += 360.0;
    }
    a
}

/// Determinants at or below this count as singular in spine-core's solvers.
const SPINE_EPSILON: f64 = 1e-4;

/// spine-core `apply1` (inheritance normal, no compress or stretch): the turn (degrees) to add
/// to `bone`'s local rotation.
fn apply1(bone: &SpineLocal, parent: &SpineWorld, target: Point, alpha: f64) -> f64 {
    let (pa, pb, pc, pd) = (parent.a, parent.b, parent.c, parent.d);
    let mut rotation_ik = -bone.shear_x - bone.rotation;
    let (x, y) = (target.x - parent.x, target.y - parent.y);
    let d = pa * pd - pb * pc;
    let (tx, ty) = if d.abs() <= SPINE_EPSILON {
        (0.0, 0.0)
    } else {
        (
            (x * pd - y * pb) / d - bone.x,
            (y * pa - x * pc) / d - bone.y,
        )
    };
    rotation_ik += ty.atan2(tx).to_degrees();
    if bone.scale_x < 0.0 {
        rotation_ik += 180.0;
    }
    wrap_once(rotation_ik) * alpha
}

/// What [`apply2`] changes.
struct TwoBoneSolution {
    parent_turn_deg: f64,
    /// Spine sets the root's shears to 0.
    parent_shear_dropped: bool,
    child_turn_deg: f64,
    /// The child's new local y (Spine's axes), when Spine moves it onto the root's x axis.
    child_y: Option<f64>,
}

/// spine-core `apply2` (inheritance normal, no stretch), term by term.
#[allow(clippy::too_many_arguments)]
fn apply2(
    parent: &SpineLocal,
    child: &SpineLocal,
    parent_world: &SpineWorld,
    grandparent: &SpineWorld,
    child_length: f64,
    target: Point,
    bend_positive: bool,
    softness: f64,
    alpha: f64,
) -> TwoBoneSolution {
    let bend_dir = if bend_positive { 1.0 } else { -1.0 };
    let (px, py) = (parent.x, parent.y);
    let (mut psx, mut psy, mut csx) = (parent.scale_x, parent.scale_y, child.scale_x);
    let (os1, mut s2) = if psx < 0.0 {
        psx = -psx;
        (180.0, -1.0)
    } else {
        (0.0, 1.0)
    };
    if psy < 0.0 {
        psy = -psy;
        s2 = -s2;
    }
    let os2 = if csx < 0.0 {
        csx = -csx;
        180.0
    } else {
        0.0
    };
    let cx = child.x;
    let w = parent_world;
    let uniform = (psx - psy).abs() <= SPINE_EPSILON;
    let (cy, cwx, cwy) = if uniform {
        let cy = child.y;
        (cy, w.a * cx + w.b * cy + w.x, w.c * cx + w.d * cy + w.y)
    } else {
        (0.0, w.a * cx + w.x, w.c * cx + w.y)
    };
    let child_y = (!uniform).then_some(0.0);
    let pp = grandparent;
    let (a, b, c, d) = (pp.a, pp.b, pp.c, pp.d);
    let det = a * d - b * c;
    let id = if det.abs() <= SPINE_EPSILON {
        0.0
    } else {
        1.0 / det
    };
    let (x, y) = (cwx - pp.x, cwy - pp.y);
    let dx = (x * d - y * b) * id - px;
    let dy = (y * a - x * c) * id - py;
    let l1 = dx.hypot(dy);
    let mut l2 = child_length * csx;
    if l1 < SPINE_EPSILON {
        // The child sits on the root's head: the root aims, the child takes rotation 0.
        return TwoBoneSolution {
            parent_turn_deg: apply1(parent, pp, target, alpha),
            parent_shear_dropped: false,
            child_turn_deg: -child.rotation,
            child_y: Some(cy),
        };
    }
    let (x, y) = (target.x - pp.x, target.y - pp.y);
    let (mut tx, mut ty) = ((x * d - y * b) * id - px, (y * a - x * c) * id - py);
    let mut dd = tx * tx + ty * ty;
    if softness != 0.0 {
        let softness = softness * psx * (csx + 1.0) * 0.5;
        let td = dd.sqrt();
        let sd = td - l1 - l2 * psx + softness;
        if sd > 0.0 {
            let p = (sd / (softness * 2.0)).min(1.0) - 1.0;
            let p = (sd - softness * (1.0 - p * p)) / td;
            tx -= p * tx;
            ty -= p * ty;
            dd = tx * tx + ty * ty;
        }
    }
    let (a1, a2);
    if uniform {
        l2 *= psx;
        let mut cos = (dd - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
        let angle2 = if cos < -1.0 {
            cos = -1.0;
            std::f64::consts::PI * bend_dir
        } else if cos > 1.0 {
            cos = 1.0;
            0.0
        } else {
            cos.acos() * bend_dir
        };
        let a = l1 + l2 * cos;
        let b = l2 * angle2.sin();
        a1 = (ty * a - tx * b).atan2(tx * a + ty * b);
        a2 = angle2;
    } else {
        (a1, a2) = non_uniform(l1, l2, psx, psy, tx, ty, dd, bend_dir);
    }
    let os = cy.atan2(cx) * s2;
    let turn1 = wrap_once((a1 - os).to_degrees() + os1 - parent.rotation);
    let turn2 = wrap_once(((a2 + os).to_degrees() - child.shear_x) * s2 + os2 - child.rotation);
    TwoBoneSolution {
        parent_turn_deg: turn1 * alpha,
        parent_shear_dropped: true,
        child_turn_deg: turn2 * alpha,
        child_y,
    }
}

/// spine-core `apply2`'s solver for a root with non-uniform scale (the child's reach is an
/// ellipse): the root and child angles, radians.
#[allow(clippy::too_many_arguments)]
fn non_uniform(
    l1: f64,
    l2: f64,
    psx: f64,
    psy: f64,
    tx: f64,
    ty: f64,
    dd: f64,
    bend_dir: f64,
) -> (f64, f64) {
    let a = psx * l2;
    let b = psy * l2;
    let (aa, bb, ta) = (a * a, b * b, ty.atan2(tx));
    let c = bb * l1 * l1 + aa * dd - aa * bb;
    let c1 = -2.0 * bb * l1;
    let c2 = bb - aa;
    let d = c1 * c1 - 4.0 * c2 * c;
    if d >= 0.0 {
        let mut q = d.sqrt();
        if c1 < 0.0 {
            q = -q;
        }
        q = -(c1 + q) * 0.5;
        let (r0, r1) = (q / c2, c / q);
        let r = if r0.abs() < r1.abs() { r0 } else { r1 };
        let r0 = dd - r * r;
        if r0 >= 0.0 {
            let y = r0.sqrt() * bend_dir;
            return (ta - y.atan2(r), (y / psy).atan2((r - l1) / psx));
        }
    }
    let (mut min_angle, mut min_x, mut min_y) = (std::f64::consts::PI, l1 - a, 0.0);
    let mut min_dist = min_x * min_x;
    let (mut max_angle, mut max_x, mut max_y) = (0.0, l1 + a, 0.0);
    let mut max_dist = max_x * max_x;
    let c = -a * l1 / (aa - bb);
    if (-1.0..=1.0).contains(&c) {
        let c = c.acos();
        let x = a * c.cos() + l1;
        let y = b * c.sin();
        let d = x * x + y * y;
        if d < min_dist {
            (min_angle, min_dist, min_x, min_y) = (c, d, x, y);
        }
        if d > max_dist {
            (max_angle, max_dist, max_x, max_y) = (c, d, x, y);
        }
    }
    if dd <= (min_dist + max_dist) * 0.5 {
        (ta - (min_y * bend_dir).atan2(min_x), min_angle * bend_dir)
    } else {
        (ta - (max_y * bend_dir).atan2(max_x), max_angle * bend_dir)
    }
}

/// A chain of three or more bones by FABRIK: each bone turned by the change of its segment's
/// world direction, times `mix`, minus what its ancestors in the chain already turned it.
fn fabrik_chain(
    handles: &Handles,
    out: &mut Pose,
    frames: &[Affine],
    chain: &[usize],
    goal: Point,
    mix: f64,
) -> Result<(), PoseError> {
    // Joint positions: each bone's head, then the last bone's tail.
    let mut joints: Vec<Point> = chain
        .iter()
        .map(|&i| Point::from(frames[i].translation))
        .collect();
    let last = chain[chain.len() - 1];
    joints.push(frames[last].apply(Point::new(bone_length(handles, last), 0.0)));
    let solved = fabrik(&joints, goal);
    let mut turned = 0.0;
    for (k, &i) in chain.iter().enumerate() {
        let before = screen_angle_deg(joints[k + 1] - joints[k]);
        let after = screen_angle_deg(solved[k + 1] - solved[k]);
        if !before.is_finite() || !after.is_finite() {
            continue;
        }
        let delta = wrap_deg(after - before) * mix;
        bone_pose(out, handles, i).rotate += delta - turned;
        turned = delta;
    }
    Ok(())
}

fn wrap_deg(a: f64) -> f64 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}

/// FABRIK: alternately pull the chain's end to the goal and its root back, keeping lengths.
fn fabrik(joints: &[Point], goal: Point) -> Vec<Point> {
    let lengths: Vec<f64> = joints.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
    let root = joints[0];
    let total: f64 = lengths.iter().sum();
    let mut p = joints.to_vec();
    if (goal - root).norm() >= total {
        for k in 0..lengths.len() {
            p[k + 1] = p[k] + (goal - p[k]).normalize() * lengths[k];
        }
        return p;
    }
    let n = p.len();
    for _ in 0..FABRIK_ITERATIONS {
        p[n - 1] = goal;
        for k in (0..n - 1).rev() {
            p[k] = p[k + 1] + (p[k] - p[k + 1]).normalize() * lengths[k];
        }
        p[0] = root;
        for k in 0..n - 1 {
            p[k + 1] = p[k] + (p[k + 1] - p[k]).normalize() * lengths[k];
        }
        if (p[n - 1] - goal).norm() <= FABRIK_TOLERANCE_PX {
            break;
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::handles::Bone;

    fn arm(constraint: BoneIk) -> Handles {
        let bone = |name: &str, parent: Option<&str>, head: [f64; 2], tail: [f64; 2]| Bone {
            name: name.into(),
            parent: parent.map(Into::into),
            head: head.into(),
            tail: tail.into(),
        };
        Handles {
            bones: vec![
                bone("upper", None, [0.0, 0.0], [100.0, 0.0]),
                bone("lower", Some("upper"), [100.0, 0.0], [180.0, 0.0]),
                bone("hand", Some("lower"), [180.0, 0.0], [200.0, 0.0]),
                bone("target", None, [120.0, -60.0], [130.0, -60.0]),
            ],
            ik: vec![constraint],
            ..Handles::default()
        }
    }

    fn two_bone_constraint(bend_positive: bool) -> BoneIk {
        BoneIk {
            name: "reach".into(),
            bones: vec!["upper".into(), "lower".into()],
            target: "target".into(),
            bend_positive,
            mix: 1.0,
            softness_px: 0.0,
        }
    }

    fn end_of(handles: &Handles, pose: &Pose, bone: usize) -> Point {
        let frames = bone_world_frames(handles, pose).unwrap();
        let b = &handles.bones[bone];
        let length = (b.tail - b.head).norm();
        frames[bone].apply(Point::new(length, 0.0))
    }

    #[test]
    fn two_bones_reach_the_target_on_the_chosen_side() {
        for bend in [true, false] {
            let handles = arm(two_bone_constraint(bend));
            let pose = constrained_pose(&handles, &Pose::default()).unwrap();
            let end = end_of(&handles, &pose, 1);
            assert!(
                (end - Point::new(120.0, -60.0)).norm() < 1e-9,
                "end {end:?}"
            );
            let elbow = Point::from(bone_world_frames(&handles, &pose).unwrap()[1].translation);
            // Which side of the root → target line the elbow lies on (y down: a positive
            // cross product is clockwise on screen).
            let side = (120.0 * elbow.y - (-60.0) * elbow.x).signum();
            assert_eq!(side > 0.0, bend, "bend_positive {bend}: elbow at {elbow:?}");
            // Spine's bendPositive: the child's local rotation comes out positive.
            let child = pose.bones["lower"].rotate;
            assert_eq!(
                child > 0.0,
                bend,
                "bend_positive {bend}: child turned {child}°"
            );
        }
    }

    #[test]
    fn out_of_reach_straightens_and_mix_zero_is_forward_kinematics() {
        let mut c = two_bone_constraint(true);
        let mut handles = arm(c.clone());
        handles.bones[3].head = Point::new(0.0, -400.0);
        let pose = constrained_pose(&handles, &Pose::default()).unwrap();
        let end = end_of(&handles, &pose, 1);
        assert!((end - Point::new(0.0, -180.0)).norm() < 1e-9, "end {end:?}");
        c.mix = 0.0;
        handles.ik = vec![c];
        let pose = constrained_pose(&handles, &Pose::default()).unwrap();
        assert!(pose.bones.values().all(|b| b.rotate.abs() < 1e-12));
    }

    #[test]
    fn softness_eases_before_full_extension() {
        let mut c = two_bone_constraint(true);
        c.softness_px = 20.0;
        let mut handles = arm(c);
        handles.bones[3].head = Point::new(175.0, 0.0);
        let pose = constrained_pose(&handles, &Pose::default()).unwrap();
        let reached = end_of(&handles, &pose, 1).coords.norm();
        assert!(reached < 175.0 && reached > 160.0, "soft reach {reached}");
    }

    #[test]
    fn a_chain_of_three_reaches_by_fabrik() {
        let mut handles = arm(BoneIk {
            name: "chain".into(),
            bones: vec!["upper".into(), "lower".into(), "hand".into()],
            target: "target".into(),
            bend_positive: true,
            mix: 1.0,
            softness_px: 0.0,
        });
        handles.bones[3].head = Point::new(60.0, -120.0);
        let pose = constrained_pose(&handles, &Pose::default()).unwrap();
        let end = end_of(&handles, &pose, 2);
        assert!(
            (end - Point::new(60.0, -120.0)).norm() < 1e-3,
            "end {end:?}"
        );
    }

    #[test]
    fn one_bone_points_its_x_axis_at_the_target() {
        let mut handles = arm(BoneIk {
            name: "aim".into(),
            bones: vec!["lower".into()],
            target: "target".into(),
            bend_positive: true,
            mix: 1.0,
            softness_px: 0.0,
        });
        handles.bones[3].head = Point::new(100.0, -50.0);
        let mut keyed = Pose::default();
        keyed.bones.insert(
            "lower".into(),
            crate::rig::pose::BonePose {
                rotate: 33.0,
                shear: [10.0, 0.0],
                ..Default::default()
            },
        );
        let pose = constrained_pose(&handles, &keyed).unwrap();
        // Straight up on screen from the head at (100, 0); the shear is part of the x axis.
        let end = end_of(&handles, &pose, 1);
        assert!(
            (end - Point::new(100.0, -80.0)).norm() < 1e-9,
            "end {end:?}"
        );
        assert!((pose.bones["lower"].rotate - 80.0).abs() < 1e-9);
    }

    #[test]
    fn mix_blends_local_rotations_wrapped_once_like_spine() {
        let mut keyed = Pose::default();
        keyed.bones.insert(
            "upper".into(),
            crate::rig::pose::BonePose {
                rotate: 170.0,
                ..Default::default()
            },
        );
        let handles = arm(two_bone_constraint(false));
        let full = constrained_pose(&handles, &keyed).unwrap();
        let mut half = two_bone_constraint(false);
        half.mix = 0.5;
        let blended = constrained_pose(&arm(half), &keyed).unwrap();
        // Root: keyed + half the (once-wrapped) way to the solved local rotation.
        let wrap = |a: f64| wrap_once(a);
        let root = 170.0 + 0.5 * wrap(full.bones["upper"].rotate - 170.0);
        assert!((blended.bones["upper"].rotate - root).abs() < 1e-9);
        // Child: from its own keyed local rotation (0), independently of the root's blend.
        let child = 0.5 * wrap(full.bones["lower"].rotate);
        assert!((blended.bones["lower"].rotate - child).abs() < 1e-9);
    }
}
