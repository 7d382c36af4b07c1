//! Classic bone IK constraints, evaluated inside forward kinematics as game runtimes do.
//!
//! In: [`Handles`] with `ik` constraints and a [`Pose`]. Out: the pose with the constrained
//! bones' local rotations replaced, so that forward kinematics puts the end of each chain on
//! its target bone's head. Constraints apply in file order, each on the pose the previous ones
//! left.
//!
//! - One bone: it turns to point at the target.
//! - Two bones (Spine's IK constraint): the law of cosines places the elbow; `bend_positive`
//!   chooses the side it bends to (counter-clockwise on screen when true), `softness_px` eases
//!   the last stretch toward full extension so the limb does not snap straight, `mix` blends
//!   from the forward-kinematics rotations (0) to the solved ones (1).
//! - Longer chains: FABRIK (Aristidou & Lasenby 2011) on the joint positions, then each bone
//!   turned onto its solved direction.
//!
//! Rotations are changed by the difference between the solved and the current world direction,
//! which is exact while the ancestors' linear parts are similarities (rotation and uniform
//! scale), the case runtimes' IK also assumes.

use super::handles::Handles;
use super::pose::{bone_world_frames, screen_angle_deg, Pose, PoseError};
use crate::geom::{Point, Vec2};
use serde::{Deserialize, Serialize};

/// An IK constraint of the handles file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoneIk {
    pub name: String,
    /// The chain, root first; each bone the parent of the next.
    pub bones: Vec<String>,
    /// The bone whose head the chain's end reaches for.
    pub target: String,
    #[serde(default = "default_true")]
    pub bend_positive: bool,
    /// 0: forward kinematics only; 1: fully solved.
    #[serde(default = "default_one")]
    pub mix: f64,
    /// Distance before full extension over which a two-bone chain eases, px.
    #[serde(default)]
    pub softness_px: f64,
}

fn default_true() -> bool {
    true
}

fn default_one() -> f64 {
    1.0
}

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
        let frames = bone_world_frames(handles, &out)?;
        let goal = Point::from(frames[target].translation);
        // Joint positions: each bone's head, then the last bone's tail.
        let mut joints: Vec<Point> = chain
            .iter()
            .map(|&i| Point::from(frames[i].translation))
            .collect();
        let last = *chain
            .last()
            .ok_or_else(|| PoseError::NonFinite(constraint.name.clone()))?;
        let bone = &handles.bones[last];
        let length = Vec2::new(bone.tail[0] - bone.head[0], bone.tail[1] - bone.head[1]).norm();
        joints.push(frames[last].apply(Point::new(length, 0.0)));
        let solved = match chain.len() {
            1 => vec![
                joints[0],
                joints[0] + (goal - joints[0]).normalize() * (joints[1] - joints[0]).norm(),
            ],
            2 => two_bone(
                &joints,
                goal,
                constraint.bend_positive,
                constraint.softness_px,
            ),
            _ => fabrik(&joints, goal),
        };
        let mix = constraint.mix.clamp(0.0, 1.0);
        // Turn each bone by the change of its segment's direction, minus what its ancestors in
        // the chain already turned it.
        let mut turned = 0.0;
        for (k, &i) in chain.iter().enumerate() {
            let before = screen_angle_deg(joints[k + 1] - joints[k]);
            let after = screen_angle_deg(solved[k + 1] - solved[k]);
            if !before.is_finite() || !after.is_finite() {
                continue;
            }
            let delta = wrap_deg(after - before) * mix;
            let local = out.bones.entry(handles.bones[i].name.clone()).or_default();
            local.rotate += delta - turned;
            turned = delta;
        }
    }
    Ok(out)
}

fn wrap_deg(a: f64) -> f64 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}

/// Joint positions of a two-bone chain `[a, b, c]` with its end on `goal` (or as close as the
/// lengths allow).
fn two_bone(joints: &[Point], goal: Point, bend_positive: bool, softness_px: f64) -> Vec<Point> {
    let (a, b, c) = (joints[0], joints[1], joints[2]);
    let (l1, l2) = ((b - a).norm(), (c - b).norm());
    let to_goal = goal - a;
    let mut d = to_goal.norm();
    if d < 1e-12 || l1 < 1e-12 {
        return joints.to_vec();
    }
    let reach = l1 + l2;
    if softness_px > 0.0 {
        // Past `reach − softness` the distance eases toward `reach` instead of snapping there.
        let over = d - reach + softness_px;
        if over > 0.0 {
            let p = (over / (2.0 * softness_px)).min(1.0) - 1.0;
            d -= over - softness_px * (1.0 - p * p);
        }
    }
    let d = d.clamp((l1 - l2).abs(), reach);
    let cos = ((l1 * l1 + d * d - l2 * l2) / (2.0 * l1 * d)).clamp(-1.0, 1.0);
    let alpha = cos.acos().to_degrees();
    let base = screen_angle_deg(to_goal);
    let elbow_angle = if bend_positive {
        base + alpha
    } else {
        base - alpha
    };
    let direction = |deg: f64| {
        let r = (-deg).to_radians();
        Vec2::new(r.cos(), r.sin())
    };
    let elbow = a + direction(elbow_angle) * l1;
    let end = a + to_goal.normalize() * d;
    vec![a, elbow, end]
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
            head,
            tail,
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
        let length = Vec2::new(b.tail[0] - b.head[0], b.tail[1] - b.head[1]).norm();
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
            // Which side of the root → target line the elbow lies on (y down).
            let side = (120.0 * elbow.y - (-60.0) * elbow.x).signum();
            assert_eq!(side < 0.0, bend, "bend_positive {bend}: elbow at {elbow:?}");
        }
    }

    #[test]
    fn out_of_reach_straightens_and_mix_zero_is_forward_kinematics() {
        let mut c = two_bone_constraint(true);
        let mut handles = arm(c.clone());
        handles.bones[3].head = [0.0, -400.0];
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
        handles.bones[3].head = [175.0, 0.0];
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
        handles.bones[3].head = [60.0, -120.0];
        let pose = constrained_pose(&handles, &Pose::default()).unwrap();
        let end = end_of(&handles, &pose, 2);
        assert!(
            (end - Point::new(60.0, -120.0)).norm() < 1e-3,
            "end {end:?}"
        );
    }
}
