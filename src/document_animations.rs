//! The document's list of animations and auto-keying: [`AnimationEdit`] (add, rename,
//! duplicate, delete an animation, or put a computed one under a name) and [`key_changes`] (key only the channels a pose changed).
//!
//! In: the state's animations by name. Out: the animations after the edit, or why it is
//! refused (an empty name, a name taken, an animation that does not exist); the caller
//! ([`super::Document::apply`]) keeps the state as it was on a refusal.

use super::{DocumentError, State};
use crate::anim::edit::put_key;
use crate::anim::{Animation, Key};
use crate::rig::Pose;

/// One edit of the list of animations (see [`super::Command::Animations`]).
#[derive(Clone, Debug, PartialEq)]
pub enum AnimationEdit {
    /// A new animation with no keys.
    Add {
        name: String,
    },
    /// Renames an animation; its keys stay.
    Rename {
        from: String,
        to: String,
    },
    /// A copy of `from`'s keys under the new name `to`.
    Duplicate {
        from: String,
        to: String,
    },
    Delete {
        name: String,
    },
    /// Stores a computed animation (*Apply motion…*'s retargeted capture) under `name`,
    /// replacing one of that name: one undo step either way.
    Put {
        name: String,
        animation: Box<Animation>,
    },
}

/// Checks a new animation's name: not blank, no control characters, not taken.
fn check_new_name(state: &State, name: &str) -> Result<(), DocumentError> {
    if name.trim().is_empty() || name.chars().any(char::is_control) || name.trim() != name {
        return Err(DocumentError::AnimationName(name.to_string()));
    }
    if state.animations.contains_key(name) {
        return Err(DocumentError::AnimationExists(name.to_string()));
    }
    Ok(())
}

fn existing(state: &State, name: &str) -> Result<Animation, DocumentError> {
    state
        .animations
        .get(name)
        .cloned()
        .ok_or_else(|| DocumentError::UnknownAnimation(name.to_string()))
}

/// Applies `edit` to `next` (a copy of the state).
pub(super) fn apply(next: &mut State, edit: AnimationEdit) -> Result<(), DocumentError> {
    match edit {
        AnimationEdit::Add { name } => {
            check_new_name(next, &name)?;
            next.animations.insert(name, Animation::default());
        }
        AnimationEdit::Rename { from, to } => {
            let anim = existing(next, &from)?;
            check_new_name(next, &to)?;
            next.animations.remove(&from);
            next.animations.insert(to, anim);
        }
        AnimationEdit::Duplicate { from, to } => {
            let anim = existing(next, &from)?;
            check_new_name(next, &to)?;
            next.animations.insert(to, anim);
        }
        AnimationEdit::Delete { name } => {
            existing(next, &name)?;
            next.animations.remove(&name);
        }
        AnimationEdit::Put { name, animation } => {
            // A name taken is replaced, but it must still be a name.
            if let Err(e) = check_new_name(next, &name) {
                if !next.animations.contains_key(&name) {
                    return Err(e);
                }
            }
            super::store_animation(next, &name, *animation)?;
        }
    }
    Ok(())
}

/// `base` followed by the first of "", " 2", " 3", … that no animation of `state` has.
pub fn unused_animation_name(state: &State, base: &str) -> String {
    (1..)
        .map(|k| {
            if k == 1 {
                base.to_string()
            } else {
                format!("{base} {k}")
            }
        })
        .find(|n| !state.animations.contains_key(n))
        .unwrap_or_else(|| base.to_string())
}

/// How far (in each number's own unit: degrees, px, scale factor) a channel of the pose edited
/// may be from the animation's own value before it counts as changed and gets a key.
pub const KEY_CHANGE_TOLERANCE: f64 = 1e-6;

/// Whether `a` and `b` differ by more than [`KEY_CHANGE_TOLERANCE`] in any number.
fn changed(a: &[f64], b: &[f64]) -> bool {
    a.len() != b.len()
        || a.iter()
            .zip(b)
            .any(|(x, y)| (x - y).abs() > KEY_CHANGE_TOLERANCE)
}

/// A bone's or point's channels: rotate (degrees), translate (px), scale, shear (degrees).
type Channels = (f64, [f64; 2], [f64; 2], [f64; 2]);

/// A bone's or point's timelines of the same channels, in the same order.
type ChannelTracks<'a> = (
    &'a mut Option<Vec<Key<f64>>>,
    &'a mut Option<Vec<Key<[f64; 2]>>>,
    &'a mut Option<Vec<Key<[f64; 2]>>>,
    &'a mut Option<Vec<Key<[f64; 2]>>>,
);

/// Which channels of `new` differ from `old` by more than [`KEY_CHANGE_TOLERANCE`] (every
/// one when `all`).
fn moved_channels(new: Channels, old: Channels, all: bool) -> [bool; 4] {
    [
        all || changed(&[new.0], &[old.0]),
        all || changed(&new.1, &old.1),
        all || changed(&new.2, &old.2),
        all || changed(&new.3, &old.3),
    ]
}

/// Keys at `time_s` the channels of `new` that `moved` marks, each into its track; returns
/// how many.
fn key_moved(tracks: ChannelTracks<'_>, time_s: f64, new: Channels, moved: [bool; 4]) -> usize {
    let (rotate, translate, scale, shear) = tracks;
    if moved[0] {
        put_key(rotate.get_or_insert_with(Vec::new), time_s, new.0);
    }
    for (m, track, value) in [
        (moved[1], translate, new.1),
        (moved[2], scale, new.2),
        (moved[3], shear, new.3),
    ] {
        if m {
            put_key(track.get_or_insert_with(Vec::new), time_s, value);
        }
    }
    moved.iter().filter(|&&m| m).count()
}

/// Keys at `time_s` each channel where `pose` differs from `before` (the animation's own pose
/// there) by more than [`KEY_CHANGE_TOLERANCE`], and every channel of the bones and points
/// `pose` names that are in `keep`: a bone's or point's rotate, translate, scale and shear one
/// by one, and each IK drag that is new or moved. Returns how many channels were keyed. Keys go
/// in with [`put_key`], so a key inside a segment splits its curve.
pub fn key_changes(
    anim: &mut Animation,
    time_s: f64,
    before: &Pose,
    pose: &Pose,
    keep: &[String],
) -> usize {
    let mut keyed = 0;
    for (name, b) in &pose.bones {
        let old = before.bones.get(name).cloned().unwrap_or_default();
        let new = (b.rotate, b.translate, b.scale, b.shear);
        let old = (old.rotate, old.translate, old.scale, old.shear);
        let moved = moved_channels(new, old, keep.contains(name));
        if moved.contains(&true) {
            let t = anim.bones.entry(name.clone()).or_default();
            let tracks = (&mut t.rotate, &mut t.translate, &mut t.scale, &mut t.shear);
            keyed += key_moved(tracks, time_s, new, moved);
        }
    }
    for (name, p) in &pose.points {
        let old = before.points.get(name).cloned().unwrap_or_default();
        let new = (p.rotate, p.translate, p.scale, p.shear);
        let old = (old.rotate, old.translate, old.scale, old.shear);
        let moved = moved_channels(new, old, keep.contains(name));
        if moved.contains(&true) {
            let t = anim.points.entry(name.clone()).or_default();
            let tracks = (&mut t.rotate, &mut t.translate, &mut t.scale, &mut t.shear);
            keyed += key_moved(tracks, time_s, new, moved);
        }
    }
    for drag in &pose.ik {
        let same = |d: &crate::rig::pose::IkDrag| d.at == drag.at && d.weight == drag.weight;
        if before.ik.iter().any(|d| same(d) && d.to == drag.to) {
            continue;
        }
        keyed += 1;
        crate::document::key_drag(anim, drag, time_s);
    }
    keyed
}

/// The attachments slot `slot` can show, by part name: its own part first, then the parts that
/// are its other attachments.
pub fn slot_attachments(state: &State, slot: &str) -> Vec<String> {
    let mut names = vec![slot.to_string()];
    names.extend(
        state
            .slots
            .attachments
            .iter()
            .filter(|(_, s)| *s == slot)
            .map(|(part, _)| part.clone()),
    );
    names
}

/// Puts a stepped key of `parts.SLOT.attachment` at `time_s` in `anim` (replacing one at the
/// same time): from then on the slot shows `attachment` (`None`: nothing). Refused for a name
/// that is not a slot, or an attachment the slot does not have.
pub(super) fn key_attachment(
    state: &State,
    anim: &mut Animation,
    slot: &str,
    time_s: f64,
    attachment: Option<String>,
) -> Result<(), DocumentError> {
    let is_slot =
        state.layers.iter().any(|l| l.name == slot) && !state.slots.attachments.contains_key(slot);
    if !is_slot {
        return Err(DocumentError::Slots(format!(
            "there is no slot named '{slot}'"
        )));
    }
    if let Some(name) = &attachment {
        let names = slot_attachments(state, slot);
        if !names.contains(name) {
            return Err(DocumentError::Slots(format!(
                "slot '{slot}' has no attachment '{name}' (its attachments: {})",
                names.join(", ")
            )));
        }
    }
    let keys = anim
        .parts
        .entry(slot.to_string())
        .or_default()
        .attachment
        .get_or_insert_with(Vec::new);
    match keys
        .iter_mut()
        .find(|k| (k.time - time_s).abs() <= crate::anim::edit::KEY_TIME_TOLERANCE_S)
    {
        Some(k) => k.value = attachment,
        None => {
            let at = keys.partition_point(|k| k.time < time_s);
            keys.insert(
                at,
                crate::anim::StepKey {
                    time: time_s,
                    value: attachment,
                },
            );
        }
    }
    Ok(())
}

/// Puts a deform key of part `part` at `time_s` in `anim` ([`put_key`]). Refused for a part
/// the rig does not have, or offsets that are not one per vertex of its mesh.
pub(super) fn key_deform(
    state: &State,
    anim: &mut Animation,
    part: &str,
    time_s: f64,
    offsets: Vec<crate::geom::Vec2>,
) -> Result<(), DocumentError> {
    let rig = state.rig.as_ref().ok_or(DocumentError::NoWeights)?;
    let mesh = rig
        .doc
        .parts
        .iter()
        .find(|p| p.name == part)
        .map(|p| p.mesh.vertices.len())
        .ok_or_else(|| DocumentError::UnknownLayer(part.to_string()))?;
    if offsets.len() != mesh {
        return Err(DocumentError::PolygonSize {
            name: part.to_string(),
            got: offsets.len(),
            expected: mesh,
        });
    }
    put_key(
        anim.deform.entry(part.to_string()).or_default(),
        time_s,
        offsets,
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::{animation_named, Command, Document};
    use super::*;
    use crate::rig::pose::BonePose;

    fn arm_at(rotate: f64, translate: [f64; 2]) -> Pose {
        let mut pose = Pose::default();
        pose.bones.insert(
            "arm".into(),
            BonePose {
                rotate,
                translate,
                ..Default::default()
            },
        );
        pose
    }

    #[test]
    fn add_rename_duplicate_delete_and_their_refusals() {
        let mut doc = Document::new();
        let edit = |e| Command::Animations(e);
        doc.apply(edit(AnimationEdit::Add {
            name: "walk".into(),
        }))
        .expect("added");
        assert!(doc.state().animations["walk"] == Animation::default());
        doc.apply(Command::SetKey {
            animation: "walk".into(),
            time_s: 1.0,
            pose: arm_at(30.0, [0.0, 0.0]),
            keep: vec!["arm".into()],
            sampling: Default::default(),
        })
        .expect("keyed");
        // Taken, blank and padded names are refused, the document unchanged.
        for bad in ["walk", "", "  ", " walk2"] {
            let e = doc.apply(edit(AnimationEdit::Add { name: bad.into() }));
            assert!(e.is_err(), "{bad:?} accepted");
        }
        assert!(doc
            .apply(edit(AnimationEdit::Rename {
                from: "run".into(),
                to: "sprint".into()
            }))
            .is_err());
        doc.apply(edit(AnimationEdit::Duplicate {
            from: "walk".into(),
            to: "walk 2".into(),
        }))
        .expect("duplicated");
        assert_eq!(
            animation_named(doc.state(), "walk 2"),
            animation_named(doc.state(), "walk")
        );
        assert_eq!(unused_animation_name(doc.state(), "walk"), "walk 3");
        doc.apply(edit(AnimationEdit::Rename {
            from: "walk".into(),
            to: "stroll".into(),
        }))
        .expect("renamed");
        let names: Vec<&String> = doc.state().animations.keys().collect();
        assert_eq!(names, ["stroll", "walk 2"]);
        doc.apply(edit(AnimationEdit::Delete {
            name: "stroll".into(),
        }))
        .expect("deleted");
        assert_eq!(doc.state().animations.len(), 1);
        assert!(doc.undo());
        assert!(doc.state().animations.contains_key("stroll"));
    }

    #[test]
    fn put_stores_or_replaces_an_animation_in_one_undo_step() {
        let mut doc = Document::new();
        let keyed = |rotate: f64| {
            let mut anim = Animation::default();
            put_key(
                anim.bones
                    .entry("arm".into())
                    .or_default()
                    .rotate
                    .get_or_insert_with(Vec::new),
                0.0,
                rotate,
            );
            anim
        };
        let put = |name: &str, anim: Animation| {
            Command::Animations(AnimationEdit::Put {
                name: name.into(),
                animation: Box::new(anim),
            })
        };
        doc.apply(put("walk", keyed(10.0))).expect("put");
        assert_eq!(doc.state().animations["walk"], keyed(10.0));
        // A name taken is replaced; undo brings the old keys back, redo the new ones.
        doc.apply(put("walk", keyed(20.0))).expect("replaced");
        assert_eq!(doc.state().animations["walk"], keyed(20.0));
        assert!(doc.undo());
        assert_eq!(doc.state().animations["walk"], keyed(10.0));
        assert!(doc.redo());
        assert_eq!(doc.state().animations["walk"], keyed(20.0));
        // Blank or padded names are refused, the document unchanged.
        for bad in ["", " ", " walk"] {
            assert!(doc.apply(put(bad, keyed(5.0))).is_err(), "{bad:?} accepted");
        }
        assert_eq!(doc.state().animations.len(), 1);
        assert!(doc.undo());
        assert!(doc.undo());
        assert!(doc.state().animations.is_empty());
    }

    #[test]
    fn key_changes_keys_only_the_channels_that_moved() {
        let mut doc = Document::new();
        doc.apply(Command::SetKey {
            animation: "wave".into(),
            time_s: 0.0,
            pose: arm_at(0.0, [0.0, 0.0]),
            keep: vec!["arm".into()],
            sampling: Default::default(),
        })
        .expect("keyed");
        let before = animation_named(doc.state(), "wave").sample(1.0, false);
        let after = arm_at(45.0, [0.0, 0.0]);
        doc.apply(Command::KeyChanges {
            animation: "wave".into(),
            time_s: 1.0,
            before: before.clone(),
            pose: after,
        })
        .expect("auto-keyed");
        let arm = &animation_named(doc.state(), "wave").bones["arm"];
        assert_eq!(arm.rotate.as_ref().map(Vec::len), Some(2));
        assert_eq!(arm.translate.as_ref().map(Vec::len), Some(1));
        assert_eq!(arm.scale.as_ref().map(Vec::len), Some(1));
        // Nothing changed: refused, as Set key is.
        let e = doc.apply(Command::KeyChanges {
            animation: "wave".into(),
            time_s: 1.0,
            before: before.clone(),
            pose: before,
        });
        assert!(matches!(e, Err(DocumentError::NothingToKey(_))), "{e:?}");
    }

    #[test]
    fn set_key_keys_what_changed_and_every_channel_of_the_kept_handles() {
        let mut doc = Document::new();
        let set_key = |time_s: f64, pose: Pose, keep: &[&str]| Command::SetKey {
            animation: "wave".into(),
            time_s,
            pose,
            keep: keep.iter().map(|n| n.to_string()).collect(),
            sampling: Default::default(),
        };
        // The arm turned, the leg named at rest: only the arm's rotation is keyed.
        let mut pose = arm_at(10.0, [0.0, 0.0]);
        pose.bones.insert("leg".into(), BonePose::default());
        doc.apply(set_key(0.0, pose.clone(), &[])).expect("keyed");
        let anim = animation_named(doc.state(), "wave");
        assert_eq!(anim.bones.keys().collect::<Vec<_>>(), ["arm"]);
        let arm = &anim.bones["arm"];
        assert_eq!(arm.rotate.as_ref().map(Vec::len), Some(1));
        assert!(arm.translate.is_none() && arm.scale.is_none() && arm.shear.is_none());
        // At 1 s the animation shows the same pose; the leg moved less than the tolerance:
        // nothing to key.
        pose.bones.get_mut("leg").expect("leg").rotate = KEY_CHANGE_TOLERANCE / 2.0;
        let e = doc.apply(set_key(1.0, pose.clone(), &[]));
        assert!(matches!(e, Err(DocumentError::NothingToKey(_))), "{e:?}");
        // The leg kept (selected): all four of its channels are keyed, the arm still is not.
        doc.apply(set_key(1.0, pose, &["leg"])).expect("keyed");
        let anim = animation_named(doc.state(), "wave");
        assert_eq!(anim.bones["arm"].rotate.as_ref().map(Vec::len), Some(1));
        let leg = &anim.bones["leg"];
        let lens = [&leg.translate, &leg.scale, &leg.shear].map(|k| k.as_ref().map(Vec::len));
        assert_eq!(lens, [Some(1); 3]);
        assert_eq!(leg.rotate.as_ref().map(Vec::len), Some(1));
    }

    #[test]
    fn attachment_keys_replace_at_the_same_time_and_refuse_what_the_slot_lacks() {
        let mut doc = Document::new();
        let key = |slot: &str, time_s: f64, attachment: Option<&str>| Command::KeyAttachment {
            animation: "swap".into(),
            slot: slot.into(),
            time_s,
            attachment: attachment.map(str::to_string),
        };
        let e = doc.apply(key("hand", 0.0, Some("hand"))).unwrap_err();
        assert_eq!(
            e.to_string(),
            "slots and skins: there is no slot named 'hand'"
        );
        doc.apply(Command::AddLayer(crate::pipeline::Layer::whole(
            "hand",
            "hand.png",
            image::RgbaImage::new(8, 8),
        )))
        .expect("a layer");
        let e = doc.apply(key("hand", 0.0, Some("fist"))).unwrap_err();
        assert_eq!(
            e.to_string(),
            "slots and skins: slot 'hand' has no attachment 'fist' (its attachments: hand)"
        );
        doc.apply(key("hand", 0.5, None)).expect("hidden at 0.5 s");
        doc.apply(key("hand", 0.0, Some("hand")))
            .expect("shown at 0 s");
        doc.apply(key("hand", 0.5, Some("hand"))).expect("replaced");
        let keys = animation_named(doc.state(), "swap").parts["hand"]
            .attachment
            .clone()
            .expect("keys");
        let keys: Vec<_> = keys.into_iter().map(|k| (k.time, k.value)).collect();
        assert_eq!(
            keys,
            [(0.0, Some("hand".into())), (0.5, Some("hand".into()))]
        );
    }
}
