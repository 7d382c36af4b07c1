//! sinew's timelines as Spine 4.2 animation timelines, natively: keys and curves carried over.
//!
//! In: an [`Animation`] (checked against the rig), the rig's handles and parts, the
//! [`Skeleton`] and the [`SpineFrame`]; the bones whose motion is baked instead (their native
//! timelines are left out). Out: the animation's `bones`, `slots` and `drawOrder` sections as
//! JSON (spine-format.md §7).
//!
//! Conversions, each exact:
//! - bone `rotate`, `scale`, `shear` keep their values (sinew's bone frames are Spine's, both
//!   count angles counter-clockwise on screen, both add rotate/shear to the setup value and
//!   multiply scale into a setup scale of 1); `translate` flips y, and so do the y channel's
//!   Bézier `cy` values (a Bézier is affine-invariant in its values);
//! - point handles: `translate` (y flipped), `rotate`, `scale`, `shear` on their zero-length
//!   bone (a point's pose turns, scales and shears about its rest position, which is its bone's
//!   origin); a point carried by a bone has its `translate` turned into that bone's setup axes,
//!   Bézier handles too (a point whose channels' time handles differ is baked instead);
//! - cage keys: one `translate` timeline per cage-vertex bone (posed − rest, y flipped); the
//!   cage's single 0..1 Bézier becomes per-channel absolute handles `v0 + (v1 − v0)·cy`;
//! - part colour → slot `rgba` (Bézier `cy` are channel values, as in sinew); visibility →
//!   slot `attachment` (the part's mesh or `null`); draw order → `drawOrder` offsets;
//! - sinew holds a timeline's first value before its first key where Spine shows the setup
//!   pose, so a timeline whose first key is after 0 s gets a copy of that key at 0 s.
//!
//! Rotations are written as authored: sinew interpolates them as plain numbers too (0 → 350
//! passes through 175 in both).

use super::frame::SpineFrame;
use super::skeleton::Skeleton;
use crate::anim::{Animation, Curve, Key, StepKey};
use crate::geom::Point;
use crate::rig::Handles;
use nalgebra::Matrix2;
use serde_json::{json, Map, Value};
use std::collections::{BTreeMap, BTreeSet};

/// A JSON number; −0 is written as 0.
///
/// Written at the precision the runtimes read (float32): the shortest decimal that reads back
/// as `x`'s nearest f32, so no digit is written that a runtime would drop. Negative zero is
/// written as 0.
pub fn num(x: f64) -> Value {
    if x == 0.0 {
        return json!(0.0);
    }
    let single = x as f32;
    // Display of an f32 is its shortest round-trip decimal; read as f64, serde_json writes
    // that same short text back (a non-finite value becomes null, as before).
    json!(single
        .to_string()
        .parse::<f64>()
        .unwrap_or(f64::from(single)))
}

/// One key's object with its time and curve; `fields` come from the value.
pub(super) fn key_object(time: f64, fields: Vec<(&str, Value)>, curve: Option<Value>) -> Value {
    let mut m = Map::new();
    m.insert("time".into(), num(time));
    for (k, v) in fields {
        m.insert(k.into(), v);
    }
    if let Some(c) = curve {
        m.insert("curve".into(), c);
    }
    Value::Object(m)
}

/// Keys of a timeline with a key at 0 s added when the first comes later (holding its value).
pub(super) fn with_start<V: Clone>(keys: &[Key<V>]) -> Vec<Key<V>> {
    let mut out = Vec::with_capacity(keys.len() + 1);
    if let Some(first) = keys.first() {
        if first.time > 0.0 {
            out.push(Key {
                time: 0.0,
                value: first.value.clone(),
                curve: Curve::Linear,
            });
        }
    }
    out.extend(keys.iter().cloned());
    out
}

fn steps_with_start<V: Clone>(keys: &[StepKey<V>]) -> Vec<StepKey<V>> {
    let mut out = Vec::with_capacity(keys.len() + 1);
    if let Some(first) = keys.first() {
        if first.time > 0.0 {
            out.push(StepKey {
                time: 0.0,
                value: first.value.clone(),
            });
        }
    }
    out.extend(keys.iter().cloned());
    out
}

/// A curve as Spine writes it, channel by channel: `None` for linear. `channel_map(c, cy)` maps
/// a `cy` of channel `c` into the written units.
pub(super) fn curve_json(curve: &Curve, channel_map: &dyn Fn(usize, f64) -> f64) -> Option<Value> {
    match curve {
        Curve::Linear => None,
        Curve::Stepped => Some(json!("stepped")),
        Curve::Bezier(numbers) => Some(Value::Array(
            numbers
                .chunks_exact(4)
                .enumerate()
                .flat_map(|(c, h)| {
                    [
                        num(h[0]),
                        num(channel_map(c, h[1])),
                        num(h[2]),
                        num(channel_map(c, h[3])),
                    ]
                })
                .collect(),
        )),
    }
}

/// A one-value timeline (`value`).
pub fn timeline1(keys: &[Key<f64>]) -> Value {
    Value::Array(
        with_start(keys)
            .iter()
            .map(|k| {
                key_object(
                    k.time,
                    vec![("value", num(k.value))],
                    curve_json(&k.curve, &|_, y| y),
                )
            })
            .collect(),
    )
}

/// A two-value timeline (`x`, `y`); `flip_y` negates y values and the y channel's handles.
pub fn timeline2(keys: &[Key<[f64; 2]>], flip_y: bool) -> Value {
    let s = if flip_y { -1.0 } else { 1.0 };
    Value::Array(
        with_start(keys)
            .iter()
            .map(|k| {
                key_object(
                    k.time,
                    vec![("x", num(k.value[0])), ("y", num(s * k.value[1]))],
                    curve_json(&k.curve, &|c, y| if c == 1 { s * y } else { y }),
                )
            })
            .collect(),
    )
}

/// For a point carried by a bone, the linear map from Spine's world axes to its parent bone's
/// setup axes (in which its bone's offsets are written); `None` for a loose point.
pub fn carrier_from_world(
    handles: &Handles,
    skeleton: &Skeleton,
    point: &str,
) -> Option<Matrix2<f64>> {
    let i = handles.points.iter().position(|p| p.name == point)?;
    handles.point_parent(i)?;
    let bone = skeleton.column_bone.get(handles.bones.len() + i)?;
    let parent = skeleton.bones.get(*bone)?.parent?;
    skeleton.bones[parent].setup_world.linear.try_inverse()
}

/// Whether every Bézier among `keys` has the same time handles (`cx1`, `cx2`) in both
/// channels: then a linear mix of the channels is again such a curve.
pub fn channels_share_time_handles(keys: &[Key<[f64; 2]>]) -> bool {
    keys.iter().all(|k| match &k.curve {
        Curve::Bezier(h) => h.len() < 8 || (h[0] == h[4] && h[2] == h[6]),
        _ => true,
    })
}

/// A carried point's `translate` timeline: its canvas offsets with y flipped (Spine's world),
/// turned into its parent's setup axes by `carrier_from_world`; each Bézier's value handles
/// turned the same way (exact: both channels share their time handles). `None` when they do
/// not ([`channels_share_time_handles`]): the point is then baked.
pub fn carried_translate_timeline(
    keys: &[Key<[f64; 2]>],
    carrier_from_world: &Matrix2<f64>,
) -> Option<Value> {
    if !channels_share_time_handles(keys) {
        return None;
    }
    let m = carrier_from_world;
    let turn = |x: f64, y: f64| m * nalgebra::Vector2::new(x, -y);
    Some(Value::Array(
        with_start(keys)
            .iter()
            .map(|k| {
                let v = turn(k.value[0], k.value[1]);
                let curve = match &k.curve {
                    Curve::Bezier(h) if h.len() >= 8 => {
                        let (a, b) = (turn(h[1], h[5]), turn(h[3], h[7]));
                        curve_json(
                            &Curve::Bezier(vec![h[0], a.x, h[2], b.x, h[4], a.y, h[6], b.y]),
                            &|_, y| y,
                        )
                    }
                    other => curve_json(other, &|_, y| y),
                };
                key_object(k.time, vec![("x", num(v.x)), ("y", num(v.y))], curve)
            })
            .collect(),
    ))
}

/// One cage vertex's `translate` timeline: posed − rest (y flipped); the cage's 0..1 curve in
/// each channel's own units.
fn cage_vertex_timeline(
    keys: &[Key<Vec<Point>>],
    vertex: usize,
    rest: Point,
    frame: &SpineFrame,
) -> Value {
    let keys = with_start(keys);
    let delta = |k: &Key<Vec<Point>>| {
        let p = k.value.get(vertex).copied().unwrap_or(rest);
        frame.spine_vector(p - rest)
    };
    Value::Array(
        keys.iter()
            .enumerate()
            .map(|(i, k)| {
                let v0 = delta(k);
                let v1 = keys.get(i + 1).map_or(v0, delta);
                let curve = match &k.curve {
                    Curve::Bezier(h) if h.len() == 4 => {
                        let per_channel =
                            Curve::Bezier(vec![h[0], h[1], h[2], h[3], h[0], h[1], h[2], h[3]]);
                        curve_json(&per_channel, &|c, cy| v0[c] + (v1[c] - v0[c]) * cy)
                    }
                    other => curve_json(other, &|_, y| y),
                };
                key_object(k.time, vec![("x", num(v0[0])), ("y", num(v0[1]))], curve)
            })
            .collect(),
    )
}

/// A hex colour `rrggbbaa`, as sinew's own files write it.
fn hex(rgba: &crate::anim::Rgba) -> Value {
    serde_json::to_value(rgba).unwrap_or(Value::Null)
}

/// One animation's native sections, as JSON.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NativeTimelines {
    /// Bone name → timeline name → keys.
    pub bones: BTreeMap<String, Map<String, Value>>,
    /// Slot name → timeline name → keys.
    pub slots: Map<String, Value>,
    pub draw_order: Option<Value>,
}

/// The `bones`, `slots` and `drawOrder` sections of one animation, without the bones in
/// `baked` (by skeleton index).
pub fn native_timelines(
    animation: &Animation,
    handles: &Handles,
    parts: &[String],
    skeleton: &Skeleton,
    frame: &SpineFrame,
    baked: &BTreeSet<usize>,
) -> NativeTimelines {
    let mut bones: BTreeMap<String, Map<String, Value>> = BTreeMap::new();
    let bone_of = |name: &str| skeleton.bones.iter().position(|b| b.name == name);
    let mut put = |bone: &str, timeline: &str, value: Value| {
        if bone_of(bone).is_some_and(|i| !baked.contains(&i)) {
            bones
                .entry(bone.to_string())
                .or_default()
                .insert(timeline.into(), value);
        }
    };
    for (name, t) in &animation.bones {
        if let Some(k) = &t.rotate {
            put(name, "rotate", timeline1(k));
        }
        if let Some(k) = &t.translate {
            put(name, "translate", timeline2(k, true));
        }
        if let Some(k) = &t.scale {
            put(name, "scale", timeline2(k, false));
        }
        if let Some(k) = &t.shear {
            put(name, "shear", timeline2(k, false));
        }
    }
    for (name, t) in &animation.points {
        if let Some(k) = &t.translate {
            match carrier_from_world(handles, skeleton, name) {
                // Baked instead when not expressible (see `plan_bake`).
                Some(m) => {
                    if let Some(timeline) = carried_translate_timeline(k, &m) {
                        put(name, "translate", timeline);
                    }
                }
                None => put(name, "translate", timeline2(k, true)),
            }
        }
        if let Some(k) = &t.rotate {
            put(name, "rotate", timeline1(k));
        }
        if let Some(k) = &t.scale {
            put(name, "scale", timeline2(k, false));
        }
        if let Some(k) = &t.shear {
            put(name, "shear", timeline2(k, false));
        }
    }
    for (name, keys) in &animation.cages {
        let Some(cage) = handles.cages.iter().find(|c| &c.name == name) else {
            continue;
        };
        for (k, rest) in cage.polygon.iter().enumerate() {
            put(
                &format!("{name}.{k}"),
                "translate",
                cage_vertex_timeline(keys, k, *rest, frame),
            );
        }
    }

    let mut slots = Map::new();
    for (name, t) in &animation.parts {
        let mut m = Map::new();
        if let Some(keys) = &t.color {
            let keys: Vec<Value> = with_start(keys)
                .iter()
                .map(|k| {
                    key_object(
                        k.time,
                        vec![("color", hex(&k.value))],
                        curve_json(&k.curve, &|_, y| y),
                    )
                })
                .collect();
            m.insert("rgba".into(), Value::Array(keys));
        }
        if let Some(keys) = &t.visible {
            let keys: Vec<Value> = steps_with_start(keys)
                .iter()
                .map(|k| {
                    let shown = if k.value { json!(name) } else { Value::Null };
                    key_object(k.time, vec![("name", shown)], None)
                })
                .collect();
            m.insert("attachment".into(), Value::Array(keys));
        }
        // Names as authored: the slot's own name is the placeholder each skin fills.
        if let Some(keys) = &t.attachment {
            let keys: Vec<Value> = steps_with_start(keys)
                .iter()
                .map(|k| key_object(k.time, vec![("name", json!(k.value))], None))
                .collect();
            m.insert("attachment".into(), Value::Array(keys));
        }
        if !m.is_empty() {
            slots.insert(name.clone(), Value::Object(m));
        }
    }

    let draw_order = animation.draw_order.as_ref().map(|keys| {
        Value::Array(
            steps_with_start(keys)
                .iter()
                .map(|k| {
                    // Every part whose place changed, in setup order: the runtime walks the
                    // offsets in setup order and fills the gaps with the others, in order.
                    let offsets: Vec<Value> = parts
                        .iter()
                        .enumerate()
                        .filter_map(|(setup, part)| {
                            let now = k.value.iter().position(|p| p == part)?;
                            (now != setup)
                                .then(|| json!({"slot": part, "offset": now as i64 - setup as i64}))
                        })
                        .collect();
                    key_object(k.time, vec![("offsets", Value::Array(offsets))], None)
                })
                .collect(),
        )
    });
    NativeTimelines {
        bones,
        slots,
        draw_order,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_written_as_the_shortest_text_of_their_f32() {
        let mut x = 0.1234567890123f64;
        for _ in 0..2000 {
            x = (x * 7.3 + 0.37).rem_euclid(2048.0) - 1024.0;
            let text = num(x).to_string();
            let read: f32 = text.parse().unwrap();
            assert_eq!(read, x as f32, "{x} written as {text}");
            let digits = text.chars().filter(char::is_ascii_digit).count();
            assert!(digits <= 11, "{x} written as {text}");
        }
        assert_eq!(num(0.1).to_string(), "0.1");
        assert_eq!(num(-0.0).to_string(), "0.0");
        assert_eq!(num(1.0 / 3.0).to_string(), "0.33333334");
    }

    #[test]
    fn translate_flips_y_and_its_handles_and_gets_a_start_key() {
        let keys = vec![
            Key {
                time: 0.5,
                value: [1.0, 2.0],
                curve: Curve::Bezier(vec![0.6, 1.0, 0.7, 3.0, 0.6, 2.0, 0.7, 5.0]),
            },
            Key {
                time: 1.0,
                value: [3.0, 6.0],
                curve: Curve::Linear,
            },
        ];
        let v = timeline2(&keys, true);
        assert_eq!(v[0], json!({"time": 0.0, "x": 1.0, "y": -2.0}));
        assert_eq!(
            v[1]["curve"],
            json!([0.6, 1.0, 0.7, 3.0, 0.6, -2.0, 0.7, -5.0])
        );
        assert_eq!(v[2], json!({"time": 1.0, "x": 3.0, "y": -6.0}));
    }

    #[test]
    fn cage_curves_become_absolute_per_channel() {
        let keys = vec![
            Key {
                time: 0.0,
                value: vec![Point::new(10.0, 10.0)],
                curve: Curve::Bezier(vec![0.25, 0.0, 0.75, 1.0]),
            },
            Key {
                time: 1.0,
                value: vec![Point::new(14.0, 2.0)],
                curve: Curve::Stepped,
            },
        ];
        let frame = SpineFrame::for_canvas([20, 20]);
        let v = cage_vertex_timeline(&keys, 0, Point::new(10.0, 10.0), &frame);
        assert_eq!(v[0]["x"], json!(0.0));
        // x: 0 → 4, handles at 0 and 4; y: 0 → +8 (canvas −8, flipped), handles 0 and 8.
        assert_eq!(
            v[0]["curve"],
            json!([0.25, 0.0, 0.75, 4.0, 0.25, 0.0, 0.75, 8.0])
        );
        assert_eq!(v[1]["y"], json!(8.0));
        assert_eq!(v[1]["curve"], json!("stepped"));
    }
}
