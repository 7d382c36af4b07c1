//! Keys in a [`super::Document`]'s animations: the animation a command edits, keying a pose or a
//! drag at a time, and the keys at a time over every timeline.

use super::*;

/// Replaces animation `name` of `state` (an empty one when there is none) by `apply(name, it)`
/// (a key edit: `anim::edit`, which checks what it returns).
pub(super) fn edit_animation(
    state: &mut State,
    name: String,
    apply: impl FnOnce(&str, &Animation) -> Result<Animation, edit::EditError>,
) -> Result<(), DocumentError> {
    let edited = apply(&name, &animation_named(state, &name))?;
    state.animations.insert(name, edited);
    Ok(())
}

pub(super) fn check_key_time(time_s: f64) -> Result<(), DocumentError> {
    if time_s.is_finite() && time_s >= 0.0 {
        Ok(())
    } else {
        Err(DocumentError::KeyTime(time_s))
    }
}

/// The animation stored under `name`, or a new empty one.
pub fn animation_named(state: &State, name: &str) -> Animation {
    state.animations.get(name).cloned().unwrap_or_default()
}

pub(super) fn store_animation(
    next: &mut State,
    name: &str,
    anim: Animation,
) -> Result<(), DocumentError> {
    anim.validate(name)?;
    next.animations.insert(name.to_string(), anim);
    Ok(())
}

/// *Set key*'s keys of `pose` at `time_s` ([`Command::SetKey`]): the channels where `pose`
/// differs from what `anim` shows there (sampled with `sampling`), every channel of the handles
/// in `keep` (posed at rest when `pose` leaves them out; names that are no bone or point of
/// `state` are skipped), and every IK drag of `pose`. Keys go in with [`put_key`], so a key
/// inside a segment splits its curve and the motion around it stays as it was.
pub(super) fn key_pose(
    state: &State,
    anim: &mut Animation,
    time_s: f64,
    mut pose: Pose,
    keep: &[String],
    sampling: &crate::anim::SampleOptions,
) {
    let shown = anim.sample_with(time_s, false, sampling);
    for name in keep {
        if state.handles.bones.iter().any(|b| &b.name == name) {
            pose.bones.entry(name.clone()).or_default();
        } else if state.handles.points.iter().any(|p| &p.name == name) {
            pose.points.entry(name.clone()).or_default();
        }
    }
    animations::key_changes(anim, time_s, &shown, &pose, keep);
    for drag in &pose.ik {
        key_drag(anim, drag, time_s);
    }
}

/// Keys `drag`'s target at `time_s` on the IK timeline of its rest point and weight (made,
/// with a linear key, when the animation has none).
pub(crate) fn key_drag(anim: &mut Animation, drag: &crate::rig::pose::IkDrag, time_s: f64) {
    match anim
        .ik
        .iter_mut()
        .find(|t| t.at == drag.at && t.weight == drag.weight)
    {
        Some(t) => put_key(&mut t.to, time_s, drag.to),
        None => anim.ik.push(IkTimeline {
            at: drag.at,
            to: vec![Key {
                time: time_s,
                value: drag.to,
                curve: Curve::Linear,
            }],
            weight: drag.weight,
        }),
    }
}

/// The key of every timeline of `anim` at `time_s` (within [`KEY_TIME_TOLERANCE_S`]): bones,
/// points, cages, drags, slot colours, visibility and attachments, draw order, deform keys and
/// events, as [`edit::timelines`] lists them.
pub(super) fn keys_at(anim: &Animation, time_s: f64) -> Vec<KeyRef> {
    edit::keys_at(&edit::timelines(anim), time_s)
}

/// Every key time of `anim` over all its timelines, sorted, duplicates (within
/// [`KEY_TIME_TOLERANCE_S`]) merged.
pub fn key_times(anim: &Animation) -> Vec<f64> {
    let mut times: Vec<f64> = edit::timelines(anim)
        .into_iter()
        .flat_map(|(_, times)| times)
        .collect();
    times.sort_by(f64::total_cmp);
    times.dedup_by(|a, b| (*a - *b).abs() <= KEY_TIME_TOLERANCE_S);
    times
}
