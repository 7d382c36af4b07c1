//! One animation as DragonBones timelines, baked on every frame of the armature.
//!
//! In: the animation, the scene, the bones ([`Joint`]s and their setup transforms) and the
//! frame rate F. Out: the animation's JSON and a [`BakedAnimation`] (the values written, as the
//! runtime stores them) for [`super::played`].
//!
//! The animation lasts N = round(duration·F) frames; frame k shows sinew's frame at k/F (the
//! last at the animation's end), posed through the one path ([`bake::sample_path`]). Every bone
//! gets a translate, rotate and scale frame on each of the N + 1 frames, relative to its setup
//! transform, with `tweenEasing: 0` (a missing one plays stepped); rotations are continuous from
//! frame to frame (the runtime turns the short way). Slots get display, colour and deform (FFD)
//! frames only where the animation keys them, and the draw order a `zOrder` timeline, each
//! value on the frames where it changes. Events sit on the frame nearest their time.

use super::transform::{DbFrame, DbTransform};
use super::{num, DragonBonesError, DragonBonesOptions};
use crate::anim::curve::f32_stored;
use crate::anim::Animation;
use crate::export::joints::{local_maps, Joint};
use crate::export::spine::bake;
use crate::geom::Vec2;
use crate::pipeline::Scene;
use crate::rig::Pose;
use serde_json::{json, Map, Value};
use std::collections::BTreeMap;

/// What one animation keys on each frame, as the runtime stores it (f32 values).
#[derive(Clone, Debug, PartialEq)]
pub struct BakedAnimation {
    pub name: String,
    /// N: the animation lasts N frames; frames 0..=N are keyed.
    pub frame_count: u32,
    /// 0: loops for ever; 1: plays once.
    pub play_times: u32,
    /// Per frame, each bone's transform relative to its parent (setup plus the frame's values).
    pub bones: Vec<Vec<DbTransform>>,
    /// Slots whose display is keyed: per frame, the display index (−1: none).
    pub displays: BTreeMap<String, Vec<i64>>,
    /// Slots whose colour is keyed: per frame, RGBA multipliers in whole percent.
    pub colors: BTreeMap<String, Vec<[i64; 4]>>,
    /// Parts whose deform is keyed: per frame, offsets of every fine-mesh vertex (armature
    /// units, f32); the file holds the written vertices'.
    pub deforms: BTreeMap<String, Vec<Vec<Vec2>>>,
    /// When the draw order is keyed: per frame, the slots back to front.
    pub draw_order: Option<Vec<Vec<String>>>,
    /// What of the animation the export did not carry, one line each.
    pub left_out: Vec<String>,
}

/// The transform a rotate/translate/scale frame triple makes of `setup` as the runtime reads
/// it: values relative to the setup, written and stored in f32 (rotation and skew in degrees in
/// the file, radians in the runtime).
fn as_stored(setup: &DbTransform, t: &DbTransform) -> (DbTransform, [f64; 6]) {
    let dx = f32_stored(t.x - setup.x);
    let dy = f32_stored(t.y - setup.y);
    let rotate_deg = f32_stored((t.rotation_rad - setup.rotation_rad).to_degrees());
    let skew_deg = f32_stored((t.skew_rad - setup.skew_rad).to_degrees());
    let sx = f32_stored(t.scale_x / setup.scale_x);
    let sy = f32_stored(t.scale_y / setup.scale_y);
    let stored = DbTransform {
        x: dx,
        y: dy,
        rotation_rad: f32_stored(rotate_deg * std::f64::consts::PI / 180.0),
        skew_rad: f32_stored(skew_deg * std::f64::consts::PI / 180.0),
        scale_x: sx,
        scale_y: sy,
    };
    (stored, [dx, dy, rotate_deg, skew_deg, sx, sy])
}

/// Bakes `animation` (named `name`); `sources` and `influences` give, per part, the written
/// mesh's fine-mesh vertices and its number of influences.
#[allow(clippy::too_many_arguments)]
pub(super) fn bake(
    scene: &Scene,
    name: &str,
    animation: &Animation,
    joints: &[Joint],
    setup: &[DbTransform],
    frame: &DbFrame,
    sources: &[&[usize]],
    influences: &[usize],
    options: &DragonBonesOptions,
) -> Result<(Value, BakedAnimation), DragonBonesError> {
    let doc = &scene.doc;
    let fps = f64::from(options.frame_rate);
    let duration = animation.duration_s();
    let exact_frames = duration * fps;
    if exact_frames.is_nan() || exact_frames > crate::export::spine::MAX_BAKE_SAMPLES {
        return Err(DragonBonesError::TooLong {
            animation: name.to_string(),
            frames: exact_frames,
        });
    }
    let n = exact_frames.round() as u32;
    let mut left_out = Vec::new();
    if (exact_frames - f64::from(n)).abs() > 1e-6 {
        left_out.push(format!(
            "animation '{name}': its {duration} s are not a whole number of frames at {fps} fps; \
             it lasts {n} frames ({:.4} s)",
            f64::from(n) / fps
        ));
    }
    let times: Vec<f64> = (0..=n)
        .map(|k| (f64::from(k) / fps).min(duration))
        .collect();
    let samples = bake::sample_path(scene, animation, &times, false)
        .map_err(|e| DragonBonesError::Pose(Box::new(e)))?;

    // Bones.
    let mut previous: Vec<DbTransform> = setup.to_vec();
    let mut bones_written: Vec<Vec<DbTransform>> = Vec::with_capacity(times.len());
    let mut tracks: Vec<[Vec<Value>; 3]> = vec![Default::default(); joints.len()];
    for (k, (_, transforms)) in samples.iter().enumerate() {
        let locals =
            local_maps(joints, transforms, frame).map_err(|e| DragonBonesError::Singular(e.0))?;
        let mut row = Vec::with_capacity(joints.len());
        for (j, local) in locals.iter().enumerate() {
            let t = DbTransform::from_affine(local, Some(&previous[j]));
            previous[j] = t;
            let (stored, [dx, dy, r, s, sx, sy]) = as_stored(&setup[j], &t);
            row.push(stored);
            let duration = u32::from(k < n as usize);
            let frame_of = |pairs: [(&str, f64, f64); 2]| {
                let mut m = Map::new();
                m.insert("duration".into(), json!(duration));
                m.insert("tweenEasing".into(), json!(0));
                for (key, value, default) in pairs {
                    if value != default {
                        m.insert(key.into(), num(value));
                    }
                }
                Value::Object(m)
            };
            tracks[j][0].push(frame_of([("x", dx, 0.0), ("y", dy, 0.0)]));
            tracks[j][1].push(frame_of([("rotate", r, 0.0), ("skew", s, 0.0)]));
            tracks[j][2].push(frame_of([("x", sx, 1.0), ("y", sy, 1.0)]));
        }
        bones_written.push(row);
    }
    let bone_timelines: Vec<Value> = joints
        .iter()
        .zip(tracks)
        .map(|(joint, [translate, rotate, scale])| {
            json!({
                "name": joint.name,
                "translateFrame": translate,
                "rotateFrame": rotate,
                "scaleFrame": scale,
            })
        })
        .collect();

    // Slots: display, colour, deform, draw order.
    let poses: Vec<&Pose> = samples.iter().map(|(pose, _)| pose).collect();
    let slots = doc.slot_names();
    let mut displays = BTreeMap::new();
    let mut colors = BTreeMap::new();
    let mut slot_timelines = Vec::new();
    for slot in &slots {
        let keyed = animation.parts.get(*slot);
        let attachments = doc.attachments_of(slot);
        let mut timeline = Map::new();
        timeline.insert("name".into(), json!(slot));
        if keyed.is_some_and(|t| t.visible.is_some() || t.attachment.is_some()) {
            let values: Vec<i64> = poses
                .iter()
                .map(|pose| {
                    let state = pose.parts.get(*slot);
                    if state.is_some_and(|s| !s.visible) {
                        return -1;
                    }
                    let attachment = state.and_then(|s| s.attachment.as_deref());
                    doc.shown_part(slot, attachment, scene.skins())
                        .and_then(|i| attachments.iter().position(|&a| a == i))
                        .map_or(-1, |k| k as i64)
                })
                .collect();
            timeline.insert(
                "displayFrame".into(),
                step_frames(&values, |v| json!({ "value": v })),
            );
            displays.insert(slot.to_string(), values);
        }
        if keyed.is_some_and(|t| t.color.is_some()) {
            let values: Vec<[i64; 4]> = poses
                .iter()
                .map(|pose| {
                    let c = pose.parts.get(*slot).map_or([1.0; 4], |s| s.color);
                    c.map(|v| (v * 100.0).round() as i64)
                })
                .collect();
            let frames: Vec<Value> = values
                .iter()
                .enumerate()
                .map(|(k, [r, g, b, a])| {
                    json!({
                        "duration": u32::from(k < n as usize),
                        "tweenEasing": 0,
                        "value": { "rM": r, "gM": g, "bM": b, "aM": a },
                    })
                })
                .collect();
            timeline.insert("colorFrame".into(), Value::Array(frames));
            colors.insert(slot.to_string(), values);
        }
        if timeline.len() > 1 {
            slot_timelines.push(Value::Object(timeline));
        }
    }
    let mut deforms = BTreeMap::new();
    let mut ffd = Vec::new();
    // Numbers keyed before each deform timeline: the bones' six per frame, then each deform
    // timeline's (two per influence per frame).
    let mut floats = 6 * joints.len() * times.len();
    for part in animation.deform.keys() {
        let Some(index) = doc.parts.iter().position(|p| &p.name == part) else {
            continue;
        };
        let vertices = doc.parts[index].mesh.vertices.len();
        let offsets: Vec<Vec<Vec2>> = poses
            .iter()
            .map(|pose| {
                pose.deform.get(part).map_or_else(
                    || vec![Vec2::zeros(); vertices],
                    |o| {
                        o.iter()
                            .map(|v| Vec2::new(f32_stored(v.x), f32_stored(v.y)))
                            .collect()
                    },
                )
            })
            .collect();
        let frames: Vec<Value> = offsets
            .iter()
            .enumerate()
            .map(|(k, o)| {
                let mut m = Map::new();
                m.insert("duration".into(), json!(u32::from(k < n as usize)));
                m.insert("tweenEasing".into(), json!(0));
                let written: Vec<Vec2> = sources[index].iter().map(|&v| o[v]).collect();
                if written.iter().any(|v| v.x != 0.0 || v.y != 0.0) {
                    m.insert(
                        "vertices".into(),
                        Value::Array(written.iter().flat_map(|v| [num(v.x), num(v.y)]).collect()),
                    );
                }
                Value::Object(m)
            })
            .collect();
        if floats >= super::MAX_ANIMATION_FLOATS {
            return Err(DragonBonesError::AnimationTooLarge {
                animation: name.to_string(),
                floats,
            });
        }
        floats += 2 * influences[index] * times.len();
        ffd.push(json!({
            "name": part,
            "slot": doc.slot_of(index),
            "skin": "default",
            "frame": frames,
        }));
        deforms.insert(part.clone(), offsets);
    }
    let draw_order = animation.draw_order.as_ref().map(|_| {
        poses
            .iter()
            .map(|pose| match &pose.draw_order {
                Some(order) => order.clone(),
                None => slots.iter().map(|s| s.to_string()).collect(),
            })
            .collect::<Vec<_>>()
    });

    let mut json = Map::new();
    json.insert("name".into(), json!(name));
    json.insert("duration".into(), json!(n));
    // A cycle loops for ever; anything else plays once.
    let play_times = if animation.looping { 0 } else { 1 };
    json.insert("playTimes".into(), json!(play_times));
    json.insert("bone".into(), Value::Array(bone_timelines));
    if !slot_timelines.is_empty() {
        json.insert("slot".into(), Value::Array(slot_timelines));
    }
    if !ffd.is_empty() {
        json.insert("ffd".into(), Value::Array(ffd));
    }
    if let Some(orders) = &draw_order {
        let z: Vec<Value> = orders.iter().map(|o| z_order(&slots, o)).collect();
        json.insert(
            "zOrder".into(),
            json!({ "frame": step_frames(&z, |v| json!({ "zOrder": v })) }),
        );
    }
    if !animation.events.is_empty() {
        json.insert("frame".into(), event_frames(animation, &doc.events, fps, n));
        if animation
            .events
            .iter()
            .any(|e| doc.events.get(&e.name).is_some_and(|d| d.audio.is_some()))
        {
            left_out.push(format!(
                "animation '{name}': event audio (DragonBones events carry no sound path)"
            ));
        }
    }
    let baked = BakedAnimation {
        name: name.to_string(),
        frame_count: n,
        play_times,
        bones: bones_written,
        displays,
        colors,
        deforms,
        draw_order,
        left_out,
    };
    Ok((Value::Object(json), baked))
}

/// Stepped frames of `values` (one per animation frame): a frame where the value changes, its
/// duration the run's length (the last frame's 0).
fn step_frames<T: PartialEq + Clone>(values: &[T], body: impl Fn(&T) -> Value) -> Value {
    let mut frames = Vec::new();
    let mut k = 0;
    while k < values.len() {
        let mut end = k + 1;
        while end < values.len() && values[end] == values[k] {
            end += 1;
        }
        // The last run ends on the animation's last frame, which lasts 0.
        let duration = if end == values.len() {
            end - 1 - k
        } else {
            end - k
        };
        let mut frame = body(&values[k]);
        frame["duration"] = json!(duration);
        frames.push(frame);
        k = end;
    }
    Value::Array(frames)
}

/// A draw order as a `zOrder` frame: (setup index, offset) for every slot not where the setup
/// has it, in setup order.
fn z_order(setup: &[&str], order: &[String]) -> Value {
    let mut pairs = Vec::new();
    for (index, slot) in setup.iter().enumerate() {
        if let Some(now) = order.iter().position(|s| s == slot) {
            if now != index {
                pairs.extend([index as i64, now as i64 - index as i64]);
            }
        }
    }
    json!(pairs)
}

/// The animation's events on their nearest frames, as the `frame` timeline.
fn event_frames(
    animation: &Animation,
    defs: &crate::anim::event::EventDefs,
    fps: f64,
    n: u32,
) -> Value {
    let mut by_frame: BTreeMap<u32, Vec<Value>> = BTreeMap::new();
    for key in &animation.events {
        let def = defs.get(&key.name).cloned().unwrap_or_default();
        let fired = key.fired(&def, crate::anim::CurveEvaluation::Exact);
        let k = ((key.time * fps).round().max(0.0) as u32).min(n);
        by_frame.entry(k).or_default().push(json!({
            "name": fired.name,
            "ints": [fired.int],
            "floats": [num(fired.float)],
            "strings": [fired.string],
        }));
    }
    // An empty frame up to the first event frame; each event frame lasts until the next.
    let starts: Vec<u32> = by_frame.keys().copied().collect();
    let mut frames = Vec::new();
    if starts.first().is_some_and(|&k| k > 0) {
        frames.push(json!({ "duration": starts[0] }));
    }
    for (i, (k, events)) in by_frame.into_iter().enumerate() {
        let next = starts.get(i + 1).copied().unwrap_or(k);
        frames.push(json!({ "duration": next - k, "events": events }));
    }
    Value::Array(frames)
}
