//! The animation model: keys, timelines, and their checks.
//!
//! In: one animation as JSON (an entry of the rig document's `animations` map, read once where
//! a document or an animations file is loaded; see [`animations_from_json`]). Out: an
//! [`Animation`] whose keys are checked: times finite, ≥ 0 and strictly increasing; values
//! finite; Bézier curves of the right length with their control times inside their segment;
//! colors in [0, 1]; cage keys of one vertex count; draw-order keys without repeated names.
//! Units: seconds, degrees (counter-clockwise on screen), canvas px, colors as 0..1 multipliers.

use super::curve::{Curve, BEZIER_NUMBERS_PER_CHANNEL};
use super::AnimError;
use crate::geom::{point_numbers, point_numbers_mut, Point, Vec2};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::collections::BTreeMap;

/// A key: a value at a time, and how it travels to the next key.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Key<V> {
    /// Seconds from the start of the animation.
    pub time: f64,
    pub value: V,
    /// Interpolation to the next key (ignored on the last key).
    #[serde(default, skip_serializing_if = "Curve::is_linear")]
    pub curve: Curve,
}

/// A key of a timeline that only ever steps (visibility, draw order): no curve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StepKey<V> {
    pub time: f64,
    pub value: V,
}

/// A color multiplier, channels in [0, 1]; in files a `"rrggbbaa"` hex string as Spine writes
/// it (`"rrggbb"` means opaque).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rgba(pub [f64; 4]);

impl Serialize for Rgba {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let byte = |c: f64| (c.clamp(0.0, 1.0) * 255.0).round() as u8;
        let [r, g, b, a] = self.0.map(byte);
        serializer.serialize_str(&format!("{r:02x}{g:02x}{b:02x}{a:02x}"))
    }
}

impl<'de> Deserialize<'de> for Rgba {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let text = String::deserialize(deserializer)?;
        parse_hex_color(&text).ok_or_else(|| {
            serde::de::Error::custom(format!(
                "color \"{text}\" is not an \"rrggbbaa\" (or \"rrggbb\") hex string"
            ))
        })
    }
}

fn parse_hex_color(text: &str) -> Option<Rgba> {
    if !(text.len() == 6 || text.len() == 8) || !text.is_ascii() {
        return None;
    }
    let mut rgba = [1.0; 4];
    for (i, c) in rgba.iter_mut().enumerate().take(text.len() / 2) {
        *c = f64::from(u8::from_str_radix(&text[2 * i..2 * i + 2], 16).ok()?) / 255.0;
    }
    Some(Rgba(rgba))
}

/// A key value seen as a run of numbers that interpolate channel by channel.
pub trait Channels: Clone {
    /// Whether a Bézier's `cy` values are in the value's own units, one curve per number (Spine's
    /// bone, color and IK timelines), or a 0..1 fraction of the way, one curve for all numbers
    /// (Spine's deform timelines; used for cage polygons).
    const CURVE_PER_CHANNEL: bool = true;
    fn numbers(&self) -> &[f64];
    fn numbers_mut(&mut self) -> &mut [f64];
    /// How many Bézier channels (4 numbers each) a key's curve holds.
    fn curve_channels(&self) -> usize {
        if Self::CURVE_PER_CHANNEL {
            self.numbers().len()
        } else {
            1
        }
    }
}

impl Channels for f64 {
    fn numbers(&self) -> &[f64] {
        std::slice::from_ref(self)
    }
    fn numbers_mut(&mut self) -> &mut [f64] {
        std::slice::from_mut(self)
    }
}

impl Channels for [f64; 2] {
    fn numbers(&self) -> &[f64] {
        self
    }
    fn numbers_mut(&mut self) -> &mut [f64] {
        self
    }
}

impl Channels for Rgba {
    fn numbers(&self) -> &[f64] {
        &self.0
    }
    fn numbers_mut(&mut self) -> &mut [f64] {
        &mut self.0
    }
}

impl Channels for Point {
    fn numbers(&self) -> &[f64] {
        self.coords.as_slice()
    }
    fn numbers_mut(&mut self) -> &mut [f64] {
        self.coords.as_mut_slice()
    }
}

impl Channels for Vec<Vec2> {
    const CURVE_PER_CHANNEL: bool = false;
    fn numbers(&self) -> &[f64] {
        bytemuck::cast_slice(self)
    }
    fn numbers_mut(&mut self) -> &mut [f64] {
        bytemuck::cast_slice_mut(self)
    }
}

impl Channels for Vec<Point> {
    const CURVE_PER_CHANNEL: bool = false;
    fn numbers(&self) -> &[f64] {
        point_numbers(self)
    }
    fn numbers_mut(&mut self) -> &mut [f64] {
        point_numbers_mut(self)
    }
}

/// A bone's timelines; each value replaces the bone's [`crate::rig::pose::BonePose`] field.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct BoneTimelines {
    /// Degrees, counter-clockwise on screen; interpolated as authored (0 → 360 is a full turn).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotate: Option<Vec<Key<f64>>>,
    /// px, in the parent's frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub translate: Option<Vec<Key<[f64; 2]>>>,
    /// Along the bone, across it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scale: Option<Vec<Key<[f64; 2]>>>,
    /// Degrees: x axis, y axis.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shear: Option<Vec<Key<[f64; 2]>>>,
}

/// A point handle's timelines, as [`crate::rig::pose::PointPose`].
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct PointTimelines {
    /// px, canvas axes (a carried point: at rest, before its bone's motion).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub translate: Option<Vec<Key<[f64; 2]>>>,
    /// Degrees, counter-clockwise on screen, about the point's rest position.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotate: Option<Vec<Key<f64>>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scale: Option<Vec<Key<[f64; 2]>>>,
    /// Degrees: x axis, y axis.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shear: Option<Vec<Key<[f64; 2]>>>,
}

/// A part's timelines, as [`crate::rig::pose::PartPose`].
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct PartTimelines {
    /// RGBA multiplier; a Bézier has 4 channels whose `cy` are channel values in [0, 1].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub color: Option<Vec<Key<Rgba>>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub visible: Option<Vec<StepKey<bool>>>,
    /// Which attachment the slot shows (a part of the slot by name; the slot's own name: its
    /// default as the skins resolve it), or `null`: none. Stepped, as Spine's attachment
    /// timeline; an animation keys either this or `visible` of a slot.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub attachment: Option<Vec<StepKey<Option<String>>>>,
}

/// A keyed skinning-IK drag: the material point at rest position `at` (canvas px) goes to the
/// keyed position.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct IkTimeline {
    #[schemars(with = "[f64; 2]")]
    pub at: Point,
    #[schemars(with = "Vec<Key<[f64; 2]>>")]
    pub to: Vec<Key<Point>>,
    /// A soft drag's strength (see [`crate::rig::pose::IkDrag`]); none: a hard constraint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weight: Option<f64>,
}

/// One animation: timelines by what they move. Anything without a timeline stays at rest.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Animation {
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub bones: BTreeMap<String, BoneTimelines>,
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub points: BTreeMap<String, PointTimelines>,
    /// Posed polygons (canvas px), the same vertex count on every key and as at rest.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    #[schemars(with = "BTreeMap<String, Vec<Key<Vec<[f64; 2]>>>>")]
    pub cages: BTreeMap<String, Vec<Key<Vec<Point>>>>,
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub parts: BTreeMap<String, PartTimelines>,
    /// Each key lists every part of the rig once, back to front.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub draw_order: Option<Vec<StepKey<Vec<String>>>>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub ik: Vec<IkTimeline>,
    /// Events fired at their times (names of the rig document's `events`), in time order;
    /// several keys may share a time.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub events: Vec<super::event::EventKey>,
    /// Deform keys ([`super::deform`]): part name → per-vertex offsets of its mesh (canvas px,
    /// rest frame), added before skinning; the same count on every key as the part's vertices.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    #[schemars(with = "BTreeMap<String, Vec<Key<Vec<[f64; 2]>>>>")]
    pub deform: BTreeMap<String, super::deform::DeformKeys>,
    /// Whether the animation is a cycle, made to play over and over (in files `loop`, left out
    /// when false). Its keys are unchanged by it; what it changes is motion with a history
    /// (physics constraints, skinning-IK momentum): a looping animation shows it in its
    /// periodic steady state, as if it had been playing for ever, so that its end runs into its
    /// start without a jump ([`crate::scene::play`]). Default false: the motion starts from
    /// rest at time 0.
    #[serde(rename = "loop", skip_serializing_if = "std::ops::Not::not")]
    pub looping: bool,
}

/// What is wrong with one timeline (the enclosing [`AnimError`] names it).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TimelineError {
    #[error("{0}")]
    Json(String),
    #[error("has no keys")]
    NoKeys,
    #[error("key {key} has time {time}, which is not a finite number ≥ 0")]
    BadTime { key: usize, time: f64 },
    #[error("key {key} at {time} s does not come after the previous key at {previous} s")]
    TimeNotIncreasing {
        key: usize,
        time: f64,
        previous: f64,
    },
    #[error("key {key} has a value that is not a finite number")]
    NonFinite { key: usize },
    #[error("key {key} has a value beyond ±{MAX_KEY_VALUE} (px, degrees or scale): {}", crate::shown::Shown(*.value))]
    ValueTooLarge { key: usize, value: f64 },
    #[error("key {key} has a curve value beyond ±{MAX_KEY_VALUE}: {}", crate::shown::Shown(*.value))]
    CurveValueTooLarge { key: usize, value: f64 },
    #[error("key {key} has a curve of {got} numbers; expected {expected} (4 per value channel)")]
    CurveLength {
        key: usize,
        got: usize,
        expected: usize,
    },
    #[error("key {key} has a curve number that is not finite")]
    CurveNonFinite { key: usize },
    #[error("key {key} has a curve handle outside its segment's time span [{start}, {end}] s")]
    CurveTime { key: usize, start: f64, end: f64 },
    #[error("key {key} has a color channel outside [0, 1]")]
    ColorRange { key: usize },
    #[error("key {key} has {got} vertices but key 0 has {expected}")]
    VertexCount {
        key: usize,
        got: usize,
        expected: usize,
    },
    #[error(
        "key {key}: {field} must be a finite number{} (got {})",
        super::event::range_text(field), crate::shown::Shown(*.value)
    )]
    Payload {
        key: usize,
        field: &'static str,
        value: f64,
    },
    #[error("key {key} lists part '{name}' twice")]
    DuplicatePart { key: usize, name: String },
}

/// The largest magnitude of a key's value or of a Bézier handle's value, in the channel's
/// units (px, degrees, scale factor, 0..1 fraction): a rotation of 1e300° or a handle at 1e300
/// has no meaning and overflows what is computed from it. Posing limits the result further
/// ([`crate::rig::pose::MAX_POSED_PX`], [`crate::rig::pose::MAX_POSED_SCALE`]).
pub const MAX_KEY_VALUE: f64 = 1e6;

/// The first number of `numbers` beyond ±[`MAX_KEY_VALUE`].
fn too_large(numbers: &[f64]) -> Option<f64> {
    numbers.iter().copied().find(|v| v.abs() > MAX_KEY_VALUE)
}

/// Times: finite, ≥ 0, strictly increasing; at least one key.
fn check_times(times: impl Iterator<Item = f64>) -> Result<(), TimelineError> {
    let mut previous: Option<f64> = None;
    for (key, time) in times.enumerate() {
        if !(time.is_finite() && time >= 0.0) {
            return Err(TimelineError::BadTime { key, time });
        }
        if let Some(previous) = previous {
            if time <= previous {
                return Err(TimelineError::TimeNotIncreasing {
                    key,
                    time,
                    previous,
                });
            }
        }
        previous = Some(time);
    }
    match previous {
        Some(_) => Ok(()),
        None => Err(TimelineError::NoKeys),
    }
}

/// Times, finite values, and curves of the right length whose handles stay in their segment —
/// which keeps each segment's time a monotone function of the curve parameter.
fn check_keys<V: Channels>(keys: &[Key<V>]) -> Result<(), TimelineError> {
    check_times(keys.iter().map(|k| k.time))?;
    for (i, k) in keys.iter().enumerate() {
        let values = k.value.numbers();
        if !values.iter().all(|v| v.is_finite()) {
            return Err(TimelineError::NonFinite { key: i });
        }
        if let Some(value) = too_large(values) {
            return Err(TimelineError::ValueTooLarge { key: i, value });
        }
        let Curve::Bezier(numbers) = &k.curve else {
            continue;
        };
        let expected = BEZIER_NUMBERS_PER_CHANNEL * k.value.curve_channels();
        if numbers.len() != expected {
            return Err(TimelineError::CurveLength {
                key: i,
                got: numbers.len(),
                expected,
            });
        }
        if !numbers.iter().all(|v| v.is_finite()) {
            return Err(TimelineError::CurveNonFinite { key: i });
        }
        let handle_values: Vec<f64> = numbers.chunks_exact(2).map(|pair| pair[1]).collect();
        if let Some(value) = too_large(&handle_values) {
            return Err(TimelineError::CurveValueTooLarge { key: i, value });
        }
        if let Some(next) = keys.get(i + 1) {
            let inside = |cx: f64| cx >= k.time && cx <= next.time;
            let handle_times = numbers.chunks_exact(2).map(|pair| pair[0]);
            if !handle_times.clone().all(inside) {
                return Err(TimelineError::CurveTime {
                    key: i,
                    start: k.time,
                    end: next.time,
                });
            }
        }
    }
    Ok(())
}

fn check_step_keys<V>(keys: &[StepKey<V>]) -> Result<(), TimelineError> {
    check_times(keys.iter().map(|k| k.time))
}

fn check_color_keys(keys: &[Key<Rgba>]) -> Result<(), TimelineError> {
    check_keys(keys)?;
    match keys
        .iter()
        .position(|k| !k.value.0.iter().all(|c| (0.0..=1.0).contains(c)))
    {
        Some(key) => Err(TimelineError::ColorRange { key }),
        None => Ok(()),
    }
}

fn check_cage_keys<T>(keys: &[Key<Vec<T>>]) -> Result<(), TimelineError>
where
    Vec<T>: Channels,
{
    check_keys(keys)?;
    let expected = keys.first().map_or(0, |k| k.value.len());
    match keys.iter().position(|k| k.value.len() != expected) {
        Some(key) => Err(TimelineError::VertexCount {
            key,
            got: keys[key].value.len(),
            expected,
        }),
        None => Ok(()),
    }
}

fn check_draw_order_keys(keys: &[StepKey<Vec<String>>]) -> Result<(), TimelineError> {
    check_step_keys(keys)?;
    for (key, k) in keys.iter().enumerate() {
        let mut seen = std::collections::HashSet::new();
        if let Some(name) = k.value.iter().find(|n| !seen.insert(n.as_str())) {
            return Err(TimelineError::DuplicatePart {
                key,
                name: name.clone(),
            });
        }
    }
    Ok(())
}

impl Animation {
    /// Parses and checks the animation `name` from its JSON value.
    pub fn from_json(name: &str, value: &serde_json::Value) -> Result<Animation, AnimError> {
        // serde would also take an array for the struct (its fields in order).
        if !value.is_object() {
            return Err(AnimError::Malformed {
                animation: name.into(),
                reason: "expected an object: kind → timelines".into(),
            });
        }
        match Animation::deserialize(value) {
            Ok(animation) => {
                animation.validate(name)?;
                Ok(animation)
            }
            Err(whole) => {
                Err(
                    locate_json_error(name, value).unwrap_or_else(|| AnimError::Malformed {
                        animation: name.into(),
                        reason: whole.to_string(),
                    }),
                )
            }
        }
    }

    /// Checks every timeline on its own (no rig needed); see the module doc for what.
    pub fn validate(&self, name: &str) -> Result<(), AnimError> {
        let fail = |timeline: String| {
            move |problem| AnimError::Timeline {
                animation: name.into(),
                timeline,
                problem,
            }
        };
        for (bone, t) in &self.bones {
            let path = |what: &str| format!("bones.{bone}.{what}");
            if let Some(keys) = &t.rotate {
                check_keys(keys).map_err(fail(path("rotate")))?;
            }
            for (what, keys) in [
                ("translate", &t.translate),
                ("scale", &t.scale),
                ("shear", &t.shear),
            ] {
                if let Some(keys) = keys {
                    check_keys(keys).map_err(fail(path(what)))?;
                }
            }
        }
        for (point, t) in &self.points {
            let path = |what: &str| format!("points.{point}.{what}");
            if let Some(keys) = &t.rotate {
                check_keys(keys).map_err(fail(path("rotate")))?;
            }
            for (what, keys) in [
                ("translate", &t.translate),
                ("scale", &t.scale),
                ("shear", &t.shear),
            ] {
                if let Some(keys) = keys {
                    check_keys(keys).map_err(fail(path(what)))?;
                }
            }
        }
        for (cage, keys) in &self.cages {
            check_cage_keys(keys).map_err(fail(format!("cages.{cage}")))?;
        }
        for (part, keys) in &self.deform {
            check_cage_keys(keys).map_err(fail(format!("deform.{part}")))?;
        }
        for (part, t) in &self.parts {
            if let Some(keys) = &t.color {
                check_color_keys(keys).map_err(fail(format!("parts.{part}.color")))?;
            }
            if let Some(keys) = &t.visible {
                check_step_keys(keys).map_err(fail(format!("parts.{part}.visible")))?;
            }
            if let Some(keys) = &t.attachment {
                check_step_keys(keys).map_err(fail(format!("parts.{part}.attachment")))?;
            }
        }
        if let Some(keys) = &self.draw_order {
            check_draw_order_keys(keys).map_err(fail("draw_order".into()))?;
        }
        for (i, drag) in self.ik.iter().enumerate() {
            if !drag.at.iter().all(|v| v.is_finite()) {
                return Err(fail(format!("ik[{i}].at"))(TimelineError::NonFinite {
                    key: 0,
                }));
            }
            if let Some(value) = too_large(drag.at.coords.as_slice()) {
                return Err(fail(format!("ik[{i}].at"))(TimelineError::ValueTooLarge {
                    key: 0,
                    value,
                }));
            }
            check_keys(&drag.to).map_err(fail(format!("ik[{i}].to")))?;
        }
        super::event::check_event_keys(&self.events).map_err(fail("events".into()))?;
        Ok(())
    }

    /// The time of the latest key over all timelines, seconds (0 for an empty animation).
    pub fn duration_s(&self) -> f64 {
        fn last<K>(keys: &[K], time: impl Fn(&K) -> f64) -> f64 {
            keys.last().map_or(0.0, time)
        }
        let key = |k: &Key<f64>| k.time;
        let key2 = |k: &Key<[f64; 2]>| k.time;
        let mut end = 0.0_f64;
        let mut see = |t: f64| end = end.max(t);
        for t in self.bones.values() {
            see(t.rotate.as_deref().map_or(0.0, |k| last(k, key)));
            for keys in [&t.translate, &t.scale, &t.shear] {
                see(keys.as_deref().map_or(0.0, |k| last(k, key2)));
            }
        }
        for t in self.points.values() {
            see(t.rotate.as_deref().map_or(0.0, |k| last(k, key)));
            for keys in [&t.translate, &t.scale, &t.shear] {
                see(keys.as_deref().map_or(0.0, |k| last(k, key2)));
            }
        }
        for keys in self.cages.values() {
            see(last(keys, |k| k.time));
        }
        for keys in self.deform.values() {
            see(last(keys, |k| k.time));
        }
        for t in self.parts.values() {
            see(t.color.as_deref().map_or(0.0, |k| last(k, |k| k.time)));
            see(t.visible.as_deref().map_or(0.0, |k| last(k, |k| k.time)));
            see(t.attachment.as_deref().map_or(0.0, |k| last(k, |k| k.time)));
        }
        if let Some(keys) = &self.draw_order {
            see(last(keys, |k| k.time));
        }
        for drag in &self.ik {
            see(last(&drag.to, |k| k.time));
        }
        see(last(&self.events, |k| k.time));
        end
    }
}

/// Every animation of a rig document's `animations` map, parsed and checked on its own.
pub fn parse_animations(
    animations: &BTreeMap<String, serde_json::Value>,
) -> Result<BTreeMap<String, Animation>, AnimError> {
    parse_each(animations)
}

/// [`parse_animations`] for the map as JSON (a rig document's `animations`, or an animations
/// file: name → animation), which must be an object.
pub fn animations_from_json(
    animations: &serde_json::Value,
) -> Result<BTreeMap<String, Animation>, AnimError> {
    parse_each(animations.as_object().ok_or(AnimError::NotAMap)?)
}

fn parse_each<'a>(
    animations: impl IntoIterator<Item = (&'a String, &'a serde_json::Value)>,
) -> Result<BTreeMap<String, Animation>, AnimError> {
    animations
        .into_iter()
        .map(|(name, value)| Ok((name.clone(), Animation::from_json(name, value)?)))
        .collect()
}

const NOT_A_MAP: &str = "expected an object: name → timelines";

/// Where in an animation's JSON serde failed: tries each timeline (then each key) on its own,
/// so the message names the timeline. `None` when no single piece fails by itself.
fn locate_json_error(name: &str, value: &serde_json::Value) -> Option<AnimError> {
    let fail = |timeline: String, reason: String| AnimError::Timeline {
        animation: name.into(),
        timeline,
        problem: TimelineError::Json(reason),
    };
    let malformed = |reason: String| AnimError::Malformed {
        animation: name.into(),
        reason,
    };
    let object = value.as_object()?;
    for (section, content) in object {
        match section.as_str() {
            "bones" | "points" | "parts" => {
                let Some(names) = content.as_object() else {
                    return Some(fail(section.clone(), NOT_A_MAP.into()));
                };
                for (thing, timelines) in names {
                    let Some(timelines) = timelines.as_object() else {
                        return Some(fail(
                            format!("{section}.{thing}"),
                            "expected an object of timelines".into(),
                        ));
                    };
                    for (timeline, keys) in timelines {
                        let path = format!("{section}.{thing}.{timeline}");
                        let probed = match (section.as_str(), timeline.as_str()) {
                            ("bones" | "points", "rotate") => probe_keys::<Key<f64>>(keys),
                            ("bones", "translate" | "scale" | "shear")
                            | ("points", "translate" | "scale" | "shear") => {
                                probe_keys::<Key<[f64; 2]>>(keys)
                            }
                            ("parts", "color") => probe_keys::<Key<Rgba>>(keys),
                            ("parts", "visible") => probe_keys::<StepKey<bool>>(keys),
                            ("parts", "attachment") => probe_keys::<StepKey<Option<String>>>(keys),
                            _ => {
                                let expected = match section.as_str() {
                                    "bones" => "rotate, translate, scale or shear",
                                    "points" => "translate, rotate, scale or shear",
                                    _ => "color, visible or attachment",
                                };
                                return Some(fail(
                                    path,
                                    format!("unknown timeline '{timeline}' (expected {expected})"),
                                ));
                            }
                        };
                        if let Err((at, reason)) = probed {
                            return Some(fail(path + &at, reason));
                        }
                    }
                }
            }
            "cages" | "deform" => {
                let Some(cages) = content.as_object() else {
                    return Some(fail(section.clone(), NOT_A_MAP.into()));
                };
                for (cage, keys) in cages {
                    if let Err((at, reason)) = probe_keys::<Key<Vec<Point>>>(keys) {
                        return Some(fail(format!("{section}.{cage}{at}"), reason));
                    }
                }
            }
            "draw_order" => {
                if let Err((at, reason)) = probe_keys::<StepKey<Vec<String>>>(content) {
                    return Some(fail(format!("draw_order{at}"), reason));
                }
            }
            "events" => {
                if let Err((at, reason)) = probe_keys::<super::event::EventKey>(content) {
                    return Some(fail(format!("events{at}"), reason));
                }
            }
            "ik" => {
                let Some(drags) = content.as_array() else {
                    return Some(fail(section.clone(), "expected an array of drags".into()));
                };
                for (i, drag) in drags.iter().enumerate() {
                    if let Err(e) = IkTimeline::deserialize(drag) {
                        if let Some(Err((at, reason))) =
                            drag.get("to").map(probe_keys::<Key<Point>>)
                        {
                            return Some(fail(format!("ik[{i}].to{at}"), reason));
                        }
                        return Some(fail(format!("ik[{i}]"), e.to_string()));
                    }
                }
            }
            "loop" => {
                if !content.is_boolean() {
                    return Some(fail("loop".into(), "expected true or false".into()));
                }
            }
            other => {
                return Some(malformed(format!(
                    "unknown section '{other}' (expected bones, points, cages, parts, \
                     draw_order, ik, events, deform or loop)"
                )))
            }
        }
    }
    None
}

/// Deserializes a key list, key by key; on failure, the key's place (" key 3") and serde's reason.
fn probe_keys<K: DeserializeOwned>(keys: &serde_json::Value) -> Result<(), (String, String)> {
    match keys.as_array() {
        Some(list) => {
            for (i, key) in list.iter().enumerate() {
                K::deserialize(key).map_err(|e| (format!(" key {i}"), e.to_string()))?;
            }
            Ok(())
        }
        None => Vec::<K>::deserialize(keys)
            .map(|_| ())
            .map_err(|e| (String::new(), e.to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn the_loop_flag_reads_and_writes_as_loop_and_is_left_out_when_false() {
        let keys = json!({"bones": {"b": {"rotate": [{"time": 0.0, "value": 0.0}, {"time": 1.0, "value": 9.0}]}}});
        let plain = Animation::from_json("a", &keys).unwrap();
        assert!(!plain.looping);
        assert!(serde_json::to_value(&plain).unwrap().get("loop").is_none());
        let mut flagged_json = keys.clone();
        flagged_json["loop"] = json!(true);
        let flagged = Animation::from_json("a", &flagged_json).unwrap();
        assert!(flagged.looping);
        assert_eq!(serde_json::to_value(&flagged).unwrap(), flagged_json);
        // Not a boolean: the message names `loop`; unknown sections are still refused.
        let mut bad = keys.clone();
        bad["loop"] = json!(1);
        let e = Animation::from_json("a", &bad).unwrap_err().to_string();
        assert!(e.contains("loop"), "{e}");
        let mut unknown = keys;
        unknown["loops"] = json!(true);
        let e = Animation::from_json("a", &unknown).unwrap_err().to_string();
        assert!(e.contains("unknown section 'loops'"), "{e}");
    }
}
