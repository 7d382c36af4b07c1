//! The typed timelines under [`super`]'s edits: every kind of key seen as a time and, for the
//! curved kinds, a curve ([`EditKey`]); one timeline's keys as [`Entry`]s while they are edited,
//! written back sorted with their Bézier handles fitted to their new segments; and the one
//! dispatch from a [`TimelineId`] to the key list it names ([`edit_timeline`]).

use super::{unknown, EditError, TimelineId, TransformChannel, KEY_TIME_TOLERANCE_S};
use crate::anim::curve::Curve;
use crate::anim::timeline::{Channels, Key, StepKey};
use crate::anim::{Animation, EventKey};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::collections::BTreeMap;

/// A stored key of any timeline, as the edits see it.
pub(super) trait EditKey: Clone + Serialize + DeserializeOwned {
    /// Whether several keys of one timeline may share a time (events); a time then names all
    /// of them.
    const SHARES_TIMES: bool = false;
    fn time(&self) -> f64;
    fn set_time(&mut self, time_s: f64);
    /// How it travels to the next key; `None` (the default) for the stepped-only kinds.
    fn curve(&self) -> Option<&Curve> {
        None
    }
    fn curve_mut(&mut self) -> Option<&mut Curve> {
        None
    }
    /// The numbers its curve interpolates, one per curve channel; a kind with one curve for all
    /// its numbers (a cage polygon) has one channel, `fraction` of the way (0 at a segment's
    /// start, 1 at its end: its Bézier `cy` are fractions). None for the stepped-only kinds.
    fn curve_values(&self, _fraction: f64) -> Vec<f64> {
        Vec::new()
    }
}

impl<V: Channels + Serialize + DeserializeOwned> EditKey for Key<V> {
    fn time(&self) -> f64 {
        self.time
    }
    fn set_time(&mut self, time_s: f64) {
        self.time = time_s;
    }
    fn curve(&self) -> Option<&Curve> {
        Some(&self.curve)
    }
    fn curve_mut(&mut self) -> Option<&mut Curve> {
        Some(&mut self.curve)
    }
    fn curve_values(&self, fraction: f64) -> Vec<f64> {
        if V::CURVE_PER_CHANNEL {
            self.value.numbers().to_vec()
        } else {
            vec![fraction]
        }
    }
}

impl<V: Clone + Serialize + DeserializeOwned> EditKey for StepKey<V> {
    fn time(&self) -> f64 {
        self.time
    }
    fn set_time(&mut self, time_s: f64) {
        self.time = time_s;
    }
}

impl EditKey for EventKey {
    const SHARES_TIMES: bool = true;
    fn time(&self) -> f64 {
        self.time
    }
    fn set_time(&mut self, time_s: f64) {
        self.time = time_s;
    }
}

/// An edit of one timeline's keys, whatever their kind.
pub(super) trait TimelineEdit {
    fn edit<K: EditKey>(
        &mut self,
        timeline: &TimelineId,
        keys: &mut Vec<K>,
    ) -> Result<(), EditError>;
}

/// A key of one timeline while it is edited: its (new) time, the key, the time it is named by
/// (none for a pasted key), and the segment it started before the edit (its own and the next
/// key's old times), if it had one.
#[derive(Clone)]
pub(super) struct Entry<K> {
    pub time_s: f64,
    pub key: K,
    pub found_as: Option<f64>,
    pub old_segment: Option<(f64, f64)>,
}

/// The keys of a timeline as entries (sorted as stored).
pub(super) fn entries_of<K: EditKey>(keys: &[K]) -> Vec<Entry<K>> {
    keys.iter()
        .enumerate()
        .map(|(i, key)| Entry {
            time_s: key.time(),
            key: key.clone(),
            found_as: Some(key.time()),
            old_segment: keys.get(i + 1).map(|next| (key.time(), next.time())),
        })
        .collect()
}

pub(super) fn find<'a, K>(
    entries: &'a mut [Entry<K>],
    timeline: &TimelineId,
    time_s: f64,
) -> Result<&'a mut Entry<K>, EditError> {
    // Match by the old time: a key moved earlier in the same edit must not be found again.
    entries
        .iter_mut()
        .find(|e| {
            e.found_as
                .is_some_and(|old| (old - time_s).abs() <= KEY_TIME_TOLERANCE_S)
        })
        .ok_or_else(|| unknown(timeline, time_s))
}

/// Every entry found as `time_s` (one, except on a timeline whose keys share times); none is
/// an error.
pub(super) fn find_all<'a, K>(
    entries: &'a mut [Entry<K>],
    timeline: &TimelineId,
    time_s: f64,
) -> Result<Vec<&'a mut Entry<K>>, EditError> {
    let found: Vec<&mut Entry<K>> = entries
        .iter_mut()
        .filter(|e| {
            e.found_as
                .is_some_and(|old| (old - time_s).abs() <= KEY_TIME_TOLERANCE_S)
        })
        .collect();
    if found.is_empty() {
        return Err(unknown(timeline, time_s));
    }
    Ok(found)
}

/// Sorts `entries` (stably: events at one time keep their order), refuses two at one time
/// (where keys may not share times), fits the Bézier handles' times to their new
/// segments, and returns them as `timeline`'s keys.
pub(super) fn write_keys<K: EditKey>(
    timeline: &TimelineId,
    mut entries: Vec<Entry<K>>,
) -> Result<Vec<K>, EditError> {
    entries.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    for pair in entries.windows(2).filter(|_| !K::SHARES_TIMES) {
        if pair[1].time_s - pair[0].time_s <= KEY_TIME_TOLERANCE_S {
            return Err(EditError::Collision {
                timeline: timeline.label(),
                time_s: pair[1].time_s,
            });
        }
    }
    let times: Vec<f64> = entries.iter().map(|e| e.time_s).collect();
    Ok(entries
        .into_iter()
        .enumerate()
        .map(|(i, mut e)| {
            e.key.set_time(e.time_s);
            if let (Some(Curve::Bezier(numbers)), Some(&end)) =
                (e.key.curve_mut(), times.get(i + 1))
            {
                // An untouched segment keeps its handles exactly as given (a curve being set is
                // checked, not bent into shape).
                if e.old_segment != Some((e.time_s, end)) {
                    let old = e.old_segment.filter(|(a, b)| b > a);
                    // Even positions in each group of four are the handles' times.
                    for cx in numbers.iter_mut().step_by(2) {
                        *cx = remap(*cx, old, (e.time_s, end));
                    }
                }
            }
            e.key
        })
        .collect())
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

/// Runs `edit` on the keys of `timeline` in `animation`. A missing timeline is created empty
/// when `create` (except an IK drag's: its rest point is not part of a key), else refused. A
/// timeline the edit leaves without keys is removed, with the bone, point or part entry it
/// leaves empty; an emptied IK drag stays until the whole edit is done (see `finish`), so that
/// the drags after it keep their indices meanwhile.
pub(super) fn edit_timeline(
    animation: &mut Animation,
    timeline: &TimelineId,
    create: bool,
    edit: &mut impl TimelineEdit,
) -> Result<(), EditError> {
    let missing = || EditError::UnknownTimeline(timeline.label());
    match timeline {
        TimelineId::Bone { bone, channel } => {
            let t = owner(&mut animation.bones, bone, create).ok_or_else(missing)?;
            let (rotate, pairs) = (
                &mut t.rotate,
                [&mut t.translate, &mut t.scale, &mut t.shear],
            );
            in_channel(rotate, pairs, *channel, create, timeline, edit)?;
            drop_if_empty(&mut animation.bones, bone);
        }
        TimelineId::Point { point, channel } => {
            let t = owner(&mut animation.points, point, create).ok_or_else(missing)?;
            let (rotate, pairs) = (
                &mut t.rotate,
                [&mut t.translate, &mut t.scale, &mut t.shear],
            );
            in_channel(rotate, pairs, *channel, create, timeline, edit)?;
            drop_if_empty(&mut animation.points, point);
        }
        TimelineId::Cage { cage } => {
            let keys = owner(&mut animation.cages, cage, create).ok_or_else(missing)?;
            edit.edit(timeline, keys)?;
            drop_if_empty(&mut animation.cages, cage);
        }
        TimelineId::Ik { index } => {
            let drag = animation.ik.get_mut(*index).ok_or_else(missing)?;
            edit.edit(timeline, &mut drag.to)?;
        }
        TimelineId::PartColor { part } => {
            let t = owner(&mut animation.parts, part, create).ok_or_else(missing)?;
            in_slot(&mut t.color, create, timeline, edit)?;
            drop_if_empty(&mut animation.parts, part);
        }
        TimelineId::PartVisible { part } => {
            let t = owner(&mut animation.parts, part, create).ok_or_else(missing)?;
            in_slot(&mut t.visible, create, timeline, edit)?;
            drop_if_empty(&mut animation.parts, part);
        }
        TimelineId::DrawOrder => in_slot(&mut animation.draw_order, create, timeline, edit)?,
        TimelineId::Attachment { slot } => {
            let t = owner(&mut animation.parts, slot, create).ok_or_else(missing)?;
            in_slot(&mut t.attachment, create, timeline, edit)?;
            drop_if_empty(&mut animation.parts, slot);
        }
        TimelineId::Deform { part } => {
            let keys = owner(&mut animation.deform, part, create).ok_or_else(missing)?;
            edit.edit(timeline, keys)?;
            drop_if_empty(&mut animation.deform, part);
        }
        TimelineId::Events => {
            if !create && animation.events.is_empty() {
                return Err(missing());
            }
            edit.edit(timeline, &mut animation.events)?;
        }
    }
    Ok(())
}

/// The entry `name` of `map` (created empty when `create`).
fn owner<'a, T: Default>(
    map: &'a mut BTreeMap<String, T>,
    name: &str,
    create: bool,
) -> Option<&'a mut T> {
    if create && !map.contains_key(name) {
        map.insert(name.to_string(), T::default());
    }
    map.get_mut(name)
}

/// Removes `name`'s entry when it holds no timeline (or, for a cage, no key).
fn drop_if_empty<T: Default + PartialEq>(map: &mut BTreeMap<String, T>, name: &str) {
    if map.get(name).is_some_and(|t| *t == T::default()) {
        map.remove(name);
    }
}

/// A bone's or point's timeline of `channel`: `rotate`, or one of translate, scale and shear.
fn in_channel<E: TimelineEdit>(
    rotate: &mut Option<Vec<Key<f64>>>,
    [translate, scale, shear]: [&mut Option<Vec<Key<[f64; 2]>>>; 3],
    channel: TransformChannel,
    create: bool,
    timeline: &TimelineId,
    edit: &mut E,
) -> Result<(), EditError> {
    match channel {
        TransformChannel::Rotate => in_slot(rotate, create, timeline, edit),
        TransformChannel::Translate => in_slot(translate, create, timeline, edit),
        TransformChannel::Scale => in_slot(scale, create, timeline, edit),
        TransformChannel::Shear => in_slot(shear, create, timeline, edit),
    }
}

/// An optional timeline: edited where present (or created), removed when left without keys.
fn in_slot<K: EditKey, E: TimelineEdit>(
    slot: &mut Option<Vec<K>>,
    create: bool,
    timeline: &TimelineId,
    edit: &mut E,
) -> Result<(), EditError> {
    if create && slot.is_none() {
        *slot = Some(Vec::new());
    }
    let keys = slot
        .as_mut()
        .ok_or_else(|| EditError::UnknownTimeline(timeline.label()))?;
    edit.edit(timeline, keys)?;
    if keys.is_empty() {
        *slot = None;
    }
    Ok(())
}
