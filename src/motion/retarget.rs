//! Retargeting: a capture clip played by a 2D rig.
//!
//! In: the rig's [`Handles`] (canvas px, y down), a [`Clip`] (the file's units, y up), a
//! [`JointMap`] (which source segment drives which bone) and [`RetargetOptions`]. Out: an
//! [`Animation`] of the rig (rotate keys of the driven bones and of the legs IK moves,
//! translate keys of the root bones) and a [`RetargetReport`] of what was chosen.
//!
//! How (after Animated Drawings' retargeting, Smith et al. 2023, with feet, loops and keys):
//!
//! 1. **Projection per limb group.** The performer's facing is read from the capture (the
//!    horizontal line from the right thigh to the left one, averaged over the clip, is the
//!    performer's left; forward is left × up). Each group (legs, arms, torso) is projected on
//!    the sagittal plane (a side view) or the frontal plane (a front view). [`View::Auto`]
//!    picks, per group, the plane along whose in-plane horizontal axis the group's joints
//!    move the most around the hips (a walk's legs swing forward and back: side; a jumping
//!    jack's arms swing out: front); the torso follows the legs.
//! 2. **Bones keep their length.** Each driven bone takes the screen angle of its projected
//!    segment; bones not driven keep their rest angle relative to their parent. Only rotations
//!    change, so lengths are exact. A segment foreshortened below
//!    [`RetargetOptions::foreshortened_fraction`] of its length holds its last angle.
//! 3. **The root travels** by the hips' projected motion scaled by the rig's leg length over
//!    the performer's (`leg_scale`); the height is the hips' height above the capture's ground,
//!    so that legs at full stretch stand on the rig's ground (its lowest ankle at rest; legs
//!    drawn splayed or bent lift the root until, straight, they reach it). Every
//!    root bone takes that translation (rigs whose arms are roots move them along).
//! 4. **Feet stay planted.** A foot is in contact where it is within
//!    [`RetargetOptions::contact_height_fraction`] of leg length of the capture's ground and
//!    moves slower than [`RetargetOptions::contact_speed_fraction`] leg lengths per second.
//!    During a contact the ankle is held where the contact began, on the ground line, by
//!    analytic two-bone IK on thigh and shin (the knee bends the way the capture bends it);
//!    where the leg cannot reach, the root is lowered. Out of contact, no ankle goes below the
//!    ground line. After a contact the foot eases back to the capture's motion over
//!    [`RetargetOptions::release_frames`].
//! 5. **Loops without a seam.** A clip with a frame in its second half within
//!    [`RetargetOptions::loop_max_seam_deg`] of its first pose (every driven angle) is a cycle:
//!    it is cut at the best such frame and the remaining difference is blended into its last
//!    [`RetargetOptions::loop_blend_fraction`], so the last frame is the first ([`LoopMode`]; the library says which of its
//!    clips loop). `in_place` removes the root's horizontal travel (its least-squares line),
//!    keeping the sway.
//! 6. **Editable keys.** Every channel is reduced to Bézier keys within
//!    [`RetargetOptions::rotate_tolerance_deg`] / [`RetargetOptions::translate_tolerance_px`]
//!    ([`super::keys::reduce`]).
//!
//! Angles are sinew's: degrees, counter-clockwise on screen.

use super::bvh::Clip;
use super::fk::{frame_positions, rest_positions, FramePositions};
use super::keys;
use super::map::{JointMap, Segment, SegmentEnd, Side, SourceJoint};
use crate::anim::timeline::{Animation, BoneTimelines};
use crate::geom::{Point, Vec2};
use crate::rig::frames::{bone_world_frames, screen_angle_deg, BonePose};
use crate::rig::{Handles, Pose, PoseError};
use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Which plane a limb group is projected on.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum View {
    /// Per group, the plane of its largest motion.
    #[default]
    Auto,
    /// The sagittal plane: the character seen in profile.
    Side,
    /// The frontal plane: the character facing the viewer.
    Front,
}

/// Which way a character seen from the side faces on screen.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum Facing {
    /// Forward is +x on screen.
    #[default]
    Right,
    Left,
}

/// Whether the clip is made to loop.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum LoopMode {
    /// A cycle when its ends are within [`RetargetOptions::loop_max_seam_deg`].
    #[default]
    Auto,
    /// Always spread the seam.
    Blend,
    /// Never.
    Off,
}

/// How a clip is retargeted; every field has a default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct RetargetOptions {
    /// Default [`View::Auto`].
    pub view: View,
    /// Default [`Facing::Right`].
    pub facing: Facing,
    /// No horizontal travel of the root (its sway kept). Default false.
    pub in_place: bool,
    /// Default [`LoopMode::Auto`].
    pub loop_mode: LoopMode,
    /// A clip is a cycle when one of the frames of its second half has no driven angle more
    /// than this from the first frame's, degrees (the clip is then cut there). Default 12.
    pub loop_max_seam_deg: f64,
    /// A foot within this many leg lengths of the capture's ground may be in contact.
    /// Default 0.08.
    pub contact_height_fraction: f64,
    /// ... and moving slower than this many leg lengths per second. Default 0.6.
    pub contact_speed_fraction: f64,
    /// A loop's remaining seam is blended into this last fraction of the clip. Default 0.3.
    pub loop_blend_fraction: f64,
    /// Contacts shorter than this many frames are ignored. Default 2.
    pub min_contact_frames: usize,
    /// Frames over which a released foot eases back to the capture's motion. Default 3.
    pub release_frames: usize,
    /// A projected segment shorter than this fraction of its 3D length holds the previous
    /// frame's angle (pointing at the viewer, its direction on screen is noise). Default 0.2.
    pub foreshortened_fraction: f64,
    /// Keys fit every frame's rotations within this, degrees. Default 0.5.
    pub rotate_tolerance_deg: f64,
    /// ... and translations within this, px. Default 0.5.
    pub translate_tolerance_px: f64,
    /// The bones from the root to each ankle are keyed tighter, so that the keys move no ankle
    /// more than this many leg lengths from its frame's pose (the ground line and planted
    /// feet hold in what plays, not only in the frames). Default 0.006.
    pub ground_tolerance_fraction: f64,
}

impl Default for RetargetOptions {
    fn default() -> Self {
        RetargetOptions {
            view: View::Auto,
            facing: Facing::Right,
            in_place: false,
            loop_mode: LoopMode::Auto,
            loop_max_seam_deg: 12.0,
            loop_blend_fraction: 0.3,
            contact_height_fraction: 0.08,
            contact_speed_fraction: 0.6,
            min_contact_frames: 2,
            release_frames: 3,
            foreshortened_fraction: 0.2,
            rotate_tolerance_deg: 0.5,
            translate_tolerance_px: 0.5,
            ground_tolerance_fraction: 0.006,
        }
    }
}

/// What went wrong.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RetargetError {
    #[error("the capture has no frames")]
    NoFrames,
    #[error("the capture's frame time is not a positive number")]
    BadFrameTime,
    #[error("the rig has no root bone")]
    NoRoot,
    #[error("the capture has no hips (a joint named Hips, Hip, Pelvis or Root)")]
    NoHips,
    #[error("a capture frame has a position that is not a finite number")]
    NonFinite,
    #[error(transparent)]
    Pose(#[from] PoseError),
}

/// A limb group, projected on one plane.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum Group {
    Legs,
    Arms,
    Torso,
}

/// What retargeting chose and did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct RetargetReport {
    /// The plane each group present was projected on (never `auto`).
    pub views: BTreeMap<Group, View>,
    /// The bones the capture drives.
    pub driven: Vec<String>,
    /// Rig px per capture unit.
    pub leg_scale: f64,
    /// Foot contacts planted (both feet).
    pub contacts: usize,
    /// Whether the clip was made to loop (its seam spread).
    pub looped: bool,
    /// Frames sampled, and keys written (all channels).
    pub frames: usize,
    pub keys: usize,
    pub duration_s: f64,
}

/// A retargeted clip.
#[derive(Clone, Debug, PartialEq)]
pub struct Retargeted {
    pub animation: Animation,
    /// One pose per capture frame, before key reduction (what the keys fit).
    pub poses: Vec<Pose>,
    pub report: RetargetReport,
}

/// The performer's axes in the capture's frame: left, forward, up (unit vectors).
#[derive(Clone, Copy, Debug)]
pub struct Axes {
    pub left: Vector3<f64>,
    pub forward: Vector3<f64>,
}

impl Axes {
    /// From the thighs (else the upper arms), averaged over the frames.
    pub fn of(clip: &Clip, frames: &[FramePositions]) -> Axes {
        let pair = [
            (
                SourceJoint::Thigh(Side::Left),
                SourceJoint::Thigh(Side::Right),
            ),
            (
                SourceJoint::UpperArm(Side::Left),
                SourceJoint::UpperArm(Side::Right),
            ),
        ]
        .into_iter()
        .find_map(|(l, r)| Some((l.resolve(clip)?, r.resolve(clip)?)));
        let mut left = Vector3::zeros();
        if let Some((l, r)) = pair {
            for f in frames {
                let d = f.joints[l.index()] - f.joints[r.index()];
                left += Vector3::new(d.x, 0.0, d.z);
            }
        }
        let left = left.try_normalize(1e-12).unwrap_or_else(Vector3::x);
        let forward = left.cross(&Vector3::y());
        Axes { left, forward }
    }

    /// `p` on screen in capture units, y down: seen from the side (`facing` forward) or from
    /// the front (the performer's left on the right).
    pub fn project(&self, view: View, facing: Facing, p: Point3<f64>) -> Point {
        let sign = match facing {
            Facing::Right => 1.0,
            Facing::Left => -1.0,
        };
        match view {
            View::Front => Point::new(p.coords.dot(&self.left), -p.y),
            View::Side | View::Auto => Point::new(sign * p.coords.dot(&self.forward), -p.y),
        }
    }
}

/// The group a driven bone belongs to, by its source joint.
fn group_of(clip: &Clip, segment: &Segment) -> Group {
    let is = |joints: &[SourceJoint]| joints.iter().any(|j| j.resolve(clip) == Some(segment.from));
    let sided = |f: fn(Side) -> SourceJoint| [f(Side::Left), f(Side::Right)];
    let legs: Vec<SourceJoint> = [
        SourceJoint::Thigh,
        SourceJoint::Shin,
        SourceJoint::Foot,
        SourceJoint::Toe,
    ]
    .into_iter()
    .flat_map(sided)
    .collect();
    let arms: Vec<SourceJoint> = [
        SourceJoint::UpperArm,
        SourceJoint::Forearm,
        SourceJoint::Hand,
    ]
    .into_iter()
    .flat_map(sided)
    .collect();
    if is(&legs) {
        Group::Legs
    } else if is(&arms) {
        Group::Arms
    } else {
        Group::Torso
    }
}

fn end_point(f: &FramePositions, end: SegmentEnd) -> Option<Point3<f64>> {
    match end {
        SegmentEnd::Joint(j) => f.joint(j),
        SegmentEnd::EndSite(j) => f.end_site(j),
    }
}

/// Wraps an angle difference to (-180, 180].
fn wrap_deg(a: f64) -> f64 {
    let w = a.rem_euclid(360.0);
    if w > 180.0 {
        w - 360.0
    } else {
        w
    }
}

/// The planes each group is seen on: fixed by `view`, else the plane along whose horizontal
/// axis the group's joints move most around the hips.
fn choose_views(
    clip: &Clip,
    map: &JointMap,
    frames: &[FramePositions],
    axes: &Axes,
    hips: usize,
    view: View,
) -> BTreeMap<Group, View> {
    let mut groups: BTreeMap<Group, Vec<usize>> = BTreeMap::new();
    for segment in map.bones.values() {
        groups
            .entry(group_of(clip, segment))
            .or_default()
            .push(segment.from.index());
    }
    let mut views = BTreeMap::new();
    for (&group, joints) in &groups {
        let chosen = match view {
            View::Side | View::Front => view,
            View::Auto => {
                // Each joint's own motion over the clip (not the spread between joints: the
                // two legs stand apart along the left axis all the time).
                let variance = |axis: &Vector3<f64>| {
                    joints
                        .iter()
                        .map(|&j| {
                            let values: Vec<f64> = frames
                                .iter()
                                .map(|f| (f.joints[j] - f.joints[hips]).dot(axis))
                                .collect();
                            let n = values.len().max(1) as f64;
                            let mean = values.iter().sum::<f64>() / n;
                            values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n
                        })
                        .sum::<f64>()
                };
                if variance(&axes.forward) >= variance(&axes.left) {
                    View::Side
                } else {
                    View::Front
                }
            }
        };
        views.insert(group, chosen);
    }
    if view == View::Auto {
        if let Some(legs) = views.get(&Group::Legs).copied() {
            if let Some(torso) = views.get_mut(&Group::Torso) {
                *torso = legs;
            }
        }
    }
    views
}

/// A rig bone's rest data: its index, parent index, rest world angle and length.
struct RestBone {
    parent: Option<usize>,
    angle_deg: f64,
    length_px: f64,
}

/// Bones in an order where each parent comes before its children (a cycle, which validated
/// handles never have, is cut where the walk up meets it again).
fn parents_first(rest: &[RestBone]) -> Vec<usize> {
    let mut order = Vec::with_capacity(rest.len());
    let mut placed = vec![false; rest.len()];
    for i in 0..rest.len() {
        // The unplaced ancestors of `i`, nearest first, then placed root-most first.
        let mut chain = vec![i];
        while let Some(p) = rest[*chain.last().unwrap_or(&i)].parent {
            if placed[p] || chain.contains(&p) {
                break;
            }
            chain.push(p);
        }
        for &b in chain.iter().rev() {
            if !placed[b] {
                placed[b] = true;
                order.push(b);
            }
        }
    }
    order
}

/// Two-bone IK in the plane: thigh from `hip` (length `l1`), shin (length `l2`), ankle at
/// `target`; the knee on the side `bend` (the sign of (knee − hip) × (target − hip)). Returns
/// the world angles of the two bones, degrees. An unreachable target is reached toward.
fn two_bone(hip: Point, target: Point, l1: f64, l2: f64, bend: f64) -> (f64, f64) {
    let d = target - hip;
    let reach = d
        .norm()
        .clamp((l1 - l2).abs() + 1e-9, l1 + l2 - 1e-9)
        .max(1e-9);
    let dir = d
        .try_normalize(1e-12)
        .unwrap_or_else(|| Vec2::new(0.0, 1.0));
    let cos_a = ((l1 * l1 + reach * reach - l2 * l2) / (2.0 * l1 * reach)).clamp(-1.0, 1.0);
    let a = cos_a.acos() * if bend >= 0.0 { -1.0 } else { 1.0 };
    // Rotate `dir` by `a` in canvas axes (y down).
    let (s, c) = a.sin_cos();
    let upper = Vec2::new(c * dir.x - s * dir.y, s * dir.x + c * dir.y);
    let knee = hip + upper * l1;
    let ankle = hip + dir * reach;
    (screen_angle_deg(upper), screen_angle_deg(ankle - knee))
}

/// The cross product's sign of (knee − hip) × (ankle − hip): which way a leg bends.
fn bend_sign(hip: Point, knee: Point, ankle: Point) -> f64 {
    let (a, b) = (knee - hip, ankle - hip);
    a.x * b.y - a.y * b.x
}

/// Poses `leg` (world angles in `world`, degrees) so that its ankle reaches `target`, the knee
/// bending as it did (`now`: hip, knee and ankle before); bones below the leg that the capture
/// does not drive (`driven`) follow it.
fn solve_leg(
    world: &mut [f64],
    leg: &Leg,
    (hip, knee, ankle): (Point, Point, Point),
    target: Point,
    rest: &[RestBone],
    order: &[usize],
    driven: &dyn Fn(usize) -> bool,
) {
    let (upper, lower) = two_bone(
        hip,
        target,
        rest[leg.thigh].length_px,
        rest[leg.shin].length_px,
        bend_sign(hip, knee, ankle),
    );
    world[leg.thigh] = upper;
    world[leg.shin] = lower;
    for &i in order {
        let mut at = rest[i].parent;
        while at.is_some_and(|p| p != leg.thigh) {
            at = at.and_then(|p| rest[p].parent);
        }
        if at.is_some() && i != leg.shin && !driven(i) {
            if let Some(p) = rest[i].parent {
                world[i] = world[p] + rest[i].angle_deg - rest[p].angle_deg;
            }
        }
    }
}

/// One leg of the rig: its thigh and shin bones (indices), and its side.
struct Leg {
    thigh: usize,
    shin: usize,
    side: Side,
}

/// Per frame, whether the foot of `side` is on the ground in the capture.
fn contacts(
    clip: &Clip,
    frames: &[FramePositions],
    side: Side,
    ground_y: f64,
    leg_len: f64,
    options: &RetargetOptions,
    cyclic: bool,
) -> Vec<bool> {
    let Some(foot) = SourceJoint::Foot(side).resolve(clip) else {
        return vec![false; frames.len()];
    };
    let toe = SourceJoint::Toe(side).resolve(clip);
    let dt = clip.frame_time_s;
    let n = frames.len();
    let hips = SourceJoint::Hips.resolve(clip).map_or(0, |h| h.index());
    // One cycle's travel: in a loop, the frame before the first is the one before the last,
    // moved back by it.
    let cycle = frames[n - 1].joints[hips] - frames[0].joints[hips];
    let at = |f: usize| frames[f].joints[foot.index()];
    let mut on: Vec<bool> = (0..n)
        .map(|f| {
            let p = at(f);
            let low = toe.map_or(p.y, |t| p.y.min(frames[f].joints[t.index()].y));
            let v = if cyclic && n >= 3 && (f == 0 || f == n - 1) {
                (at(1) - (at(n - 2) - cycle)) / (2.0 * dt)
            } else {
                let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
                (at(b) - at(a)) / ((b - a).max(1) as f64 * dt)
            };
            let speed = Vector3::new(v.x, 0.0, v.z).norm();
            low - ground_y <= options.contact_height_fraction * leg_len
                && speed <= options.contact_speed_fraction * leg_len
        })
        .collect();

    // Drop runs shorter than the minimum.
    let mut f = 0;
    while f < n {
        if !on[f] {
            f += 1;
            continue;
        }
        let start = f;
        while f < n && on[f] {
            f += 1;
        }
        if f - start < options.min_contact_frames {
            on[start..f].iter_mut().for_each(|c| *c = false);
        }
    }
    if cyclic && n >= 2 {
        // The last frame is the first: a contact at either end runs across the seam.
        let both = on[0] || on[n - 1];
        on[0] = both;
        on[n - 1] = both;
    }
    on
}

/// The capture's ground height: the lowest any foot joint goes over the clip (infinite when
/// the capture has no feet).
fn source_ground(clip: &Clip, frames: &[FramePositions]) -> f64 {
    [Side::Left, Side::Right]
        .into_iter()
        .filter_map(|s| SourceJoint::Foot(s).resolve(clip))
        .flat_map(|j| frames.iter().map(move |f| f.joints[j.index()].y))
        .fold(f64::INFINITY, f64::min)
}

/// The performer's leg length at rest (thigh + shin, the longer side), capture units; 0
/// without legs.
fn source_leg(clip: &Clip, rest: &FramePositions) -> f64 {
    [Side::Left, Side::Right]
        .into_iter()
        .filter_map(|side| {
            let (t, s, f) = (
                SourceJoint::Thigh(side).resolve(clip)?,
                SourceJoint::Shin(side).resolve(clip)?,
                SourceJoint::Foot(side).resolve(clip)?,
            );
            let p = |j: super::bvh::JointId| rest.joints[j.index()];
            Some((p(s) - p(t)).norm() + (p(f) - p(s)).norm())
        })
        .fold(0.0f64, f64::max)
}

/// Per side whose foot the capture has, the frames where that foot is on the ground
/// ([`RetargetOptions::contact_height_fraction`], [`RetargetOptions::contact_speed_fraction`]).
/// `cyclic`: the clip is one loop of a cycle (as [`RetargetReport::looped`] says).
pub fn foot_contacts(
    clip: &Clip,
    options: &RetargetOptions,
    cyclic: bool,
) -> Vec<(Side, Vec<bool>)> {
    let frames: Vec<FramePositions> = (0..clip.frame_count())
        .filter_map(|f| frame_positions(clip, f))
        .collect();
    let ground = source_ground(clip, &frames);
    let leg = source_leg(clip, &rest_positions(clip));
    if !ground.is_finite() || leg <= 0.0 || frames.is_empty() {
        return Vec::new();
    }
    [Side::Left, Side::Right]
        .into_iter()
        .filter(|&s| SourceJoint::Foot(s).resolve(clip).is_some())
        .map(|s| (s, contacts(clip, &frames, s, ground, leg, options, cyclic)))
        .collect()
}

/// Blends the difference between the last and the first value into the series' last
/// `window` fraction (a smoothstep ramp from 0 to the whole difference), so that the last
/// value is the first (plus whole turns for angles when `turn` is 360) and the frames before
/// the window are untouched.
fn spread_seam(values: &mut [f64], turn: Option<f64>, window: f64) {
    let n = values.len();
    if n < 2 {
        return;
    }
    let mut drift = values[n - 1] - values[0];
    if let Some(turn) = turn {
        drift -= turn * (drift / turn).round();
    }
    let last = (n - 1) as f64;
    let start = last * (1.0 - window.clamp(1.0 / last, 1.0));
    for (i, v) in values.iter_mut().enumerate() {
        let s = ((i as f64 - start) / (last - start)).clamp(0.0, 1.0);
        *v -= drift * s * s * (3.0 - 2.0 * s);
    }
}

/// Makes a series of angles continuous (no jumps of more than half a turn).
fn unwrap(values: &mut [f64]) {
    for i in 1..values.len() {
        values[i] = values[i - 1] + wrap_deg(values[i] - values[i - 1]);
    }
}

/// Retargets `clip` onto the rig of `handles` with `map`.
pub fn retarget(
    handles: &Handles,
    clip: &Clip,
    map: &JointMap,
    options: &RetargetOptions,
) -> Result<Retargeted, RetargetError> {
    let mut n = clip.frame_count();
    if n == 0 {
        return Err(RetargetError::NoFrames);
    }
    if !(clip.frame_time_s.is_finite() && clip.frame_time_s > 0.0) {
        return Err(RetargetError::BadFrameTime);
    }
    let mut frames: Vec<FramePositions> = (0..n)
        .map(|f| frame_positions(clip, f).ok_or(RetargetError::NoFrames))
        .collect::<Result<_, _>>()?;
    if frames.iter().any(|f| {
        f.joints
            .iter()
            .any(|p| !p.coords.iter().all(|v| v.is_finite()))
    }) {
        return Err(RetargetError::NonFinite);
    }
    let rest_src = rest_positions(clip);
    let hips = SourceJoint::Hips
        .resolve(clip)
        .or_else(|| clip.ids().next())
        .ok_or(RetargetError::NoHips)?
        .index();
    let axes = Axes::of(clip, &frames);
    let views = choose_views(clip, map, &frames, &axes, hips, options.view);
    let view_of = |bone: &str| -> View {
        map.bones
            .get(bone)
            .map(|s| group_of(clip, s))
            .and_then(|g| views.get(&g).copied())
            .unwrap_or(View::Side)
    };
    let root_view = views
        .get(&Group::Torso)
        .or_else(|| views.get(&Group::Legs))
        .copied()
        .unwrap_or(View::Side);

    // The rig at rest.
    let index: BTreeMap<&str, usize> = handles
        .bones
        .iter()
        .enumerate()
        .map(|(i, b)| (b.name.as_str(), i))
        .collect();
    let rest: Vec<RestBone> = handles
        .bones
        .iter()
        .map(|b| RestBone {
            parent: b.parent.as_deref().and_then(|p| index.get(p).copied()),
            angle_deg: screen_angle_deg(b.tail - b.head),
            length_px: (b.tail - b.head).norm(),
        })
        .collect();
    let rest_local =
        |i: usize| -> f64 { rest[i].angle_deg - rest[i].parent.map_or(0.0, |p| rest[p].angle_deg) };
    let order = parents_first(&rest);
    let roots: Vec<usize> = (0..rest.len())
        .filter(|&i| rest[i].parent.is_none())
        .collect();
    if roots.is_empty() {
        return Err(RetargetError::NoRoot);
    }
    // The rig's legs (a person's two, an animal's four), each with the capture foot whose
    // contacts plant it: the side of the thigh's driving joint.
    let legs: Vec<Leg> = ["", "back_", "front_"]
        .into_iter()
        .flat_map(|end| ["l", "r"].map(move |s| (end, s)))
        .filter_map(|(end, s)| {
            let thigh_name = format!("leg_{end}upper_{s}");
            let thigh = *index.get(thigh_name.as_str())?;
            let shin = *index.get(format!("leg_{end}lower_{s}").as_str())?;
            let from = map.bones.get(&thigh_name)?.from;
            let side = [Side::Left, Side::Right]
                .into_iter()
                .find(|&side| SourceJoint::Thigh(side).resolve(clip) == Some(from))?;
            Some(Leg { thigh, shin, side })
        })
        .collect();

    // Scale: the rig's leg over the performer's.
    let src_leg = source_leg(clip, &rest_src);
    let rig_leg = legs
        .iter()
        .map(|l| rest[l.thigh].length_px + rest[l.shin].length_px)
        .fold(0.0f64, f64::max);
    let (src_size, rig_size) = if src_leg > 0.0 && rig_leg > 0.0 {
        (src_leg, rig_leg)
    } else {
        // No legs: the driven bones' lengths against their segments' at rest.
        map.bones.iter().fold((0.0, 0.0), |(s, r), (bone, seg)| {
            let a = rest_src.joints[seg.from.index()];
            let len = end_point(&rest_src, seg.to).map_or(0.0, |b| (b - a).norm());
            (
                s + len,
                r + index.get(bone.as_str()).map_or(0.0, |&i| rest[i].length_px),
            )
        })
    };
    let leg_scale = if src_size > 0.0 {
        rig_size / src_size
    } else {
        1.0
    };
    let leg_src = if src_leg > 0.0 {
        src_leg
    } else {
        src_size.max(1e-9)
    };

    // Driven angles per frame, continuous in time.
    let driven: Vec<(usize, Segment)> = map
        .bones
        .iter()
        .filter_map(|(name, seg)| Some((*index.get(name.as_str())?, *seg)))
        .collect();
    let mut angles: Vec<Vec<f64>> = Vec::with_capacity(driven.len());
    for &(bone, seg) in &driven {
        let view = view_of(&handles.bones[bone].name);
        let mut series = Vec::with_capacity(n);
        let mut last = rest[bone].angle_deg;
        for f in &frames {
            let a = f.joints[seg.from.index()];
            if let Some(b) = end_point(f, seg.to) {
                let on_screen =
                    axes.project(view, options.facing, b) - axes.project(view, options.facing, a);
                if on_screen.norm() > options.foreshortened_fraction * (b - a).norm() {
                    last = screen_angle_deg(on_screen);
                }
            }
            series.push(last);
        }
        unwrap(&mut series);
        angles.push(series);
    }
    // A loop ends at the frame of the clip's second half that best matches the first (a
    // capture rarely ends exactly one cycle after it starts): the clip is cut there, and what
    // differences remain are spread.
    let seam_at = |k: usize| -> f64 {
        angles
            .iter()
            .map(|s| wrap_deg(s[k] - s[0]).abs())
            .fold(0.0, f64::max)
    };
    let cut = (n / 2).max(2)..n;
    let best = cut
        .clone()
        .min_by(|&a, &b| seam_at(a).total_cmp(&seam_at(b)).then(b.cmp(&a)))
        .filter(|_| n >= 3);
    let looped = match (options.loop_mode, best) {
        (LoopMode::Off, _) | (_, None) => false,
        (LoopMode::Blend, Some(_)) => true,
        (LoopMode::Auto, Some(k)) => seam_at(k) <= options.loop_max_seam_deg,
    };
    if let (true, Some(k)) = (looped, best) {
        n = k + 1;
        frames.truncate(n);
        angles.iter_mut().for_each(|s| s.truncate(n));
    }
    if looped {
        angles
            .iter_mut()
            .for_each(|s| spread_seam(s, Some(360.0), options.loop_blend_fraction));
    }

    // Root translation: hips on screen, scaled; height above the capture's ground.
    let ground_src = source_ground(clip, &frames);
    let stand_src = [Side::Left, Side::Right]
        .into_iter()
        .filter_map(|s| SourceJoint::Foot(s).resolve(clip))
        .map(|j| rest_src.joints[hips].y - rest_src.joints[j.index()].y)
        .fold(0.0f64, f64::max);
    let hips_screen: Vec<Point> = frames
        .iter()
        .map(|f| axes.project(root_view, options.facing, f.joints[hips]))
        .collect();
    let mut root_x: Vec<f64> = hips_screen
        .iter()
        .map(|p| (p.x - hips_screen[0].x) * leg_scale)
        .collect();
    // Standing straight in the capture, the rig's legs stand straight too: its thigh heads a
    // leg's length above its ground line (legs drawn splayed or bent reach less far down at
    // rest, so the root rises by the difference).
    // The rig's ground line: its lowest ankle at rest.
    let ground_px = legs
        .iter()
        .map(|l| handles.bones[l.shin].tail.y)
        .fold(f64::MIN, f64::max);
    let stand_px = if legs.is_empty() {
        0.0
    } else {
        let thighs = legs
            .iter()
            .map(|l| handles.bones[l.thigh].head.y)
            .sum::<f64>()
            / legs.len() as f64;
        let reach = legs
            .iter()
            .map(|l| rest[l.thigh].length_px + rest[l.shin].length_px)
            .sum::<f64>()
            / legs.len() as f64;
        (ground_px - reach - thighs).min(0.0)
    };
    let mut root_y: Vec<f64> = frames
        .iter()
        .map(|f| {
            if ground_src.is_finite() {
                stand_px - (f.joints[hips].y - ground_src - stand_src) * leg_scale
            } else {
                (axes.project(root_view, options.facing, f.joints[hips]).y - hips_screen[0].y)
                    * leg_scale
            }
        })
        .collect();
    // The horizontal travel (least-squares line), removed at the end when in place.
    let times: Vec<f64> = (0..n).map(|f| f as f64 * clip.frame_time_s).collect();
    let travel = {
        let mean_t = times.iter().sum::<f64>() / n as f64;
        let mean_x = root_x.iter().sum::<f64>() / n as f64;
        let var: f64 = times.iter().map(|t| (t - mean_t).powi(2)).sum();
        let cov: f64 = times
            .iter()
            .zip(&root_x)
            .map(|(t, x)| (t - mean_t) * (x - mean_x))
            .sum();
        let slope = if var > 0.0 { cov / var } else { 0.0 };
        move |t: f64| mean_x + slope * (t - mean_t)
    };
    if looped {
        spread_seam(&mut root_y, None, options.loop_blend_fraction);
        // The sway loops; the travel is kept (or removed below).
        let trend: Vec<f64> = times.iter().map(|&t| travel(t)).collect();
        let mut sway: Vec<f64> = root_x.iter().zip(&trend).map(|(x, t)| x - t).collect();
        spread_seam(&mut sway, None, options.loop_blend_fraction);
        root_x = sway.iter().zip(&trend).map(|(s, t)| s + t).collect();
    }

    // Poses from the driven angles: world angles parents first, then local rotations.
    let driven_at: BTreeMap<usize, usize> = driven
        .iter()
        .enumerate()
        .map(|(k, &(b, _))| (b, k))
        .collect();
    let mut world = vec![vec![0.0; rest.len()]; n];
    for f in 0..n {
        for &i in &order {
            let parent = rest[i].parent.map_or(0.0, |p| world[f][p]);
            world[f][i] = match driven_at.get(&i) {
                Some(&k) => angles[k][f],
                None => parent + rest_local(i),
            };
        }
    }
    let pose_at = |world: &[f64], root_x: f64, root_y: f64| -> Pose {
        let mut pose = Pose::default();
        for (i, bone) in handles.bones.iter().enumerate() {
            let parent = rest[i].parent.map_or(0.0, |p| world[p]);
            let rotate = world[i] - parent - rest_local(i);
            let translate = if rest[i].parent.is_none() {
                [root_x, root_y]
            } else {
                [0.0, 0.0]
            };
            pose.bones.insert(
                bone.name.clone(),
                BonePose {
                    rotate,
                    translate,
                    ..BonePose::default()
                },
            );
        }
        pose
    };
    let ankle_of = |frames_px: &[crate::rig::Affine], leg: &Leg| -> (Point, Point, Point) {
        let at = |i: usize, along: f64| frames_px[i].apply(Point::new(along, 0.0));
        (
            at(leg.thigh, 0.0),
            at(leg.shin, 0.0),
            at(leg.shin, rest[leg.shin].length_px),
        )
    };

    // Feet: contacts from the capture, planted by IK.
    let on: Vec<Vec<bool>> = legs
        .iter()
        .map(|l| {
            if ground_src.is_finite() {
                contacts(clip, &frames, l.side, ground_src, leg_src, options, looped)
            } else {
                vec![false; n]
            }
        })
        .collect();
    let contact_count = on
        .iter()
        .map(|c| {
            c.windows(2).filter(|w| w[1] && !w[0]).count() + usize::from(c.first() == Some(&true))
        })
        .sum();
    if !legs.is_empty() {
        let mut planted: Vec<Option<Point>> = vec![None; legs.len()];
        let mut released: Vec<(usize, Point)> = vec![(usize::MAX, Point::origin()); legs.len()];
        // A loop's contact that runs across the seam is one contact: it is planted where its
        // last run begins, one cycle's travel back at frame 0, so that the last frame and the
        // first stand the same.
        if looped {
            let cycle_travel = root_x[n - 1] - root_x[0];
            for (k, leg) in legs.iter().enumerate() {
                if !(on[k][0] && on[k][n - 1]) || on[k].iter().all(|&c| c) {
                    continue;
                }
                let begin = (0..n)
                    .rev()
                    .take_while(|&f| on[k][f])
                    .last()
                    .unwrap_or(n - 1);
                let frames_px = bone_world_frames(
                    handles,
                    &pose_at(&world[begin], root_x[begin], root_y[begin]),
                )?;
                let (_, _, ankle) = ankle_of(&frames_px, leg);
                planted[k] = Some(Point::new(ankle.x - cycle_travel, ground_px));
            }
        }
        for f in 0..n {
            // Lower the root where a planted leg cannot reach.
            let frames_px = bone_world_frames(handles, &pose_at(&world[f], root_x[f], root_y[f]))?;
            let mut drop = 0.0f64;
            for (k, leg) in legs.iter().enumerate() {
                let (hip, _, ankle) = ankle_of(&frames_px, leg);
                let target = if on[k][f] {
                    Some(*planted[k].get_or_insert(Point::new(ankle.x, ground_px)))
                } else {
                    planted[k] = None;
                    (ankle.y > ground_px).then(|| Point::new(ankle.x, ground_px))
                };
                if let Some(t) = target {
                    let reach = (rest[leg.thigh].length_px + rest[leg.shin].length_px) * 0.999;
                    let dx = t.x - hip.x;
                    if dx.abs() < reach {
                        let need = (t.y - hip.y) - (reach * reach - dx * dx).sqrt();
                        drop = drop.max(need);
                    }
                }
            }
            root_y[f] += drop;
            let frames_px = bone_world_frames(handles, &pose_at(&world[f], root_x[f], root_y[f]))?;
            for (k, leg) in legs.iter().enumerate() {
                let (hip, knee, ankle) = ankle_of(&frames_px, leg);
                let target = if on[k][f] {
                    released[k] = (f, planted[k].unwrap_or(ankle));
                    planted[k]
                } else {
                    let (end, from) = released[k];
                    let eased = if end != usize::MAX && f > end && f - end <= options.release_frames
                    {
                        let s = (f - end) as f64 / (options.release_frames + 1) as f64;
                        Some(from + (ankle - from) * s)
                    } else {
                        None
                    };
                    match eased {
                        Some(p) => Some(Point::new(p.x, p.y.min(ground_px))),
                        None => (ankle.y > ground_px).then(|| Point::new(ankle.x, ground_px)),
                    }
                };
                let Some(target) = target else { continue };
                solve_leg(
                    &mut world[f],
                    leg,
                    (hip, knee, ankle),
                    target,
                    &rest,
                    &order,
                    &|i| driven_at.contains_key(&i),
                );
            }
        }
    }
    if options.in_place {
        for (x, &t) in root_x.iter_mut().zip(&times) {
            *x -= travel(t);
        }
    }

    // Poses and keys.
    let poses: Vec<Pose> = (0..n)
        .map(|f| pose_at(&world[f], root_x[f], root_y[f]))
        .collect();
    // A clip made to loop is a cycle: flagged, so that physics and momentum play in their
    // steady state (crate::scene::play).
    let mut animation = Animation {
        looping: looped,
        ..Animation::default()
    };
    let mut key_count = 0;
    let cyclic = looped;
    // The bones between the root and an ankle share the ground's tolerance: keys within it
    // leave no ankle more than `ground_tolerance_fraction` of a leg from where its frame put it
    // (three bones, each turning the ankle by at most its angle error times a leg length).
    let mut on_leg_chain = vec![false; rest.len()];
    for leg in &legs {
        let mut at = Some(leg.shin);
        while let Some(i) = at {
            on_leg_chain[i] = true;
            at = rest[i].parent;
        }
    }
    let chain_deg = (options.ground_tolerance_fraction / 3.0).to_degrees();
    let chain_px = options.ground_tolerance_fraction / 3.0 * rig_leg;
    let rotate_tolerance = |i: usize| {
        if on_leg_chain[i] {
            options.rotate_tolerance_deg.min(chain_deg)
        } else {
            options.rotate_tolerance_deg
        }
    };
    let translate_tolerance = if legs.is_empty() {
        options.translate_tolerance_px
    } else {
        options.translate_tolerance_px.min(chain_px)
    };
    for (i, bone) in handles.bones.iter().enumerate() {
        let mut rotate: Vec<f64> = poses.iter().map(|p| p.bones[&bone.name].rotate).collect();
        unwrap(&mut rotate);
        let moves = rotate.iter().any(|r| r.abs() > 1e-9);
        let mut timelines = BoneTimelines::default();
        if moves {
            let values: Vec<[f64; 1]> = rotate.iter().map(|&r| [r]).collect();
            let k = keys::reduce(&times, &values, rotate_tolerance(i), cyclic);
            key_count += k.len();
            timelines.rotate = Some(
                k.into_iter()
                    .map(|k| crate::anim::timeline::Key {
                        time: k.time,
                        value: k.value[0],
                        curve: k.curve,
                    })
                    .collect(),
            );
        }
        if rest[i].parent.is_none() {
            let values: Vec<[f64; 2]> = root_x.iter().zip(&root_y).map(|(&x, &y)| [x, y]).collect();
            let k = keys::reduce(
                &times,
                &values,
                translate_tolerance,
                cyclic && options.in_place,
            );
            key_count += k.len();
            timelines.translate = Some(k);
        }
        if timelines.rotate.is_some() || timelines.translate.is_some() {
            animation.bones.insert(bone.name.clone(), timelines);
        }
    }
    let report = RetargetReport {
        views,
        driven: driven
            .iter()
            .map(|&(b, _)| handles.bones[b].name.clone())
            .collect(),
        leg_scale,
        contacts: contact_count,
        looped,
        frames: n,
        keys: key_count,
        duration_s: times[n - 1],
    };
    Ok(Retargeted {
        animation,
        poses,
        report,
    })
}
