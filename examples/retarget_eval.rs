//! The retargeting evaluation (issue 42): every clip of the bundled motion library retargeted
//! onto several characters by sinew (`sinew::motion::retarget::retarget`) and by a baseline
//! built the way Animated Drawings retargets, both scored against the clip's joints projected to
//! 2D. Prints Markdown tables; `tools/retarget-eval/run.sh` builds the characters and runs it,
//! `docs/retarget-eval.md` reads the result.
//!
//! Usage:
//!   retarget_eval NAME=HANDLES.json...            the tables
//!   retarget_eval --anims CLIP RIG.json OUT.json [--in-place]
//!                                                  the rig document with CLIP_sinew and
//!                                                  CLIP_baseline added, for `sinew render`
//!
//! Metrics (per clip × character; the keyed animation sampled at each capture frame's time,
//! the per-frame poses before key reduction, and the baseline):
//! - limb angle error: per driven bone per frame, the angle between the posed bone (head →
//!   tail through `bone_world_frames`) and its source segment projected on the plane sinew
//!   chose for the bone's group; frames where the projected segment is shorter than 0.2 of its
//!   3D length (pointing at the viewer: no direction on screen) are left out and counted;
//! - bone lengths: the largest |posed length / rest length − 1| of any bone in any frame;
//! - foot sliding: per contact run of `foot_contacts`, the ankle's (leg_lower tail) horizontal
//!   path length during the run in rig leg lengths, against the projected source foot joint's
//!   path over the same frames in source leg lengths;
//! - ground penetration: how far any ankle goes below the lowest rest ankle, in leg lengths;
//! - loop seam (clips the report calls looped): the largest distance between the last and the
//!   first frame's driven bone ends (heads and tails, the root bone's horizontal travel taken
//!   out) in leg lengths, against the same on the projected source joints.

use anyhow::{anyhow, bail, Context, Result};
use sinew::anim::curve::Curve;
use sinew::anim::timeline::{Animation, BoneTimelines, Key};
use sinew::geom::Point;
use sinew::motion::bvh::Clip;
use sinew::motion::fk::{frame_positions, rest_positions, FramePositions};
use sinew::motion::library::MOTIONS;
use sinew::motion::map::{JointMap, Segment, SegmentEnd, Side, SourceJoint};
use sinew::motion::retarget::{
    foot_contacts, retarget, Axes, Facing, Group, LoopMode, RetargetOptions, View,
};
use sinew::rig::frames::{bone_world_frames, screen_angle_deg, BonePose};
use sinew::rig::{Handles, Pose};
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// Issue 42's targets.
const ANGLE_MEAN_MAX: f64 = 5.0;
const ANGLE_P95_MAX: f64 = 15.0;
const LENGTH_MAX: f64 = 1e-6;
const SLIDE_EXTRA_MAX: f64 = 0.02;
const PENETRATION_MAX: f64 = 0.01;
const SEAM_RATIO_MAX: f64 = 2.0;
/// A projected segment shorter than this fraction of its 3D length has no direction to score.
const FORESHORTENED: f64 = 0.2;

fn wrap_deg(a: f64) -> f64 {
    let w = a.rem_euclid(360.0);
    if w > 180.0 {
        w - 360.0
    } else {
        w
    }
}

fn end_point(f: &FramePositions, end: SegmentEnd) -> Option<nalgebra::Point3<f64>> {
    match end {
        SegmentEnd::Joint(j) => f.joint(j),
        SegmentEnd::EndSite(j) => f.end_site(j),
    }
}

/// The limb group of a driven bone, by its source joint (as retarget.rs decides it).
fn group_of(clip: &Clip, segment: &Segment) -> Group {
    let hit = |js: &[fn(Side) -> SourceJoint]| {
        js.iter().any(|f| {
            [Side::Left, Side::Right]
                .into_iter()
                .any(|s| f(s).resolve(clip) == Some(segment.from))
        })
    };
    if hit(&[
        SourceJoint::Thigh,
        SourceJoint::Shin,
        SourceJoint::Foot,
        SourceJoint::Toe,
    ]) {
        Group::Legs
    } else if hit(&[
        SourceJoint::UpperArm,
        SourceJoint::Forearm,
        SourceJoint::Hand,
    ]) {
        Group::Arms
    } else {
        Group::Torso
    }
}

/// The performer's leg (thigh + shin, the longer side) at rest, capture units.
fn source_leg(clip: &Clip, rest: &FramePositions) -> f64 {
    [Side::Left, Side::Right]
        .into_iter()
        .filter_map(|side| {
            let t = SourceJoint::Thigh(side).resolve(clip)?;
            let s = SourceJoint::Shin(side).resolve(clip)?;
            let f = SourceJoint::Foot(side).resolve(clip)?;
            let p = |j: sinew::motion::JointId| rest.joints[j.index()];
            Some((p(s) - p(t)).norm() + (p(f) - p(s)).norm())
        })
        .fold(0.0, f64::max)
}

fn side_suffix(side: Side) -> &'static str {
    match side {
        Side::Left => "l",
        Side::Right => "r",
    }
}

/// Everything about one clip that does not depend on the character.
struct Source {
    name: &'static str,
    clip: Clip,
    frames: Vec<FramePositions>,
    axes: Axes,
    leg: f64,
    hips: usize,
}

/// A character: its name and handles.
struct Character {
    name: String,
    handles: Handles,
}

/// The rig's static data used by the baseline and the metrics.
struct Rig<'a> {
    handles: &'a Handles,
    index: BTreeMap<&'a str, usize>,
    parent: Vec<Option<usize>>,
    rest_angle: Vec<f64>,
    rest_len: Vec<f64>,
    order: Vec<usize>,
    leg: f64,
    ground: f64,
}

impl<'a> Rig<'a> {
    fn new(handles: &'a Handles) -> Rig<'a> {
        let index: BTreeMap<&str, usize> = handles
            .bones
            .iter()
            .enumerate()
            .map(|(i, b)| (b.name.as_str(), i))
            .collect();
        let parent: Vec<Option<usize>> = handles
            .bones
            .iter()
            .map(|b| b.parent.as_deref().and_then(|p| index.get(p).copied()))
            .collect();
        let rest_angle = handles
            .bones
            .iter()
            .map(|b| screen_angle_deg(b.tail - b.head))
            .collect();
        let rest_len: Vec<f64> = handles
            .bones
            .iter()
            .map(|b| (b.tail - b.head).norm())
            .collect();
        // Parents first.
        let mut order = Vec::new();
        let mut placed = vec![false; parent.len()];
        while order.len() < parent.len() {
            let before = order.len();
            for i in 0..parent.len() {
                if !placed[i] && parent[i].is_none_or(|p| placed[p]) {
                    placed[i] = true;
                    order.push(i);
                }
            }
            if order.len() == before {
                break; // a cycle: validated rigs have none
            }
        }
        let leg_bones = |s: &str| {
            Some((
                *index.get(format!("leg_upper_{s}").as_str())?,
                *index.get(format!("leg_lower_{s}").as_str())?,
            ))
        };
        let legs: Vec<(usize, usize)> = ["l", "r"].into_iter().filter_map(leg_bones).collect();
        let leg = legs
            .iter()
            .map(|&(t, s)| rest_len[t] + rest_len[s])
            .fold(0.0, f64::max);
        let ground = legs
            .iter()
            .map(|&(_, s)| handles.bones[s].tail.y)
            .fold(f64::MIN, f64::max);
        Rig {
            handles,
            index,
            parent,
            rest_angle,
            rest_len,
            order,
            leg,
            ground,
        }
    }

    fn rest_local(&self, i: usize) -> f64 {
        self.rest_angle[i] - self.parent[i].map_or(0.0, |p| self.rest_angle[p])
    }
}

/// The baseline, after Animated Drawings' `Retargeter`: per frame every driven bone's world
/// angle is its source segment's projected angle (on sinew's plane for the group); bones not
/// driven keep their rest angle to their parent; every root bone is translated by the hips'
/// projected motion since the first frame × the leg scale. No contacts, no ground, no loop
/// blending, no key reduction.
fn baseline(
    rig: &Rig,
    src: &Source,
    map: &JointMap,
    views: &BTreeMap<Group, View>,
    leg_scale: f64,
) -> Vec<Pose> {
    let view_of = |seg: &Segment| {
        views
            .get(&group_of(&src.clip, seg))
            .copied()
            .unwrap_or(View::Side)
    };
    let root_view = views
        .get(&Group::Torso)
        .or_else(|| views.get(&Group::Legs))
        .copied()
        .unwrap_or(View::Side);
    let driven: BTreeMap<usize, Segment> = map
        .bones
        .iter()
        .filter_map(|(name, seg)| Some((*rig.index.get(name.as_str())?, *seg)))
        .collect();
    let hips0 = src
        .axes
        .project(root_view, Facing::Right, src.frames[0].joints[src.hips]);
    let mut last: BTreeMap<usize, f64> = driven.keys().map(|&i| (i, rig.rest_angle[i])).collect();
    src.frames
        .iter()
        .map(|f| {
            let mut world = vec![0.0; rig.parent.len()];
            for &i in &rig.order {
                let parent = rig.parent[i].map_or(0.0, |p| world[p]);
                world[i] = match driven.get(&i) {
                    Some(seg) => {
                        let a = f.joints[seg.from.index()];
                        if let Some(b) = end_point(f, seg.to) {
                            let v = view_of(seg);
                            let d = src.axes.project(v, Facing::Right, b)
                                - src.axes.project(v, Facing::Right, a);
                            // AD normalizes the projected vector; a zero one has no angle.
                            if d.norm() > 1e-9 * (b - a).norm().max(1e-12) {
                                last.insert(i, screen_angle_deg(d));
                            }
                        }
                        last[&i]
                    }
                    None => parent + rig.rest_local(i),
                };
            }
            let hips = src
                .axes
                .project(root_view, Facing::Right, f.joints[src.hips]);
            let root = [
                (hips.x - hips0.x) * leg_scale,
                (hips.y - hips0.y) * leg_scale,
            ];
            let mut pose = Pose::default();
            for (i, bone) in rig.handles.bones.iter().enumerate() {
                let parent = rig.parent[i].map_or(0.0, |p| world[p]);
                pose.bones.insert(
                    bone.name.clone(),
                    BonePose {
                        rotate: world[i] - parent - rig.rest_local(i),
                        translate: if rig.parent[i].is_none() {
                            root
                        } else {
                            [0.0, 0.0]
                        },
                        ..BonePose::default()
                    },
                );
            }
            pose
        })
        .collect()
}

/// Poses as an animation: one linear key per frame per bone (angles unwrapped).
fn animation_of(rig: &Rig, poses: &[Pose], dt: f64) -> Animation {
    let mut animation = Animation::default();
    for (i, bone) in rig.handles.bones.iter().enumerate() {
        let mut rotate: Vec<Key<f64>> = Vec::new();
        let mut prev = 0.0;
        for (f, p) in poses.iter().enumerate() {
            let r = p.bones[&bone.name].rotate;
            let r = if f == 0 { r } else { prev + wrap_deg(r - prev) };
            prev = r;
            rotate.push(Key {
                time: f as f64 * dt,
                value: r,
                curve: Curve::Linear,
            });
        }
        let translate = rig.parent[i].is_none().then(|| {
            poses
                .iter()
                .enumerate()
                .map(|(f, p)| Key {
                    time: f as f64 * dt,
                    value: p.bones[&bone.name].translate,
                    curve: Curve::Linear,
                })
                .collect()
        });
        animation.bones.insert(
            bone.name.clone(),
            BoneTimelines {
                rotate: Some(rotate),
                translate,
                ..BoneTimelines::default()
            },
        );
    }
    animation
}

/// One variant's scores on one clip × character.
#[derive(Default, Clone)]
struct Scores {
    /// Limb bones (legs and arms groups): all frames scored.
    limb: Vec<f64>,
    /// Leg bones (thigh, shin) of a foot in contact, and every other limb bone-frame.
    planted: Vec<f64>,
    free: Vec<f64>,
    arms: Vec<f64>,
    torso: Vec<f64>,
    /// Bone-frames left out (foreshortened source segment).
    skipped: usize,
    length: f64,
    penetration: f64,
    /// Per contact: (rig slide, source slide), leg lengths: the foot's horizontal extent
    /// (largest x − smallest x) over the contact's frames.
    slides: Vec<(f64, f64)>,
    /// The same as path lengths (sum of |Δx| frame to frame): counts sub-pixel jitter too.
    paths: Vec<(f64, f64)>,
    /// (rig seam, source seam), leg lengths, when the clip looped.
    seam: Option<(f64, f64)>,
}

struct Cx<'a> {
    rig: &'a Rig<'a>,
    src: &'a Source,
    map: &'a JointMap,
    views: &'a BTreeMap<Group, View>,
    looped: bool,
    /// Per side, the frames its foot is in contact (`foot_contacts`, cyclic when looped).
    contacts: &'a [(Side, Vec<bool>)],
}

fn score(cx: &Cx, poses: &[Pose]) -> Result<Scores> {
    let (rig, src) = (cx.rig, cx.src);
    let mut s = Scores::default();
    let view_of = |seg: &Segment| {
        cx.views
            .get(&group_of(&src.clip, seg))
            .copied()
            .unwrap_or(View::Side)
    };
    let legs_view = cx.views.get(&Group::Legs).copied().unwrap_or(View::Side);
    let contact_at = |side: Side, f: usize| {
        cx.contacts
            .iter()
            .any(|(s, on)| *s == side && on.get(f).copied().unwrap_or(false))
    };
    let driven: Vec<(usize, Segment, Group)> = cx
        .map
        .bones
        .iter()
        .filter_map(|(name, seg)| {
            Some((
                *rig.index.get(name.as_str())?,
                *seg,
                group_of(&src.clip, seg),
            ))
        })
        .collect();
    let root = (0..rig.parent.len())
        .find(|&i| rig.parent[i].is_none())
        .ok_or_else(|| anyhow!("no root bone"))?;
    // Per frame: each bone's head and tail.
    let mut ends: Vec<Vec<(Point, Point)>> = Vec::with_capacity(poses.len());
    for pose in poses {
        let frames = bone_world_frames(rig.handles, pose)?;
        ends.push(
            frames
                .iter()
                .zip(&rig.rest_len)
                .map(|(fr, &len)| {
                    (
                        fr.apply(Point::new(0.0, 0.0)),
                        fr.apply(Point::new(len, 0.0)),
                    )
                })
                .collect(),
        );
    }
    for (f, e) in ends.iter().enumerate() {
        for (i, &(h, t)) in e.iter().enumerate() {
            if rig.rest_len[i] > 0.0 {
                s.length = s.length.max(((t - h).norm() / rig.rest_len[i] - 1.0).abs());
            }
        }
        for &(i, seg, group) in &driven {
            let fr = &src.frames[f];
            let a = fr.joints[seg.from.index()];
            let Some(b) = end_point(fr, seg.to) else {
                continue;
            };
            let v = view_of(&seg);
            let d = src.axes.project(v, Facing::Right, b) - src.axes.project(v, Facing::Right, a);
            if d.norm() < FORESHORTENED * (b - a).norm() {
                s.skipped += 1;
                continue;
            }
            let (h, t) = e[i];
            let err = wrap_deg(screen_angle_deg(t - h) - screen_angle_deg(d)).abs();
            match group {
                Group::Torso => s.torso.push(err),
                Group::Arms => {
                    s.limb.push(err);
                    s.arms.push(err);
                    s.free.push(err);
                }
                Group::Legs => {
                    s.limb.push(err);
                    let name = &rig.handles.bones[i].name;
                    let planted = [Side::Left, Side::Right].into_iter().any(|side| {
                        let sfx = side_suffix(side);
                        (*name == format!("leg_upper_{sfx}") || *name == format!("leg_lower_{sfx}"))
                            && contact_at(side, f)
                    });
                    if planted {
                        s.planted.push(err);
                    } else {
                        s.free.push(err);
                    }
                }
            }
        }
    }
    // Ankles: penetration and sliding.
    for (side, on) in cx.contacts {
        let sfx = side_suffix(*side);
        let Some(&shin) = rig.index.get(format!("leg_lower_{sfx}").as_str()) else {
            continue;
        };
        let ankle: Vec<Point> = ends.iter().map(|e| e[shin].1).collect();
        for p in &ankle {
            s.penetration = s.penetration.max((p.y - rig.ground) / rig.leg);
        }
        let Some(foot) = SourceJoint::Foot(*side).resolve(&src.clip) else {
            continue;
        };
        let src_foot: Vec<Point> = src
            .frames
            .iter()
            .map(|f| {
                src.axes
                    .project(legs_view, Facing::Right, f.joints[foot.index()])
            })
            .collect();
        let mut f = 0;
        while f < on.len() {
            if !on[f] {
                f += 1;
                continue;
            }
            let start = f;
            while f < on.len() && on[f] {
                f += 1;
            }
            let path = |xs: &[Point]| -> f64 {
                xs[start..f]
                    .windows(2)
                    .map(|w| (w[1].x - w[0].x).abs())
                    .sum()
            };
            let extent = |xs: &[Point]| -> f64 {
                let (lo, hi) = xs[start..f]
                    .iter()
                    .fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                        (lo.min(p.x), hi.max(p.x))
                    });
                hi - lo
            };
            s.slides
                .push((extent(&ankle) / rig.leg, extent(&src_foot) / src.leg));
            s.paths
                .push((path(&ankle) / rig.leg, path(&src_foot) / src.leg));
        }
    }
    s.penetration = s.penetration.max(0.0);
    // Loop seam, horizontal travel taken out.
    if cx.looped && poses.len() >= 2 {
        let n = poses.len();
        let rig_seam = driven
            .iter()
            .flat_map(|&(i, _, _)| {
                let (a, b) = (&ends[0], &ends[n - 1]);
                let (dx0, dx1) = (ends[0][root].0.x, ends[n - 1][root].0.x);
                [
                    (a[i].0 - Point::new(dx0, 0.0)) - (b[i].0 - Point::new(dx1, 0.0)),
                    (a[i].1 - Point::new(dx0, 0.0)) - (b[i].1 - Point::new(dx1, 0.0)),
                ]
            })
            .map(|d| d.norm())
            .fold(0.0, f64::max)
            / rig.leg;
        let at = |f: usize, seg: &Segment| -> Vec<Point> {
            let fr = &src.frames[f];
            let v = view_of(seg);
            let hx = src.axes.project(v, Facing::Right, fr.joints[src.hips]).x;
            [Some(fr.joints[seg.from.index()]), end_point(fr, seg.to)]
                .into_iter()
                .flatten()
                .map(|p| {
                    let q = src.axes.project(v, Facing::Right, p);
                    Point::new(q.x - hx, q.y)
                })
                .collect()
        };
        let src_seam = driven
            .iter()
            .flat_map(|(_, seg, _)| {
                at(0, seg)
                    .into_iter()
                    .zip(at(n - 1, seg))
                    .map(|(a, b)| (a - b).norm())
                    .collect::<Vec<_>>()
            })
            .fold(0.0, f64::max)
            / src.leg;
        s.seam = Some((rig_seam, src_seam));
    }
    Ok(s)
}

/// Per frame, to stderr: contacts, and per variant each ankle's x and height above the ground
/// line (px, up positive).
fn dump(
    rig: &Rig,
    src: &Source,
    contacts: &[(Side, Vec<bool>)],
    variants: &[&[Pose]],
) -> Result<()> {
    let shins: Vec<usize> = ["l", "r"]
        .iter()
        .filter_map(|s| rig.index.get(format!("leg_lower_{s}").as_str()).copied())
        .collect();
    eprintln!("leg {:.1} px, ground y {:.1}", rig.leg, rig.ground);
    for f in 0..src.frames.len() {
        let mut line = format!("{f:3}");
        for (side, on) in contacts {
            line += &format!(" {}{}", side_suffix(*side), if on[f] { "*" } else { " " });
        }
        for poses in variants {
            let frames = bone_world_frames(rig.handles, &poses[f])?;
            line += " |";
            for &s in &shins {
                let a = frames[s].apply(Point::new(rig.rest_len[s], 0.0));
                line += &format!(" {:8.2} {:7.2}", a.x, rig.ground - a.y);
            }
        }
        eprintln!("{line}");
    }
    if let Ok(bone) = std::env::var("RETARGET_EVAL_BONE") {
        let i = *rig
            .index
            .get(bone.as_str())
            .ok_or_else(|| anyhow!("no bone {bone}"))?;
        for f in 0..src.frames.len() {
            let mut line = format!("{f:3} {bone}");
            for poses in variants {
                let frames = bone_world_frames(rig.handles, &poses[f])?;
                let (h, t) = (
                    frames[i].apply(Point::new(0.0, 0.0)),
                    frames[i].apply(Point::new(rig.rest_len[i], 0.0)),
                );
                line += &format!(" {:8.2}", screen_angle_deg(t - h));
            }
            eprintln!("{line}");
        }
    }
    Ok(())
}

fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        f64::NAN
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
}

fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    let k = ((q * s.len() as f64).ceil() as usize).clamp(1, s.len()) - 1;
    s[k]
}

fn median(v: &[f64]) -> f64 {
    quantile(v, 0.5)
}

/// Results of one clip × character.
struct Row {
    clip: &'static str,
    character: String,
    views: String,
    looped: bool,
    keys: usize,
    contacts: usize,
    /// Bones the capture drives.
    driven: usize,
    /// The largest change of a driven segment's projected angle from the last frame to the
    /// first, degrees.
    src_seam_deg: f64,
    /// sinew keyed, sinew per-frame poses, baseline, sinew per-frame poses with the loop
    /// stage off (`--loop off`).
    v: [Scores; 4],
}

fn load_sources() -> Result<Vec<Source>> {
    MOTIONS
        .iter()
        .map(|m| {
            let clip = m.clip().map_err(|e| anyhow!("{}: {e}", m.name))?;
            let frames: Vec<FramePositions> = (0..clip.frame_count())
                .map(|f| frame_positions(&clip, f).ok_or_else(|| anyhow!("{}: frame {f}", m.name)))
                .collect::<Result<_>>()?;
            let axes = Axes::of(&clip, &frames);
            let leg = source_leg(&clip, &rest_positions(&clip));
            let hips = SourceJoint::Hips
                .resolve(&clip)
                .ok_or_else(|| anyhow!("{}: no hips", m.name))?
                .index();
            Ok(Source {
                name: m.name,
                clip,
                frames,
                axes,
                leg,
                hips,
            })
        })
        .collect()
}

fn load_character(arg: &str) -> Result<Character> {
    let (name, path) = arg
        .split_once('=')
        .ok_or_else(|| anyhow!("expected NAME=HANDLES.json, got {arg}"))?;
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {path}"))?;
    let handles: Handles =
        serde_json::from_str(&text).with_context(|| format!("parsing {path}"))?;
    Ok(Character {
        name: name.to_string(),
        handles,
    })
}

fn run_one(src: &Source, ch: &Character) -> Result<Row> {
    let names: Vec<&str> = ch.handles.bones.iter().map(|b| b.name.as_str()).collect();
    let map = JointMap::humanoid(&src.clip, &names)?;
    let options = RetargetOptions::default();
    let out = retarget(&ch.handles, &src.clip, &map, &options)?;
    let unlooped = retarget(
        &ch.handles,
        &src.clip,
        &map,
        &RetargetOptions {
            loop_mode: LoopMode::Off,
            ..options.clone()
        },
    )?;
    let rig = Rig::new(&ch.handles);
    let dt = src.clip.frame_time_s;
    let keyed: Vec<Pose> = (0..src.frames.len())
        .map(|f| out.animation.sample(f as f64 * dt, false))
        .collect();
    let base = baseline(&rig, src, &map, &out.report.views, out.report.leg_scale);
    let contacts = foot_contacts(&src.clip, &options, out.report.looped);
    if std::env::var("RETARGET_EVAL_DUMP").ok().as_deref()
        == Some(&format!("{}:{}", src.name, ch.name))
    {
        dump(&rig, src, &contacts, &[&keyed, &out.poses, &base])?;
    }
    let cx = Cx {
        rig: &rig,
        src,
        map: &map,
        views: &out.report.views,
        looped: out.report.looped,
        contacts: &contacts,
    };
    let view = |g| match out.report.views.get(&g) {
        Some(View::Side) => "side",
        Some(View::Front) => "front",
        Some(View::Auto) => "auto",
        None => "-",
    };
    let src_seam_deg = map
        .bones
        .values()
        .filter_map(|seg| {
            let v = out
                .report
                .views
                .get(&group_of(&src.clip, seg))
                .copied()
                .unwrap_or(View::Side);
            let angle = |fr: &FramePositions| -> Option<f64> {
                let a = src
                    .axes
                    .project(v, Facing::Right, fr.joints[seg.from.index()]);
                let b = src.axes.project(v, Facing::Right, end_point(fr, seg.to)?);
                Some(screen_angle_deg(b - a))
            };
            Some(wrap_deg(angle(src.frames.last()?)? - angle(&src.frames[0])?).abs())
        })
        .fold(0.0, f64::max);
    Ok(Row {
        driven: out.report.driven.len(),
        src_seam_deg,
        clip: src.name,
        character: ch.name.clone(),
        views: format!(
            "{}/{}/{}",
            view(Group::Legs),
            view(Group::Arms),
            view(Group::Torso)
        ),
        looped: out.report.looped,
        keys: out.report.keys,
        contacts: out.report.contacts,
        v: [
            score(&cx, &keyed)?,
            score(&cx, &out.poses)?,
            score(&cx, &base)?,
            score(&cx, &unlooped.poses)?,
        ],
    })
}

/// Pooled scores of several rows, per variant.
fn pool(rows: &[&Row], k: usize) -> Scores {
    let mut p = Scores::default();
    for r in rows {
        let s = &r.v[k];
        p.limb.extend(&s.limb);
        p.planted.extend(&s.planted);
        p.free.extend(&s.free);
        p.arms.extend(&s.arms);
        p.torso.extend(&s.torso);
        p.skipped += s.skipped;
        p.length = p.length.max(s.length);
        p.penetration = p.penetration.max(s.penetration);
        p.slides.extend(&s.slides);
        p.paths.extend(&s.paths);
    }
    p
}

fn seam_ratios(rows: &[&Row], k: usize) -> Vec<f64> {
    rows.iter()
        .filter_map(|r| r.v[k].seam)
        .map(|(rig, src)| rig / src.max(1e-9))
        .collect()
}

fn seams(rows: &[&Row], k: usize) -> Vec<f64> {
    rows.iter()
        .filter_map(|r| r.v[k].seam)
        .map(|s| s.0)
        .collect()
}

fn slide_within(s: &Scores) -> String {
    if s.slides.is_empty() {
        return "-".into();
    }
    let ok = s
        .slides
        .iter()
        .filter(|(r, src)| r - src <= SLIDE_EXTRA_MAX)
        .count();
    format!("{ok}/{}", s.slides.len())
}

fn excess(s: &Scores) -> Vec<f64> {
    s.slides.iter().map(|(r, src)| r - src).collect()
}

fn path_within(s: &Scores) -> String {
    if s.paths.is_empty() {
        return "-".into();
    }
    let ok = s
        .paths
        .iter()
        .filter(|(r, src)| r - src <= SLIDE_EXTRA_MAX)
        .count();
    format!("{ok}/{}", s.paths.len())
}

fn f(x: f64, digits: usize) -> String {
    if x.is_nan() {
        "-".into()
    } else {
        format!("{x:.digits$}")
    }
}

fn e(x: f64) -> String {
    if x.is_nan() {
        "-".into()
    } else if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.1e}")
    }
}

fn tables(rows: &[Row], characters: &[Character]) -> String {
    let mut out = String::new();
    let clips: Vec<&str> = MOTIONS.iter().map(|m| m.name).collect();
    let groups: Vec<(String, Vec<&Row>)> = clips
        .iter()
        .map(|c| {
            (
                c.to_string(),
                rows.iter().filter(|r| r.clip == *c).collect(),
            )
        })
        .chain(std::iter::once((
            "**all**".to_string(),
            rows.iter().collect(),
        )))
        .collect();
    let _ = writeln!(
        out,
        "Characters ({}): {}. Clips: {}. Each cell: sinew (the keyed animation) / baseline \
         (Animated Drawings' way); where sinew's per-frame poses (before key reduction) differ, \
         they are in the second table.\n",
        characters.len(),
        characters
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        clips.join(", ")
    );

    let _ = writeln!(out, "### Per clip, all characters pooled\n");
    let _ = writeln!(
        out,
        "| clip | views legs/arms/torso | looped | limb angle mean ° | limb angle p95 ° | \
         max bone length change | contacts sliding ≤ source + {SLIDE_EXTRA_MAX} | median slide − source (leg lengths) | \
         max ground penetration (leg lengths) | median loop seam / source's |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|");
    for (name, rs) in &groups {
        let (k, b) = (pool(rs, 0), pool(rs, 2));
        let views: Vec<&str> = {
            let mut v: Vec<&str> = rs.iter().map(|r| r.views.as_str()).collect();
            v.sort();
            v.dedup();
            v
        };
        let looped = rs.iter().filter(|r| r.looped).count();
        let _ = writeln!(
            out,
            "| {name} | {} | {looped}/{} | {} / {} | {} / {} | {} / {} | {} / {} | {} / {} | {} / {} | {} / {} |",
            if views.len() > 2 { "mixed".to_string() } else { views.join(", ") },
            rs.len(),
            f(mean(&k.limb), 2),
            f(mean(&b.limb), 2),
            f(quantile(&k.limb, 0.95), 1),
            f(quantile(&b.limb, 0.95), 1),
            e(k.length),
            e(b.length),
            slide_within(&k),
            slide_within(&b),
            f(median(&excess(&k)), 3),
            f(median(&excess(&b)), 3),
            f(k.penetration, 3),
            f(b.penetration, 3),
            f(median(&seam_ratios(rs, 0)), 2),
            f(median(&seam_ratios(rs, 2)), 2),
        );
    }

    let _ = writeln!(
        out,
        "\n### Where sinew's angle error comes from, and the other variants\n\n\
         Angle cells: sinew's keyed animation, in brackets its per-frame poses (before key \
         reduction). A leg bone is *planted* in the frames where its foot is in contact (IK holds \
         the ankle). The source's seam is the largest change of a driven segment's projected \
         angle between the clip's last and first frames (sinew calls a clip a loop when it is \
         ≤ 25° and spreads it over the clip).\n"
    );
    let _ = writeln!(
        out,
        "| clip | source seam ° | legs of a planted foot: mean ° / p95 ° (n) | other limb bones: mean ° / p95 ° (n) | \
         arms: mean ° | torso (hip, chest, neck, head): mean ° | left out (foreshortened) | \
         contacts sliding ≤ source + {SLIDE_EXTRA_MAX}, as path length: keys / frames / baseline | \
         source seam, median (leg lengths) | max loop seam, frames / keys (leg lengths) | keys per clip (median) | \
         with the loop stage off (frames): planted legs / other limb bones / arms / torso, mean ° |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (name, rs) in &groups {
        let (k, p, b, o) = (pool(rs, 0), pool(rs, 1), pool(rs, 2), pool(rs, 3));
        let mut keys: Vec<f64> = rs.iter().map(|r| r.keys as f64).collect();
        keys.sort_by(|a, b| a.total_cmp(b));
        let seam_p = seams(rs, 1).into_iter().fold(f64::NAN, f64::max);
        let seam_k = seams(rs, 0).into_iter().fold(f64::NAN, f64::max);
        let src_seam: Vec<f64> = rs.iter().filter_map(|r| r.v[2].seam).map(|s| s.1).collect();
        let src_deg = rs.iter().map(|r| r.src_seam_deg).fold(f64::NAN, f64::max);
        let _ = writeln!(
            out,
            "| {name} | {} | {} / {} ({}) [{} / {}] | {} / {} ({}) [{} / {}] | {} [{}] | {} [{}] | {} | {} / {} / {} | {} | {} / {} | {} | {} / {} / {} / {} |",
            f(src_deg, 1),
            f(mean(&k.planted), 2),
            f(quantile(&k.planted, 0.95), 1),
            k.planted.len(),
            f(mean(&p.planted), 2),
            f(quantile(&p.planted, 0.95), 1),
            f(mean(&k.free), 2),
            f(quantile(&k.free, 0.95), 1),
            k.free.len(),
            f(mean(&p.free), 2),
            f(quantile(&p.free, 0.95), 1),
            f(mean(&k.arms), 2),
            f(mean(&p.arms), 2),
            f(mean(&k.torso), 2),
            f(mean(&p.torso), 2),
            k.skipped,
            path_within(&k),
            path_within(&p),
            path_within(&b),
            f(median(&src_seam), 3),
            f(seam_p, 4),
            f(seam_k, 4),
            f(median(&keys), 0),
            f(mean(&o.planted), 2),
            f(mean(&o.free), 2),
            f(mean(&o.arms), 2),
            f(mean(&o.torso), 2),
        );
    }

    let _ = writeln!(out, "\n### Per character, walk and run\n");
    let _ = writeln!(
        out,
        "| clip | character | contacts planted | limb angle mean ° | limb angle p95 ° | \
         contacts sliding ≤ source + {SLIDE_EXTRA_MAX} | max slide − source | max penetration | loop seam / source's | keys |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|");
    for r in rows.iter().filter(|r| r.clip == "walk" || r.clip == "run") {
        let (k, b) = (&r.v[0], &r.v[2]);
        let ratio = |s: &Scores| s.seam.map_or(f64::NAN, |(a, b)| a / b.max(1e-9));
        let max_ex = |s: &Scores| excess(s).into_iter().fold(f64::NAN, f64::max);
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} / {} | {} / {} | {} / {} | {} / {} | {} / {} | {} / {} | {} |",
            r.clip,
            r.character,
            r.contacts,
            f(mean(&k.limb), 2),
            f(mean(&b.limb), 2),
            f(quantile(&k.limb, 0.95), 1),
            f(quantile(&b.limb, 0.95), 1),
            slide_within(k),
            slide_within(b),
            f(max_ex(k), 3),
            f(max_ex(b), 3),
            f(k.penetration, 3),
            f(b.penetration, 3),
            f(ratio(k), 2),
            f(ratio(b), 2),
            r.keys,
        );
    }

    let _ = writeln!(
        out,
        "\n### Characters: the rest leg against the planted-leg angle error\n\n\
         *Rest span*: the rest leg's vertical extent (ankle y − thigh head y) over its length, \
         the shorter leg: 1 for a leg drawn straight down. The thighs hang from the hip bone (or \
         the rig's root); that bone takes the capture's Hips → Chest direction, so a thigh head \
         away from its head swings as the torso leans, which the capture's thighs do not. Planted-leg cells: sinew's per-frame \
         poses, mean angle error of thigh and shin while their foot is in contact.\n"
    );
    let _ = writeln!(
        out,
        "| character | bones | driven (walk) | leg px | rest span | thigh head from its parent's head (leg lengths) | planted legs idle ° | walk ° | run ° | wave ° |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|");
    for c in characters {
        let rig = Rig::new(&c.handles);
        let span = ["l", "r"]
            .iter()
            .filter_map(|s| {
                let t = *rig.index.get(format!("leg_upper_{s}").as_str())?;
                let k = *rig.index.get(format!("leg_lower_{s}").as_str())?;
                let b = &c.handles.bones;
                Some((b[k].tail.y - b[t].head.y) / (rig.rest_len[t] + rig.rest_len[k]))
            })
            .fold(f64::MAX, f64::min);
        // How far the thigh heads sit from their parent's head (what turns them about it).
        let offset = ["l", "r"]
            .iter()
            .filter_map(|s| {
                let t = *rig.index.get(format!("leg_upper_{s}").as_str())?;
                let p = rig.parent[t]?;
                let b = &c.handles.bones;
                Some((b[t].head - b[p].head).norm() / rig.leg)
            })
            .fold(0.0, f64::max);
        let planted = |clip: &str| {
            rows.iter()
                .find(|r| r.clip == clip && r.character == c.name)
                .map_or(f64::NAN, |r| mean(&r.v[1].planted))
        };
        let driven = rows
            .iter()
            .find(|r| r.clip == "walk" && r.character == c.name)
            .map_or(0, |r| r.driven);
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.name,
            c.handles.bones.len(),
            driven,
            f(rig.leg, 0),
            f(span, 3),
            f(offset, 2),
            f(planted("idle"), 1),
            f(planted("walk"), 1),
            f(planted("run"), 1),
            f(planted("wave"), 1),
        );
    }

    // Targets.
    let _ = writeln!(out, "\n### Issue 42's targets\n");
    let _ = writeln!(out, "| target | sinew (keys) | sinew (frames) | baseline |");
    let _ = writeln!(out, "|---|---|---|---|");
    let side_walk_run: Vec<&Row> = rows
        .iter()
        .filter(|r| (r.clip == "walk" || r.clip == "run") && r.views.starts_with("side"))
        .collect();
    let all: Vec<&Row> = rows.iter().collect();
    let mut line = |what: String, cell: &dyn Fn(usize) -> String| {
        let _ = writeln!(out, "| {what} | {} | {} | {} |", cell(0), cell(1), cell(2));
    };
    let yes = |ok: bool| if ok { "met" } else { "**missed**" };
    line(
        format!("walk + run (side) limb angle mean ≤ {ANGLE_MEAN_MAX}°"),
        &|k| {
            let m = mean(&pool(&side_walk_run, k).limb);
            format!("{} ({})", f(m, 2), yes(m <= ANGLE_MEAN_MAX))
        },
    );
    line(
        format!("walk + run (side) limb angle p95 ≤ {ANGLE_P95_MAX}°"),
        &|k| {
            let m = quantile(&pool(&side_walk_run, k).limb, 0.95);
            format!("{} ({})", f(m, 1), yes(m <= ANGLE_P95_MAX))
        },
    );
    line(format!("bone length change ≤ {LENGTH_MAX:e}"), &|k| {
        let m = pool(&all, k).length;
        format!("{} ({})", e(m), yes(m <= LENGTH_MAX))
    });
    line(
        format!("contacts sliding ≤ source + {SLIDE_EXTRA_MAX} leg lengths"),
        &|k| {
            let p = pool(&all, k);
            let ok = p.slides.iter().all(|(r, s)| r - s <= SLIDE_EXTRA_MAX);
            format!("{} ({})", slide_within(&p), yes(ok))
        },
    );
    line(
        format!("ground penetration ≤ {PENETRATION_MAX} leg lengths"),
        &|k| {
            let m = pool(&all, k).penetration;
            format!("{} ({})", f(m, 4), yes(m <= PENETRATION_MAX))
        },
    );
    line(
        format!("loop seam ≤ {SEAM_RATIO_MAX} × source's (looped clip × character)"),
        &|k| {
            let r = seam_ratios(&all, k);
            let ok = r.iter().filter(|&&x| x <= SEAM_RATIO_MAX).count();
            format!("{ok}/{} ({})", r.len(), yes(ok == r.len()))
        },
    );
    out
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--anims") {
        // A rig document with CLIP_sinew (what `sinew animate --motion CLIP` adds) and
        // CLIP_baseline (one linear key per capture frame) added, for `sinew render`.
        let in_place = args.iter().any(|a| a == "--in-place");
        let args: Vec<&String> = args.iter().filter(|a| *a != "--in-place").collect();
        let [_, clip_name, rig_path, out_path] = args.as_slice() else {
            bail!("usage: retarget_eval --anims CLIP RIG.json OUT.json [--in-place]");
        };
        let src = load_sources()?
            .into_iter()
            .find(|s| s.name == clip_name.as_str())
            .ok_or_else(|| anyhow!("no clip {clip_name}"))?;
        let mut doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(rig_path)?)?;
        let handles: Handles = serde_json::from_value(doc["handles"].clone())?;
        let names: Vec<&str> = handles.bones.iter().map(|b| b.name.as_str()).collect();
        let map = JointMap::humanoid(&src.clip, &names)?;
        let options = RetargetOptions {
            in_place,
            ..RetargetOptions::default()
        };
        let out = retarget(&handles, &src.clip, &map, &options)?;
        let rig = Rig::new(&handles);
        let mut poses = baseline(&rig, &src, &map, &out.report.views, out.report.leg_scale);
        if in_place {
            // As sinew's in_place: the root's least-squares line in time taken out of x.
            let n = poses.len() as f64;
            let root = &handles.bones[(0..rig.parent.len())
                .find(|&i| rig.parent[i].is_none())
                .ok_or_else(|| anyhow!("no root"))?]
            .name;
            let xs: Vec<f64> = poses.iter().map(|p| p.bones[root].translate[0]).collect();
            let mean_t = (n - 1.0) / 2.0;
            let mean_x = xs.iter().sum::<f64>() / n;
            let (mut cov, mut var) = (0.0, 0.0);
            for (t, x) in xs.iter().enumerate() {
                cov += (t as f64 - mean_t) * (x - mean_x);
                var += (t as f64 - mean_t).powi(2);
            }
            let slope = if var > 0.0 { cov / var } else { 0.0 };
            for (t, pose) in poses.iter_mut().enumerate() {
                let line = mean_x + slope * (t as f64 - mean_t);
                for (i, b) in handles.bones.iter().enumerate() {
                    if rig.parent[i].is_none() {
                        if let Some(bp) = pose.bones.get_mut(&b.name) {
                            bp.translate[0] -= line;
                        }
                    }
                }
            }
        }
        let base = animation_of(&rig, &poses, src.clip.frame_time_s);
        let animations = doc["animations"]
            .as_object_mut()
            .ok_or_else(|| anyhow!("{rig_path}: no animations object"))?;
        animations.insert(
            format!("{clip_name}_sinew"),
            serde_json::to_value(&out.animation)?,
        );
        animations.insert(
            format!("{clip_name}_baseline"),
            serde_json::to_value(&base)?,
        );
        std::fs::write(out_path, serde_json::to_string(&doc)?)?;
        return Ok(());
    }
    if args.is_empty() {
        bail!("usage: retarget_eval NAME=HANDLES.json... | --anims CLIP RIG.json OUT.json");
    }
    let characters: Vec<Character> = args
        .iter()
        .map(|a| load_character(a))
        .collect::<Result<_>>()?;
    let sources = load_sources()?;
    let mut rows = Vec::new();
    for src in &sources {
        for ch in &characters {
            rows.push(run_one(src, ch).with_context(|| format!("{} on {}", src.name, ch.name))?);
        }
    }
    use sha2::Digest as _;
    let hash = sha2::Sha256::digest(include_bytes!("../src/motion/retarget.rs"));
    println!(
        "src/motion/retarget.rs as built: sha256 {}\n",
        hash.iter().map(|b| format!("{b:02x}")).collect::<String>()
    );
    print!("{}", tables(&rows, &characters));
    Ok(())
}
