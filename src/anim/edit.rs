//! Editing an animation's keys timeline by timeline: list, move in time, copy and paste,
//! delete, and set the curve of a key's outgoing segment.
//!
//! In: one animation as JSON (an entry of the rig document's `animations` map, see
//! [`super::timeline`]) and keys named by [`KeyRef`] — a timeline ([`TimelineId`]: a handle or
//! part and one of its channels) and a time. Out: the edited animation as JSON, checked as
//! [`Animation::from_json`] checks any animation and written in its normal form, or an
//! [`EditError`] and no change.
//!
//! Rules every edit keeps:
//! - times stay finite and ≥ 0;
//! - a move that would put two keys of one timeline at the same time (within
//!   [`KEY_TIME_TOLERANCE_S`]) is **refused** ([`EditError::Collision`]): moving is for
//!   re-timing, and silently dropping a key the animator did not select would lose work. A
//!   paste **replaces** a key at the same time, as keying the pose does: pasting is writing
//!   values at the playhead;
//! - Bézier handles are times in seconds, so when a segment's keys move (or a key between
//!   them is deleted, or one is pasted in) every handle keeps its fraction of its segment's
//!   time span; this keeps the shape and keeps the handles inside the segment, which the
//!   timeline check requires;
//! - a timeline left without keys is removed (an IK drag with it, so later drags move up).

use super::curve::{Curve, BEZIER_NUMBERS_PER_CHANNEL};
use super::timeline::Rgba;
use super::{AnimError, Animation};
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

/// Keys closer in time than this (s) are the same key.
pub const KEY_TIME_TOLERANCE_S: f64 = 1e-6;

/// What an edit got wrong; the animation is unchanged.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EditError {
    #[error("animation '{0}' is not a JSON object")]
    NotAnObject(String),
    #[error("{timeline} has no key at {time_s} s")]
    UnknownKey { timeline: String, time_s: f64 },
    #[error("the animation has no {0} to paste into")]
    UnknownTimeline(String),
    #[error("a key time must be a finite number of seconds ≥ 0, not {0}")]
    BadTime(f64),
    #[error("a time shift must be a finite number of seconds, not {0}")]
    BadShift(f64),
    #[error("{timeline} would have two keys at {time_s} s; move the other key first")]
    Collision { timeline: String, time_s: f64 },
    #[error("{0} only steps from key to key; it has no curves")]
    NoCurves(String),
    #[error("the key of {timeline} at {time_s} s is the last one: there is no segment to curve")]
    LastKey { timeline: String, time_s: f64 },
    #[error("{timeline}: key {key} is malformed ({reason})")]
    MalformedKey {
        timeline: String,
        key: usize,
        reason: String,
    },
    #[error(transparent)]
    Animation(#[from] AnimError),
}

/// The transform channels bones and point handles have, as their timelines name them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TransformChannel {
    Rotate,
    Translate,
    Scale,
    Shear,
}

impl TransformChannel {
    pub const ALL: [TransformChannel; 4] = [
        TransformChannel::Rotate,
        TransformChannel::Translate,
        TransformChannel::Scale,
        TransformChannel::Shear,
    ];

    /// The timeline's name in the animation JSON.
    pub fn name(self) -> &'static str {
        match self {
            TransformChannel::Rotate => "rotate",
            TransformChannel::Translate => "translate",
            TransformChannel::Scale => "scale",
            TransformChannel::Shear => "shear",
        }
    }
}

/// One timeline of an animation: what it moves and which channel.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimelineId {
    Bone {
        bone: String,
        channel: TransformChannel,
    },
    Point {
        point: String,
        channel: TransformChannel,
    },
    /// A cage's posed polygon (one curve for all vertices, `cy` a 0..1 fraction).
    Cage {
        cage: String,
    },
    /// The keyed target of the animation's `index`-th skinning-IK drag.
    Ik {
        index: usize,
    },
    PartColor {
        part: String,
    },
    /// Stepped only.
    PartVisible {
        part: String,
    },
    /// Stepped only.
    DrawOrder,
}

impl TimelineId {
    /// How the timeline reads in messages and the dopesheet: `arm rotate`, `ik[0]`, ….
    pub fn label(&self) -> String {
        match self {
            TimelineId::Bone { bone, channel } => format!("{bone} {}", channel.name()),
            TimelineId::Point { point, channel } => format!("{point} {}", channel.name()),
            TimelineId::Cage { cage } => format!("{cage} cage"),
            TimelineId::Ik { index } => format!("ik[{index}]"),
            TimelineId::PartColor { part } => format!("{part} color"),
            TimelineId::PartVisible { part } => format!("{part} visible"),
            TimelineId::DrawOrder => "draw order".into(),
        }
    }

    /// Whether its keys carry a curve (the stepped-only timelines do not).
    pub fn has_curves(&self) -> bool {
        !matches!(self, TimelineId::PartVisible { .. } | TimelineId::DrawOrder)
    }

    /// The JSON path to its key array: object keys, and the IK drag's index.
    fn path(&self) -> Vec<PathStep<'_>> {
        use PathStep::{Field, Index};
        match self {
            TimelineId::Bone { bone, channel } => {
                vec![Field("bones"), Field(bone), Field(channel.name())]
            }
            TimelineId::Point { point, channel } => {
                vec![Field("points"), Field(point), Field(channel.name())]
            }
            TimelineId::Cage { cage } => vec![Field("cages"), Field(cage)],
            TimelineId::Ik { index } => vec![Field("ik"), Index(*index), Field("to")],
            TimelineId::PartColor { part } => vec![Field("parts"), Field(part), Field("color")],
            TimelineId::PartVisible { part } => {
                vec![Field("parts"), Field(part), Field("visible")]
            }
            TimelineId::DrawOrder => vec![Field("draw_order")],
        }
    }
}

#[derive(Clone, Copy)]
enum PathStep<'a> {
    Field(&'a str),
    Index(usize),
}

/// One key: its timeline and time (s).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct KeyRef {
    pub timeline: TimelineId,
    pub time_s: f64,
}

impl KeyRef {
    /// Whether this names the key at `time_s` of `timeline` (times within the tolerance).
    pub fn is(&self, timeline: &TimelineId, time_s: f64) -> bool {
        self.timeline == *timeline && (self.time_s - time_s).abs() <= KEY_TIME_TOLERANCE_S
    }
}

/// A copied key: its timeline, its time after the earliest copied key's (s), the key as
/// stored, and the time of the key that followed it (for its Bézier handles' proportions).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CopiedKey {
    pub timeline: TimelineId,
    pub offset_s: f64,
    pub key: Value,
    pub next_time_s: Option<f64>,
}

/// A key's outgoing segment, for drawing and editing its curve.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    pub start_s: f64,
    pub end_s: f64,
    /// The values at both ends, one number per curve channel; a cage's one channel runs
    /// from 0 to 1 (its Bézier `cy` are fractions of the way).
    pub start: Vec<f64>,
    pub end: Vec<f64>,
    pub curve: Curve,
}

impl Segment {
    /// Curve channels (4 Bézier numbers each).
    pub fn channels(&self) -> usize {
        self.start.len()
    }

    /// A Bézier that plays exactly as the linear segment: handles at the thirds.
    pub fn linear_bezier(&self) -> Vec<f64> {
        let dt = self.end_s - self.start_s;
        self.start
            .iter()
            .zip(&self.end)
            .flat_map(|(&v0, &v1)| {
                [
                    self.start_s + dt / 3.0,
                    v0 + (v1 - v0) / 3.0,
                    self.start_s + 2.0 * dt / 3.0,
                    v0 + 2.0 * (v1 - v0) / 3.0,
                ]
            })
            .collect()
    }

    /// Channel `channel`'s value at `time_s` (clamped to the segment).
    pub fn value_at(&self, channel: usize, time_s: f64) -> f64 {
        let (t0, t1) = (self.start_s, self.end_s);
        let (Some(&v0), Some(&v1)) = (self.start.get(channel), self.end.get(channel)) else {
            return 0.0;
        };
        let t = time_s.clamp(t0, t1);
        match &self.curve {
            Curve::Linear => v0 + (v1 - v0) * ((t - t0) / (t1 - t0)),
            Curve::Stepped => {
                if t >= t1 {
                    v1
                } else {
                    v0
                }
            }
            Curve::Bezier(numbers) => {
                let k = BEZIER_NUMBERS_PER_CHANNEL * channel;
                let handles = numbers
                    .get(k..k + BEZIER_NUMBERS_PER_CHANNEL)
                    .unwrap_or(&[]);
                super::curve::bezier_value(t0, v0, handles, t1, v1, t)
            }
        }
    }
}

/// Every timeline of `animation` with its key times, in a stable order: bones, points, cages,
/// IK drags, part colors and visibility, draw order (names alphabetical, channels as
/// [`TransformChannel::ALL`]).
pub fn timelines(animation: &Value) -> Vec<(TimelineId, Vec<f64>)> {
    let mut out = Vec::new();
    let mut push = |id: TimelineId| {
        if let Some(keys) = keys_of(animation, &id) {
            let times = keys.iter().filter_map(key_time).collect();
            out.push((id, times));
        }
    };
    let names = |section: &str| -> Vec<String> {
        animation
            .get(section)
            .and_then(Value::as_object)
            .map(|m| {
                let mut names: Vec<String> = m.keys().cloned().collect();
                names.sort();
                names
            })
            .unwrap_or_default()
    };
    for bone in names("bones") {
        for channel in TransformChannel::ALL {
            push(TimelineId::Bone {
                bone: bone.clone(),
                channel,
            });
        }
    }
    for point in names("points") {
        for channel in TransformChannel::ALL {
            push(TimelineId::Point {
                point: point.clone(),
                channel,
            });
        }
    }
    for cage in names("cages") {
        push(TimelineId::Cage { cage });
    }
    let drags = animation
        .get("ik")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    for index in 0..drags {
        push(TimelineId::Ik { index });
    }
    for part in names("parts") {
        push(TimelineId::PartColor { part: part.clone() });
        push(TimelineId::PartVisible { part });
    }
    push(TimelineId::DrawOrder);
    out
}

/// Moves `keys` by `delta_s` seconds (one step: all of them or none).
pub fn move_keys(
    name: &str,
    animation: &Value,
    keys: &[KeyRef],
    delta_s: f64,
) -> Result<Value, EditError> {
    if !delta_s.is_finite() {
        return Err(EditError::BadShift(delta_s));
    }
    let mut edited = animation.clone();
    for (timeline, times) in group(keys) {
        let mut entries = entries_of(&edited, &timeline)?;
        for time_s in times {
            let entry = find(&mut entries, &timeline, time_s)?;
            entry.time_s = checked_time(entry.time_s + delta_s)?;
        }
        write_timeline(&mut edited, &timeline, entries)?;
    }
    normalized(name, &edited)
}

/// Removes `keys` (one step).
pub fn delete_keys(name: &str, animation: &Value, keys: &[KeyRef]) -> Result<Value, EditError> {
    let mut edited = animation.clone();
    for (timeline, times) in group(keys) {
        let mut entries = entries_of(&edited, &timeline)?;
        for time_s in &times {
            find(&mut entries, &timeline, *time_s)?;
        }
        entries.retain(|e| {
            !times
                .iter()
                .any(|t| (e.time_s - t).abs() <= KEY_TIME_TOLERANCE_S)
        });
        write_timeline(&mut edited, &timeline, entries)?;
    }
    normalized(name, &edited)
}

/// Copies `keys` out of `animation`, with times relative to the earliest of them.
pub fn copy_keys(animation: &Value, keys: &[KeyRef]) -> Result<Vec<CopiedKey>, EditError> {
    let earliest = keys.iter().map(|k| k.time_s).fold(f64::INFINITY, f64::min);
    let mut out = Vec::new();
    for (timeline, times) in group(keys) {
        let mut entries = entries_of(animation, &timeline)?;
        for time_s in times {
            let entry = find(&mut entries, &timeline, time_s)?;
            out.push(CopiedKey {
                timeline: timeline.clone(),
                offset_s: entry.time_s - earliest,
                key: entry.key.clone(),
                next_time_s: entry.old_segment.map(|(_, end)| end),
            });
        }
    }
    Ok(out)
}

/// Writes `keys` at `at_s` plus their offsets, creating timelines as needed (an IK drag's
/// timeline must exist: its rest point is not part of a key). A key already at a pasted time
/// is replaced.
pub fn paste_keys(
    name: &str,
    animation: &Value,
    at_s: f64,
    keys: &[CopiedKey],
) -> Result<Value, EditError> {
    checked_time(at_s)?;
    let mut edited = animation.clone();
    if edited.is_null() {
        edited = Value::Object(Map::new());
    }
    let mut timelines: Vec<&TimelineId> = keys.iter().map(|k| &k.timeline).collect();
    timelines.sort();
    timelines.dedup();
    for timeline in timelines {
        if keys_of(&edited, timeline).is_none() {
            create_timeline(&mut edited, timeline)?;
        }
        let mut entries = entries_of(&edited, timeline)?;
        for copied in keys.iter().filter(|k| k.timeline == *timeline) {
            let time_s = checked_time(at_s + copied.offset_s)?;
            let label = timeline.label();
            let old_time = key_time(&copied.key).ok_or_else(|| malformed(&label, 0, "no time"))?;
            entries.retain(|e| (e.time_s - time_s).abs() > KEY_TIME_TOLERANCE_S);
            entries.push(Entry {
                time_s,
                key: copied.key.clone(),
                found_as: None,
                old_segment: copied.next_time_s.map(|end| (old_time, end)),
            });
        }
        write_timeline(&mut edited, timeline, entries)?;
    }
    normalized(name, &edited)
}

/// Sets the curve of `key`'s outgoing segment. A Bézier needs a next key (its handles must lie
/// in the segment) and `4 ×` channels numbers (see [`Segment::channels`]).
pub fn set_curve(
    name: &str,
    animation: &Value,
    key: &KeyRef,
    curve: &Curve,
) -> Result<Value, EditError> {
    let label = key.timeline.label();
    if !key.timeline.has_curves() {
        return Err(EditError::NoCurves(label));
    }
    let mut edited = animation.clone();
    let mut entries = entries_of(&edited, &key.timeline)?;
    let entry = find(&mut entries, &key.timeline, key.time_s)?;
    if matches!(curve, Curve::Bezier(_)) && entry.old_segment.is_none() {
        return Err(EditError::LastKey {
            timeline: label,
            time_s: key.time_s,
        });
    }
    let curve_json = serde_json::to_value(curve).map_err(|e| malformed(&label, 0, e))?;
    if let Some(object) = entry.key.as_object_mut() {
        object.insert("curve".into(), curve_json);
    }
    write_timeline(&mut edited, &key.timeline, entries)?;
    normalized(name, &edited)
}

/// `key`'s outgoing segment: both ends' times and values and its curve.
pub fn segment(animation: &Value, key: &KeyRef) -> Result<Segment, EditError> {
    let label = key.timeline.label();
    if !key.timeline.has_curves() {
        return Err(EditError::NoCurves(label));
    }
    let entries = entries_of(animation, &key.timeline)?;
    let index = entries
        .iter()
        .position(|e| (e.time_s - key.time_s).abs() <= KEY_TIME_TOLERANCE_S)
        .ok_or_else(|| unknown(&key.timeline, key.time_s))?;
    let Some(next) = entries.get(index + 1).cloned() else {
        return Err(EditError::LastKey {
            timeline: label,
            time_s: key.time_s,
        });
    };
    let entry = &entries[index];
    let cage = matches!(key.timeline, TimelineId::Cage { .. });
    let values = |stored: &Value, at: usize, fraction: f64| -> Result<Vec<f64>, EditError> {
        if cage {
            // One curve for the whole polygon, its `cy` a fraction of the way.
            return Ok(vec![fraction]);
        }
        let value = stored
            .get("value")
            .ok_or_else(|| malformed(&label, at, "no value"))?;
        channel_numbers(value).ok_or_else(|| malformed(&label, at, "not a keyed number"))
    };
    let curve = match entry.key.get("curve") {
        None => Curve::Linear,
        Some(c) => Curve::deserialize(c).map_err(|e| malformed(&label, index, e))?,
    };
    Ok(Segment {
        start_s: entry.time_s,
        end_s: next.time_s,
        start: values(&entry.key, index, 0.0)?,
        end: values(&next.key, index + 1, 1.0)?,
        curve,
    })
}

/// The numbers a key value interpolates by, one per curve channel: a number, a pair, a color;
/// a cage polygon is one channel from 0 to 1 (its curve is a fraction of the way).
fn channel_numbers(value: &Value) -> Option<Vec<f64>> {
    match value {
        Value::Number(n) => Some(vec![n.as_f64()?]),
        Value::String(_) => Some(Rgba::deserialize(value).ok()?.0.to_vec()),
        Value::Array(items) if items.iter().all(Value::is_number) => {
            items.iter().map(Value::as_f64).collect()
        }
        _ => None,
    }
}

/// A key of one timeline while it is edited: its (new) time, the stored key, the time it is
/// named by (none for a pasted key), and the segment it started before the edit (its own and
/// the next key's old times), if it had one.
#[derive(Clone)]
struct Entry {
    time_s: f64,
    key: Value,
    found_as: Option<f64>,
    old_segment: Option<(f64, f64)>,
}

fn malformed(timeline: &str, key: usize, reason: impl ToString) -> EditError {
    EditError::MalformedKey {
        timeline: timeline.to_string(),
        key,
        reason: reason.to_string(),
    }
}

fn unknown(timeline: &TimelineId, time_s: f64) -> EditError {
    EditError::UnknownKey {
        timeline: timeline.label(),
        time_s,
    }
}

fn checked_time(time_s: f64) -> Result<f64, EditError> {
    // A shift by whole frames can land a hair below zero.
    if time_s < 0.0 && time_s > -KEY_TIME_TOLERANCE_S {
        return Ok(0.0);
    }
    if time_s.is_finite() && time_s >= 0.0 {
        Ok(time_s)
    } else {
        Err(EditError::BadTime(time_s))
    }
}

fn key_time(key: &Value) -> Option<f64> {
    key.get("time").and_then(Value::as_f64)
}

/// `keys` by timeline, in the order timelines first appear.
fn group(keys: &[KeyRef]) -> Vec<(TimelineId, Vec<f64>)> {
    let mut out: Vec<(TimelineId, Vec<f64>)> = Vec::new();
    for k in keys {
        match out.iter_mut().find(|(t, _)| *t == k.timeline) {
            Some((_, times)) => {
                if !times
                    .iter()
                    .any(|t| (t - k.time_s).abs() <= KEY_TIME_TOLERANCE_S)
                {
                    times.push(k.time_s);
                }
            }
            None => out.push((k.timeline.clone(), vec![k.time_s])),
        }
    }
    out
}

fn find<'a>(
    entries: &'a mut [Entry],
    timeline: &TimelineId,
    time_s: f64,
) -> Result<&'a mut Entry, EditError> {
    // Match by the old time: a key moved earlier in the same edit must not be found again.
    entries
        .iter_mut()
        .find(|e| {
            e.found_as
                .is_some_and(|old| (old - time_s).abs() <= KEY_TIME_TOLERANCE_S)
        })
        .ok_or_else(|| unknown(timeline, time_s))
}

fn keys_of<'a>(animation: &'a Value, timeline: &TimelineId) -> Option<&'a Vec<Value>> {
    let mut at = animation;
    for step in timeline.path() {
        at = match step {
            PathStep::Field(f) => at.get(f)?,
            PathStep::Index(i) => at.get(i)?,
        };
    }
    at.as_array()
}

fn keys_of_mut<'a>(animation: &'a mut Value, timeline: &TimelineId) -> Option<&'a mut Vec<Value>> {
    let mut at = animation;
    for step in timeline.path() {
        at = match step {
            PathStep::Field(f) => at.get_mut(f)?,
            PathStep::Index(i) => at.get_mut(i)?,
        };
    }
    at.as_array_mut()
}

/// The keys of `timeline` as entries (sorted as stored); the timeline must exist.
fn entries_of(animation: &Value, timeline: &TimelineId) -> Result<Vec<Entry>, EditError> {
    let label = timeline.label();
    let keys =
        keys_of(animation, timeline).ok_or_else(|| EditError::UnknownTimeline(label.clone()))?;
    let times = keys
        .iter()
        .enumerate()
        .map(|(i, k)| key_time(k).ok_or_else(|| malformed(&label, i, "no time")))
        .collect::<Result<Vec<f64>, EditError>>()?;
    Ok(keys
        .iter()
        .zip(&times)
        .enumerate()
        .map(|(i, (key, &time_s))| Entry {
            time_s,
            key: key.clone(),
            found_as: Some(time_s),
            old_segment: times.get(i + 1).map(|&next| (time_s, next)),
        })
        .collect())
}

/// Sorts `entries`, refuses two at one time, fixes the Bézier handles' times to their new
/// segments, and writes them as `timeline`'s keys (removing it when empty).
fn write_timeline(
    animation: &mut Value,
    timeline: &TimelineId,
    mut entries: Vec<Entry>,
) -> Result<(), EditError> {
    entries.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    for pair in entries.windows(2) {
        if pair[1].time_s - pair[0].time_s <= KEY_TIME_TOLERANCE_S {
            return Err(EditError::Collision {
                timeline: timeline.label(),
                time_s: pair[1].time_s,
            });
        }
    }
    let times: Vec<f64> = entries.iter().map(|e| e.time_s).collect();
    let keys: Vec<Value> = entries
        .into_iter()
        .enumerate()
        .map(|(i, mut e)| {
            if let Some(object) = e.key.as_object_mut() {
                object.insert("time".into(), Value::from(e.time_s));
                if let (Some(Value::Array(numbers)), Some(&end)) =
                    (object.get_mut("curve"), times.get(i + 1))
                {
                    // An untouched segment keeps its handles exactly as given (a curve being
                    // set is checked, not bent into shape).
                    let untouched = e.old_segment == Some((e.time_s, end));
                    let old = e.old_segment.filter(|(a, b)| b > a);
                    for (j, n) in numbers.iter_mut().enumerate().filter(|_| !untouched) {
                        // Even positions in each group of four are the handles' times.
                        if j % 2 == 0 {
                            if let Some(cx) = n.as_f64() {
                                *n = Value::from(remap(cx, old, (e.time_s, end)));
                            }
                        }
                    }
                }
            }
            e.key
        })
        .collect();
    if keys.is_empty() {
        remove_timeline(animation, timeline);
        return Ok(());
    }
    if let Some(slot) = keys_of_mut(animation, timeline) {
        *slot = keys;
    }
    Ok(())
}

/// A handle time at fraction f of its old segment goes to fraction f of the new one; one
/// without an old segment (pasted after a last key) is clamped into the new one.
fn remap(cx: f64, old: Option<(f64, f64)>, new: (f64, f64)) -> f64 {
    let (t0, t1) = new;
    match old {
        Some((a, b)) => t0 + ((cx - a) / (b - a)).clamp(0.0, 1.0) * (t1 - t0),
        None => cx.clamp(t0, t1),
    }
}

fn create_timeline(animation: &mut Value, timeline: &TimelineId) -> Result<(), EditError> {
    let missing = || EditError::UnknownTimeline(timeline.label());
    let path = timeline.path();
    let mut at = animation;
    for (i, step) in path.iter().enumerate() {
        let last = i + 1 == path.len();
        at = match *step {
            PathStep::Field(f) => {
                let object = at.as_object_mut().ok_or_else(missing)?;
                object.entry(f).or_insert_with(|| {
                    if last {
                        Value::Array(Vec::new())
                    } else {
                        Value::Object(Map::new())
                    }
                })
            }
            PathStep::Index(index) => at.get_mut(index).ok_or_else(missing)?,
        };
    }
    Ok(())
}

/// Removes an emptied timeline, and the bone, point, part or IK drag entry it leaves empty.
fn remove_timeline(animation: &mut Value, timeline: &TimelineId) {
    let path = timeline.path();
    let Some((PathStep::Field(field), parents)) = path.split_last() else {
        return;
    };
    let mut at = &mut *animation;
    for step in parents {
        let next = match *step {
            PathStep::Field(f) => at.get_mut(f),
            PathStep::Index(i) => at.get_mut(i),
        };
        let Some(next) = next else { return };
        at = next;
    }
    if let Some(object) = at.as_object_mut() {
        object.remove(*field);
    }
    match timeline {
        TimelineId::Ik { index } => {
            if let Some(drags) = animation.get_mut("ik").and_then(Value::as_array_mut) {
                if *index < drags.len() {
                    drags.remove(*index);
                }
            }
        }
        TimelineId::Bone { bone: name, .. }
        | TimelineId::Point { point: name, .. }
        | TimelineId::PartColor { part: name }
        | TimelineId::PartVisible { part: name } => {
            if let Some(PathStep::Field(section)) = parents.first() {
                if let Some(owners) = animation.get_mut(*section).and_then(Value::as_object_mut) {
                    if owners
                        .get(name.as_str())
                        .and_then(Value::as_object)
                        .is_some_and(Map::is_empty)
                    {
                        owners.remove(name.as_str());
                    }
                }
            }
        }
        TimelineId::Cage { .. } | TimelineId::DrawOrder => {}
    }
}

/// Checks the edited animation and writes it in normal form.
fn normalized(name: &str, animation: &Value) -> Result<Value, EditError> {
    if !animation.is_object() {
        return Err(EditError::NotAnObject(name.to_string()));
    }
    let checked = Animation::from_json(name, animation)?;
    serde_json::to_value(&checked).map_err(|e| {
        EditError::Animation(AnimError::Malformed {
            animation: name.to_string(),
            reason: e.to_string(),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn rotate(bone: &str) -> TimelineId {
        TimelineId::Bone {
            bone: bone.into(),
            channel: TransformChannel::Rotate,
        }
    }

    fn key(timeline: &TimelineId, time_s: f64) -> KeyRef {
        KeyRef {
            timeline: timeline.clone(),
            time_s,
        }
    }

    /// `arm` rotates 0 → 90 → 0 over keys at 0, 1, 2; its translate has one key; one IK drag.
    fn walk() -> Value {
        json!({
            "bones": {"arm": {
                "rotate": [{"time": 0, "value": 0}, {"time": 1, "value": 90},
                           {"time": 2, "value": 0}],
                "translate": [{"time": 1, "value": [3, 4]}]}},
            "ik": [{"at": [1, 2], "to": [{"time": 0, "value": [5, 6]}]}],
            "parts": {"head": {"visible": [{"time": 0, "value": true}]}}
        })
    }

    fn times(animation: &Value, timeline: &TimelineId) -> Vec<f64> {
        timelines(animation)
            .into_iter()
            .find(|(t, _)| t == timeline)
            .map(|(_, times)| times)
            .unwrap_or_default()
    }

    fn rotate_values(animation: &Value) -> Vec<f64> {
        animation["bones"]["arm"]["rotate"]
            .as_array()
            .unwrap()
            .iter()
            .map(|k| k["value"].as_f64().unwrap())
            .collect()
    }

    #[test]
    fn lists_every_timeline_with_its_times() {
        let listed = timelines(&walk());
        let ids: Vec<String> = listed.iter().map(|(t, _)| t.label()).collect();
        assert_eq!(
            ids,
            ["arm rotate", "arm translate", "ik[0]", "head visible"]
        );
        assert_eq!(listed[0].1, vec![0.0, 1.0, 2.0]);
        assert!(!TimelineId::PartVisible {
            part: "head".into()
        }
        .has_curves());
    }

    #[test]
    fn moving_keys_keeps_values_and_reorders() {
        let arm = rotate("arm");
        let moved = move_keys("walk", &walk(), &[key(&arm, 0.0)], 1.5).unwrap();
        assert_eq!(times(&moved, &arm), vec![1.0, 1.5, 2.0]);
        assert_eq!(rotate_values(&moved), vec![90.0, 0.0, 0.0]);
        // A block moves past the places its own keys leave.
        let block = [key(&arm, 1.0), key(&arm, 2.0)];
        let moved = move_keys("walk", &walk(), &block, 1.0).unwrap();
        assert_eq!(times(&moved, &arm), vec![0.0, 2.0, 3.0]);
        assert_eq!(rotate_values(&moved), vec![0.0, 90.0, 0.0]);
        // Other timelines of the same handle stay.
        let translate = TimelineId::Bone {
            bone: "arm".into(),
            channel: TransformChannel::Translate,
        };
        assert_eq!(times(&moved, &translate), vec![1.0]);
    }

    #[test]
    fn moves_that_collide_or_leave_time_are_refused() {
        let arm = rotate("arm");
        let walk = walk();
        assert_eq!(
            move_keys("walk", &walk, &[key(&arm, 0.0)], 1.0),
            Err(EditError::Collision {
                timeline: "arm rotate".into(),
                time_s: 1.0
            })
        );
        assert_eq!(
            move_keys("walk", &walk, &[key(&arm, 1.0)], -1.5),
            Err(EditError::BadTime(-0.5))
        );
        assert!(matches!(
            move_keys("walk", &walk, &[key(&arm, 1.0)], f64::NAN),
            Err(EditError::BadShift(_))
        ));
        assert!(matches!(
            move_keys("walk", &walk, &[key(&arm, 0.5)], 0.1),
            Err(EditError::UnknownKey { .. })
        ));
        assert!(matches!(
            move_keys("walk", &walk, &[key(&rotate("leg"), 0.0)], 0.1),
            Err(EditError::UnknownTimeline(_))
        ));
        // A collision on one timeline refuses the whole move.
        let both = [key(&TimelineId::Ik { index: 0 }, 0.0), key(&arm, 0.0)];
        assert!(move_keys("walk", &walk, &both, 1.0).is_err());
    }

    /// `walk` with a Bézier segment from the arm's key at 0 to its key at 1.
    fn curved_walk() -> Value {
        set_curve(
            "walk",
            &walk(),
            &key(&rotate("arm"), 0.0),
            &Curve::Bezier(vec![0.25, 10.0, 0.75, 80.0]),
        )
        .unwrap()
    }

    #[test]
    fn bezier_handles_keep_their_fraction_of_the_segment() {
        let arm = rotate("arm");
        let curved = curved_walk();
        // Stretching the segment to 0 → 2 doubles the handle times; values stay.
        let stretched = move_keys("walk", &curved, &[key(&arm, 1.0), key(&arm, 2.0)], 1.0).unwrap();
        assert_eq!(
            stretched["bones"]["arm"]["rotate"][0]["curve"],
            json!([0.5, 10.0, 1.5, 80.0])
        );
        // Deleting the key that ended the segment stretches it to the next one.
        let deleted = delete_keys("walk", &curved, &[key(&arm, 1.0)]).unwrap();
        assert_eq!(
            deleted["bones"]["arm"]["rotate"][0]["curve"],
            json!([0.5, 10.0, 1.5, 80.0])
        );
        // Moving the curved key itself shifts and squeezes its handles with it.
        let shifted = move_keys("walk", &curved, &[key(&arm, 0.0)], 0.5).unwrap();
        assert_eq!(
            shifted["bones"]["arm"]["rotate"][0]["curve"],
            json!([0.625, 10.0, 0.875, 80.0])
        );
    }

    #[test]
    fn deleting_the_last_keys_removes_the_timeline_and_its_owner() {
        let arm = rotate("arm");
        let translate = TimelineId::Bone {
            bone: "arm".into(),
            channel: TransformChannel::Translate,
        };
        let all: Vec<KeyRef> = [0.0, 1.0, 2.0].iter().map(|&t| key(&arm, t)).collect();
        let gone = delete_keys("walk", &walk(), &all).unwrap();
        assert!(gone["bones"]["arm"].get("rotate").is_none());
        assert_eq!(times(&gone, &translate), vec![1.0]);
        let mut rest = all.clone();
        rest.push(key(&translate, 1.0));
        rest.push(key(&TimelineId::Ik { index: 0 }, 0.0));
        let gone = delete_keys("walk", &walk(), &rest).unwrap();
        assert!(gone.get("bones").is_none(), "{gone}");
        assert!(gone.get("ik").is_none(), "{gone}");
        assert!(matches!(
            delete_keys("walk", &walk(), &[key(&arm, 3.0)]),
            Err(EditError::UnknownKey { .. })
        ));
    }

    #[test]
    fn copy_and_paste_at_a_time() {
        let arm = rotate("arm");
        let ik = TimelineId::Ik { index: 0 };
        let walk = walk();
        let copied = copy_keys(&walk, &[key(&arm, 1.0), key(&arm, 2.0), key(&ik, 0.0)]).unwrap();
        assert_eq!(copied.len(), 3);
        assert_eq!(copied[0].offset_s, 1.0);
        assert_eq!(copied[2].offset_s, 0.0);
        let pasted = paste_keys("walk", &walk, 2.0, &copied).unwrap();
        // Offsets count from the earliest copied key (the IK drag's at 0): 90 at 3, 0 at 4.
        assert_eq!(times(&pasted, &arm), vec![0.0, 1.0, 2.0, 3.0, 4.0]);
        assert_eq!(rotate_values(&pasted), vec![0.0, 90.0, 0.0, 90.0, 0.0]);
        assert_eq!(times(&pasted, &ik), vec![0.0, 2.0]);
        // Pasting over existing keys replaces them.
        let over = paste_keys("walk", &walk, 1.0, &copied[..1]).unwrap();
        assert_eq!(times(&over, &arm), vec![0.0, 1.0, 2.0]);
        assert_eq!(rotate_values(&over), vec![0.0, 90.0, 90.0]);
        // Into an animation without that timeline: created; an IK drag must exist.
        let empty = json!({});
        let created = paste_keys("other", &empty, 0.5, &copied[..2]).unwrap();
        assert_eq!(times(&created, &arm), vec![1.5, 2.5]);
        assert_eq!(
            paste_keys("other", &empty, 0.0, &copied[2..]),
            Err(EditError::UnknownTimeline("ik[0]".into()))
        );
        assert!(matches!(
            paste_keys("walk", &walk, -1.0, &copied),
            Err(EditError::BadTime(_))
        ));
    }

    #[test]
    fn pasted_bezier_handles_fit_their_new_segment() {
        let arm = rotate("arm");
        let curved = curved_walk();
        let copied = copy_keys(&curved, &[key(&arm, 0.0)]).unwrap();
        let pasted = paste_keys("walk", &curved, 1.5, &copied).unwrap();
        // The segment 1.5 → 2 is half as long as the copied 0 → 1.
        assert_eq!(
            pasted["bones"]["arm"]["rotate"][2]["curve"],
            json!([1.625, 10.0, 1.875, 80.0])
        );
        Animation::from_json("walk", &pasted).unwrap();
    }

    #[test]
    fn curves_are_set_and_checked() {
        let arm = rotate("arm");
        let walk = walk();
        let stepped = set_curve("walk", &walk, &key(&arm, 1.0), &Curve::Stepped).unwrap();
        assert_eq!(stepped["bones"]["arm"]["rotate"][1]["curve"], "stepped");
        let back = set_curve("walk", &stepped, &key(&arm, 1.0), &Curve::Linear).unwrap();
        assert_eq!(
            back,
            Animation::from_json("walk", &walk)
                .map(|a| serde_json::to_value(a).unwrap())
                .unwrap()
        );
        assert!(matches!(
            set_curve(
                "walk",
                &walk,
                &key(&arm, 2.0),
                &Curve::Bezier(vec![2.0, 0.0, 2.0, 0.0])
            ),
            Err(EditError::LastKey { .. })
        ));
        assert!(matches!(
            set_curve(
                "walk",
                &walk,
                &key(
                    &TimelineId::PartVisible {
                        part: "head".into()
                    },
                    0.0
                ),
                &Curve::Stepped
            ),
            Err(EditError::NoCurves(_))
        ));
        // The timeline check refuses a wrong length and a handle outside the segment.
        let ik = TimelineId::Ik { index: 0 };
        let longer = paste_keys(
            "walk",
            &walk,
            1.0,
            &copy_keys(&walk, &[key(&ik, 0.0)]).unwrap(),
        )
        .unwrap();
        assert!(matches!(
            set_curve(
                "walk",
                &longer,
                &key(&ik, 0.0),
                &Curve::Bezier(vec![0.3, 1.0, 0.6, 2.0])
            ),
            Err(EditError::Animation(AnimError::Timeline {
                problem: crate::anim::TimelineError::CurveLength { .. },
                ..
            }))
        ));
        assert!(matches!(
            set_curve(
                "walk",
                &walk,
                &key(&arm, 0.0),
                &Curve::Bezier(vec![1.5, 1.0, 0.6, 2.0])
            ),
            Err(EditError::Animation(AnimError::Timeline {
                problem: crate::anim::TimelineError::CurveTime { .. },
                ..
            }))
        ));
    }

    #[test]
    fn a_segment_and_its_linear_bezier_play_alike() {
        let ik = TimelineId::Ik { index: 0 };
        let walk = walk();
        let two = paste_keys(
            "walk",
            &walk,
            0.8,
            &[CopiedKey {
                timeline: ik.clone(),
                offset_s: 0.0,
                key: json!({"time": 0, "value": [9, -2]}),
                next_time_s: None,
            }],
        )
        .unwrap();
        let segment = segment(&two, &key(&ik, 0.0)).unwrap();
        assert_eq!((segment.start_s, segment.end_s), (0.0, 0.8));
        assert_eq!(segment.start, vec![5.0, 6.0]);
        assert_eq!(segment.end, vec![9.0, -2.0]);
        assert_eq!(segment.channels(), 2);
        let bezier = Segment {
            curve: Curve::Bezier(segment.linear_bezier()),
            ..segment.clone()
        };
        for i in 0..=10 {
            let t = 0.08 * i as f64;
            for c in 0..2 {
                let (a, b) = (segment.value_at(c, t), bezier.value_at(c, t));
                assert!((a - b).abs() < 1e-9, "{t} {c}: {a} {b}");
            }
        }
        // And the document's sampling agrees once the curve is stored.
        let stored = set_curve("walk", &two, &key(&ik, 0.0), &bezier.curve).unwrap();
        let anim = Animation::from_json("walk", &stored).unwrap();
        let pose = anim.sample(0.2, false);
        assert!((pose.ik[0].to[0] - 6.0).abs() < 1e-9, "{:?}", pose.ik);
        let rotate_last = segment_error(&walk);
        assert!(matches!(rotate_last, Err(EditError::LastKey { .. })));
    }

    fn segment_error(walk: &Value) -> Result<Segment, EditError> {
        segment(walk, &key(&rotate("arm"), 2.0))
    }
}
