//! Editing an animation's keys timeline by timeline: list, move in time, copy and paste,
//! delete, and set the curve of a key's outgoing segment.
//!
//! In: one [`Animation`] (an entry of the rig document's `animations` map, see
//! [`super::timeline`]) and keys named by [`KeyRef`] — a timeline ([`TimelineId`]: a handle or
//! part and one of its channels) and a time. Out: the edited animation, checked as
//! [`Animation::validate`] checks any animation, or an [`EditError`] and no change.
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
//! - a timeline left without keys is removed (an IK drag with it, so later drags move up
//!   once the edit is done).
//!
//! Copied keys ([`CopiedKey`]) carry the key as its JSON, as the animations file stores it: they
//! travel through the system clipboard, and a paste parses them for the timeline they name.

mod keys;

use super::curve::{split_curve, Curve, BEZIER_NUMBERS_PER_CHANNEL};
use super::timeline::Channels;
use super::{AnimError, Animation, Key};
use keys::{entries_of, find, find_all, write_keys, EditKey, Entry, TimelineEdit};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// Keys closer in time than this (s) are the same key.
pub const KEY_TIME_TOLERANCE_S: f64 = 1e-6;

/// What an edit got wrong; the animation is unchanged.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EditError {
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
    /// A copied key that does not parse as a key of the timeline it names (`key`: its place
    /// among the copied keys).
    #[error("{timeline}: copied key {key} is malformed ({reason})")]
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
    /// Which attachment slot `slot` shows (`parts.SLOT.attachment`). Stepped only.
    Attachment {
        slot: String,
    },
    /// The deform keys of part `part` (one of a slot's attachments): one curve for all its
    /// vertex offsets, `cy` a 0..1 fraction, as a cage's.
    Deform {
        part: String,
    },
    /// The animation's events. No curves; several keys may share a time, and a key time names
    /// every event at that time (moved, copied and deleted together).
    Events,
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
            TimelineId::Attachment { slot } => format!("{slot} attachment"),
            TimelineId::Deform { part } => format!("{part} deform"),
            TimelineId::Events => "events".into(),
        }
    }

    /// Whether its keys carry a curve (the stepped-only timelines do not).
    pub fn has_curves(&self) -> bool {
        !matches!(
            self,
            TimelineId::PartVisible { .. }
                | TimelineId::DrawOrder
                | TimelineId::Attachment { .. }
                | TimelineId::Events
        )
    }
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

/// A copied key: its timeline, its time after the earliest copied key's (s), the key as the
/// animations file stores it, and the time of the key that followed it (for its Bézier handles'
/// proportions).
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
        self.bezier_at_thirds(|v0, v1| (v0 + (v1 - v0) / 3.0, v0 + 2.0 * (v1 - v0) / 3.0))
    }

    /// A Bézier that eases out of the start and into the end: each channel's handles at the
    /// thirds of the time, level with their key (zero slope at both keys).
    pub fn ease_bezier(&self) -> Vec<f64> {
        self.bezier_at_thirds(|v0, v1| (v0, v1))
    }

    /// Bézier numbers with both handles at the thirds of the segment's time and values
    /// `handle_values(start, end)` per channel.
    fn bezier_at_thirds(&self, handle_values: impl Fn(f64, f64) -> (f64, f64)) -> Vec<f64> {
        let dt = self.end_s - self.start_s;
        self.start
            .iter()
            .zip(&self.end)
            .flat_map(|(&v0, &v1)| {
                let (c1, c2) = handle_values(v0, v1);
                [
                    self.start_s + dt / 3.0,
                    c1,
                    self.start_s + 2.0 * dt / 3.0,
                    c2,
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

/// The key of each of `timelines` (as [`timelines`] lists them) at `time_s`, within
/// [`KEY_TIME_TOLERANCE_S`].
pub fn keys_at(timelines: &[(TimelineId, Vec<f64>)], time_s: f64) -> Vec<KeyRef> {
    timelines
        .iter()
        .filter_map(|(timeline, times)| {
            let &at = times
                .iter()
                .find(|&&t| (t - time_s).abs() <= KEY_TIME_TOLERANCE_S)?;
            Some(KeyRef {
                timeline: timeline.clone(),
                time_s: at,
            })
        })
        .collect()
}

/// Every timeline of `animation` with its key times, in a stable order: bones, points, cages,
/// deform keys, IK drags, part colors, visibility and attachments, draw order, events (names
/// alphabetical, channels as [`TransformChannel::ALL`]; the events' times once each).
pub fn timelines(animation: &Animation) -> Vec<(TimelineId, Vec<f64>)> {
    let mut out = Vec::new();
    for (bone, t) in &animation.bones {
        for (channel, times) in transform_times(&t.rotate, [&t.translate, &t.scale, &t.shear]) {
            let bone = bone.clone();
            out.push((TimelineId::Bone { bone, channel }, times));
        }
    }
    for (point, t) in &animation.points {
        for (channel, times) in transform_times(&t.rotate, [&t.translate, &t.scale, &t.shear]) {
            let point = point.clone();
            out.push((TimelineId::Point { point, channel }, times));
        }
    }
    for (cage, keys) in &animation.cages {
        out.push((TimelineId::Cage { cage: cage.clone() }, times(keys)));
    }
    for (part, keys) in &animation.deform {
        out.push((TimelineId::Deform { part: part.clone() }, times(keys)));
    }
    for (index, drag) in animation.ik.iter().enumerate() {
        out.push((TimelineId::Ik { index }, times(&drag.to)));
    }
    for (part, t) in &animation.parts {
        if let Some(keys) = &t.color {
            out.push((TimelineId::PartColor { part: part.clone() }, times(keys)));
        }
        if let Some(keys) = &t.visible {
            out.push((TimelineId::PartVisible { part: part.clone() }, times(keys)));
        }
        if let Some(keys) = &t.attachment {
            out.push((TimelineId::Attachment { slot: part.clone() }, times(keys)));
        }
    }
    if let Some(keys) = &animation.draw_order {
        out.push((TimelineId::DrawOrder, times(keys)));
    }
    if !animation.events.is_empty() {
        let mut at = times(&animation.events);
        at.dedup_by(|a, b| (*a - *b).abs() <= KEY_TIME_TOLERANCE_S);
        out.push((TimelineId::Events, at));
    }
    out
}

fn times<K: EditKey>(keys: &[K]) -> Vec<f64> {
    keys.iter().map(EditKey::time).collect()
}

/// The key times of a bone's or point's transform timelines that exist, by channel in
/// [`TransformChannel::ALL`]'s order.
fn transform_times(
    rotate: &Option<Vec<Key<f64>>>,
    [translate, scale, shear]: [&Option<Vec<Key<[f64; 2]>>>; 3],
) -> Vec<(TransformChannel, Vec<f64>)> {
    let channels = [
        rotate.as_deref().map(times),
        translate.as_deref().map(times),
        scale.as_deref().map(times),
        shear.as_deref().map(times),
    ];
    TransformChannel::ALL
        .into_iter()
        .zip(channels)
        .filter_map(|(channel, times)| Some((channel, times?)))
        .collect()
}

/// Moves `keys` by `delta_s` seconds (one step: all of them or none).
pub fn move_keys(
    name: &str,
    animation: &Animation,
    keys: &[KeyRef],
    delta_s: f64,
) -> Result<Animation, EditError> {
    struct Move {
        times: Vec<f64>,
        delta_s: f64,
    }
    impl TimelineEdit for Move {
        fn edit<K: EditKey>(
            &mut self,
            timeline: &TimelineId,
            keys: &mut Vec<K>,
        ) -> Result<(), EditError> {
            let mut entries = entries_of(keys);
            for &time_s in &self.times {
                for entry in find_all(&mut entries, timeline, time_s)? {
                    entry.time_s = checked_time(entry.time_s + self.delta_s)?;
                }
            }
            *keys = write_keys(timeline, entries)?;
            Ok(())
        }
    }
    if !delta_s.is_finite() {
        return Err(EditError::BadShift(delta_s));
    }
    edit_each(name, animation, keys, |times| Move { times, delta_s })
}

/// Removes `keys` (one step).
pub fn delete_keys(
    name: &str,
    animation: &Animation,
    keys: &[KeyRef],
) -> Result<Animation, EditError> {
    struct Delete {
        times: Vec<f64>,
    }
    impl TimelineEdit for Delete {
        fn edit<K: EditKey>(
            &mut self,
            timeline: &TimelineId,
            keys: &mut Vec<K>,
        ) -> Result<(), EditError> {
            let mut entries = entries_of(keys);
            for &time_s in &self.times {
                find(&mut entries, timeline, time_s)?;
            }
            entries.retain(|e| {
                !self
                    .times
                    .iter()
                    .any(|t| (e.time_s - t).abs() <= KEY_TIME_TOLERANCE_S)
            });
            *keys = write_keys(timeline, entries)?;
            Ok(())
        }
    }
    edit_each(name, animation, keys, |times| Delete { times })
}

/// Copies `keys` out of `animation`, with times relative to the earliest of them.
pub fn copy_keys(animation: &Animation, keys: &[KeyRef]) -> Result<Vec<CopiedKey>, EditError> {
    struct Copy {
        times: Vec<f64>,
        earliest: f64,
        out: Vec<CopiedKey>,
    }
    impl TimelineEdit for Copy {
        fn edit<K: EditKey>(
            &mut self,
            timeline: &TimelineId,
            keys: &mut Vec<K>,
        ) -> Result<(), EditError> {
            let mut entries = entries_of(keys);
            for (i, &time_s) in self.times.iter().enumerate() {
                for entry in find_all(&mut entries, timeline, time_s)? {
                    let key = serde_json::to_value(&entry.key)
                        .map_err(|e| malformed(&timeline.label(), i, e))?;
                    self.out.push(CopiedKey {
                        timeline: timeline.clone(),
                        offset_s: entry.time_s - self.earliest,
                        key,
                        next_time_s: entry.old_segment.map(|(_, end)| end),
                    });
                }
            }
            Ok(())
        }
    }
    let earliest = keys.iter().map(|k| k.time_s).fold(f64::INFINITY, f64::min);
    // Reading through the editing path: it works on a copy that is dropped.
    let mut scratch = animation.clone();
    let mut copy = Copy {
        times: Vec::new(),
        earliest,
        out: Vec::new(),
    };
    for (timeline, times) in group(keys) {
        copy.times = times;
        keys::edit_timeline(&mut scratch, &timeline, false, &mut copy)?;
    }
    Ok(copy.out)
}

/// Keys `value` at `time_s` in one timeline's sorted `keys` (as keying a pose does): a key
/// already at that time (within [`KEY_TIME_TOLERANCE_S`]) takes the value; a new key between
/// two others splits their segment ([`super::curve::split_curve`]: de Casteljau for a Bézier),
/// so the motion around it is what it was. Where `value` differs from the motion's value at
/// `time_s`, the Bézier handles on either side of the new key move with it by the difference
/// (a per-channel curve), so the curve keeps its tangents there. A key before the first or
/// after the last one is linear.
pub fn put_key<V: Channels>(keys: &mut Vec<Key<V>>, time_s: f64, value: V) {
    let at = keys
        .iter()
        .position(|k| k.time > time_s - KEY_TIME_TOLERANCE_S);
    let Some(i) = at else {
        keys.push(Key {
            time: time_s,
            value,
            curve: Curve::Linear,
        });
        return;
    };
    if (keys[i].time - time_s).abs() <= KEY_TIME_TOLERANCE_S {
        keys[i].value = value;
        return;
    }
    let mut curve = Curve::Linear;
    if i > 0 {
        let (previous, next) = (&keys[i - 1], &keys[i]);
        let split = split_curve(
            &previous.curve,
            (previous.time, previous.value.numbers()),
            (next.time, next.value.numbers()),
            time_s,
            V::CURVE_PER_CHANNEL,
        );
        let (mut before, mut after) = (split.before, split.after);
        if V::CURVE_PER_CHANNEL {
            // The handles beside the new key follow its value (cy2 before it, cy1 after it).
            let moved = value.numbers().iter().zip(&split.value).map(|(v, s)| v - s);
            for (c, delta) in moved.enumerate() {
                let base = c * BEZIER_NUMBERS_PER_CHANNEL;
                if let Curve::Bezier(n) = &mut before {
                    if let Some(cy2) = n.get_mut(base + 3) {
                        *cy2 += delta;
                    }
                }
                if let Curve::Bezier(n) = &mut after {
                    if let Some(cy1) = n.get_mut(base + 1) {
                        *cy1 += delta;
                    }
                }
            }
        }
        keys[i - 1].curve = before;
        curve = after;
    }
    keys.insert(
        i,
        Key {
            time: time_s,
            value,
            curve,
        },
    );
}

/// Writes `keys` at `at_s` plus their offsets, creating timelines as needed (an IK drag's
/// timeline must exist: its rest point is not part of a key). A key already at a pasted time
/// is replaced.
pub fn paste_keys(
    name: &str,
    animation: &Animation,
    at_s: f64,
    keys: &[CopiedKey],
) -> Result<Animation, EditError> {
    struct Paste<'a> {
        at_s: f64,
        keys: &'a [CopiedKey],
    }
    impl TimelineEdit for Paste<'_> {
        fn edit<K: EditKey>(
            &mut self,
            timeline: &TimelineId,
            keys: &mut Vec<K>,
        ) -> Result<(), EditError> {
            let mut entries = entries_of(keys);
            let pasted = self.keys.iter().enumerate();
            for (i, copied) in pasted.filter(|(_, k)| k.timeline == *timeline) {
                let time_s = checked_time(self.at_s + copied.offset_s)?;
                let key =
                    K::deserialize(&copied.key).map_err(|e| malformed(&timeline.label(), i, e))?;
                let old_time = key.time();
                // A key already there is replaced; keys pasted together stay together.
                entries.retain(|e| {
                    e.found_as.is_none() || (e.time_s - time_s).abs() > KEY_TIME_TOLERANCE_S
                });
                entries.push(Entry {
                    time_s,
                    key,
                    found_as: None,
                    old_segment: copied.next_time_s.map(|end| (old_time, end)),
                });
            }
            *keys = write_keys(timeline, entries)?;
            Ok(())
        }
    }
    checked_time(at_s)?;
    let mut timelines: Vec<&TimelineId> = keys.iter().map(|k| &k.timeline).collect();
    timelines.sort();
    timelines.dedup();
    let mut edited = animation.clone();
    let mut paste = Paste { at_s, keys };
    for timeline in &timelines {
        keys::edit_timeline(&mut edited, timeline, true, &mut paste)?;
    }
    finish(name, edited, &timelines)
}

/// Sets the curve of `key`'s outgoing segment. A Bézier needs a next key (its handles must lie
/// in the segment) and `4 ×` channels numbers (see [`Segment::channels`]).
pub fn set_curve(
    name: &str,
    animation: &Animation,
    key: &KeyRef,
    curve: &Curve,
) -> Result<Animation, EditError> {
    struct SetCurve<'a> {
        time_s: f64,
        curve: &'a Curve,
    }
    impl TimelineEdit for SetCurve<'_> {
        fn edit<K: EditKey>(
            &mut self,
            timeline: &TimelineId,
            keys: &mut Vec<K>,
        ) -> Result<(), EditError> {
            let mut entries = entries_of(keys);
            let entry = find(&mut entries, timeline, self.time_s)?;
            if matches!(self.curve, Curve::Bezier(_)) && entry.old_segment.is_none() {
                return Err(EditError::LastKey {
                    timeline: timeline.label(),
                    time_s: self.time_s,
                });
            }
            let curve = entry
                .key
                .curve_mut()
                .ok_or_else(|| EditError::NoCurves(timeline.label()))?;
            *curve = self.curve.clone();
            *keys = write_keys(timeline, entries)?;
            Ok(())
        }
    }
    if !key.timeline.has_curves() {
        return Err(EditError::NoCurves(key.timeline.label()));
    }
    let mut edited = animation.clone();
    let mut set = SetCurve {
        time_s: key.time_s,
        curve,
    };
    keys::edit_timeline(&mut edited, &key.timeline, false, &mut set)?;
    finish(name, edited, &[&key.timeline])
}

/// `key`'s outgoing segment: both ends' times and values and its curve.
pub fn segment(animation: &Animation, key: &KeyRef) -> Result<Segment, EditError> {
    struct Read {
        time_s: f64,
        out: Option<Segment>,
    }
    impl TimelineEdit for Read {
        fn edit<K: EditKey>(
            &mut self,
            timeline: &TimelineId,
            keys: &mut Vec<K>,
        ) -> Result<(), EditError> {
            let index = keys
                .iter()
                .position(|k| (k.time() - self.time_s).abs() <= KEY_TIME_TOLERANCE_S)
                .ok_or_else(|| unknown(timeline, self.time_s))?;
            let (Some(entry), Some(next)) = (keys.get(index), keys.get(index + 1)) else {
                return Err(EditError::LastKey {
                    timeline: timeline.label(),
                    time_s: self.time_s,
                });
            };
            self.out = Some(Segment {
                start_s: entry.time(),
                end_s: next.time(),
                start: entry.curve_values(0.0),
                end: next.curve_values(1.0),
                curve: entry.curve().cloned().unwrap_or_default(),
            });
            Ok(())
        }
    }
    if !key.timeline.has_curves() {
        return Err(EditError::NoCurves(key.timeline.label()));
    }
    let mut scratch = animation.clone();
    let mut read = Read {
        time_s: key.time_s,
        out: None,
    };
    keys::edit_timeline(&mut scratch, &key.timeline, false, &mut read)?;
    read.out.ok_or_else(|| unknown(&key.timeline, key.time_s))
}

/// Runs the edit `make(times)` on each timeline `keys` name, on a copy of `animation`.
fn edit_each<E: TimelineEdit>(
    name: &str,
    animation: &Animation,
    keys: &[KeyRef],
    make: impl Fn(Vec<f64>) -> E,
) -> Result<Animation, EditError> {
    let mut edited = animation.clone();
    let groups = group(keys);
    for (timeline, times) in &groups {
        keys::edit_timeline(&mut edited, timeline, false, &mut make(times.clone()))?;
    }
    let timelines: Vec<&TimelineId> = groups.iter().map(|(t, _)| t).collect();
    finish(name, edited, &timelines)
}

/// Drops the IK drags among `timelines` the edit left without keys, and checks the result.
fn finish(
    name: &str,
    mut animation: Animation,
    timelines: &[&TimelineId],
) -> Result<Animation, EditError> {
    let mut index = 0;
    animation.ik.retain(|drag| {
        let edited = timelines.contains(&&TimelineId::Ik { index });
        index += 1;
        !(edited && drag.to.is_empty())
    });
    animation.validate(name)?;
    Ok(animation)
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

#[cfg(test)]
#[path = "edit/tests.rs"]
mod tests;
