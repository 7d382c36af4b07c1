//! Animate mode's *Apply motion…*, driven by input events only: a motion of the library (or a
//! capture file typed in, where no native dialog answers) retargeted onto the rig as one
//! undoable edit; a rig whose bones have no humanoid names gets the library's error and keeps
//! its animations.

use super::*;
use crate::anim::Animation;
use std::collections::BTreeMap;

fn animations(h: &Harness<'_, EditorApp>) -> BTreeMap<String, Animation> {
    h.state().doc.state().animations.clone()
}

/// Keys of the bones' rotations in `anim`, all bones together.
fn rotation_keys(anim: &Animation) -> usize {
    anim.bones
        .values()
        .map(|t| t.rotate.as_ref().map_or(0, Vec::len))
        .sum()
}

/// Animate mode (key 3), then *Apply motion…*: the window's fields are there.
fn open_apply_motion(h: &mut Harness<'_, EditorApp>) {
    h.key_press(Key::Num3);
    h.run();
    click_shown(h, "Apply motion…");
    h.get_by_label("Animation name:");
}

#[test]
fn apply_motion_adds_the_walk_as_one_undoable_edit_and_a_capture_file_too() {
    let mut h = open_character("apply-motion");
    open_apply_motion(&mut h);
    assert!(animations(&h).is_empty());

    // Picking "walk" names the animation after it; Apply adds it, picked for editing.
    click_shown(&mut h, "walk");
    assert_eq!(
        h.get_by_label("Animation name:").value().as_deref(),
        Some("walk")
    );
    click_shown_by(&mut h, button("Apply"));
    let walk = animations(&h)
        .remove("walk")
        .unwrap_or_else(|| panic!("no walk: {:?}", h.state().message));
    for bone in ["hip", "leg_upper_l", "leg_lower_r", "arm_upper_l"] {
        assert!(walk.bones.contains_key(bone), "{bone} is not keyed");
    }
    assert!(rotation_keys(&walk) > 10, "{}", rotation_keys(&walk));
    assert_eq!(h.state().animate.animation, "walk");
    let message = h.state().message.clone().unwrap_or_default();
    for what in [
        "'walk'",
        "keys from",
        "legs ",
        "foot contacts planted",
        "loops",
    ] {
        assert!(message.contains(what), "{what} not in: {message}");
    }
    assert!(
        h.query_by_label("Animation name:").is_none(),
        "the window closes once applied"
    );

    // One edit: Ctrl+Z takes the whole animation back, Ctrl+Shift+Z brings it again.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert!(animations(&h).is_empty());
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    h.run();
    assert_eq!(animations(&h).get("walk"), Some(&walk));

    // From a file, typed where no native dialog answers: the name follows the file's stem
    // until typed over; seen from the side, in place.
    click_shown(&mut h, "Apply motion…");
    click_shown(&mut h, "From file…");
    let bvh = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/motions/wave.bvh");
    type_into(&mut h, "Capture file (.bvh):", &bvh.display().to_string());
    assert_eq!(
        h.get_by_label("Animation name:").value().as_deref(),
        Some("wave")
    );
    type_into(&mut h, "Animation name:", "greeting");
    click_shown(&mut h, "Side");
    click_shown(&mut h, "In place");
    click_shown_by(&mut h, button("Apply"));
    let all = animations(&h);
    assert_eq!(
        all.keys().collect::<Vec<_>>(),
        ["greeting", "walk"],
        "{:?}",
        h.state().message
    );
    assert!(rotation_keys(&all["greeting"]) > 0);
    assert_eq!(h.state().animate.animation, "greeting");
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("arms side"), "{message}");
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(animations(&h).keys().collect::<Vec<_>>(), ["walk"]);
}

#[test]
fn a_rig_without_humanoid_bone_names_gets_the_error_and_keeps_its_animations() {
    let (dir, path) = character_rig("apply-motion-unnamed");
    let mut doc = Document::open(&path).expect("opens");
    let bones: Vec<String> = doc
        .state()
        .handles
        .bones
        .iter()
        .map(|b| b.name.clone())
        .collect();
    for (k, from) in bones.into_iter().enumerate() {
        doc.apply(Command::Rename {
            from,
            to: format!("piece {k}"),
        })
        .expect("renamed");
    }
    doc.apply(Command::Animations(crate::document::AnimationEdit::Add {
        name: "sway".into(),
    }))
    .expect("added");
    let mut h = InFolder {
        h: harness(EditorApp::new(doc)),
        _dir: dir,
    };
    h.run();
    let before = animations(&h);
    open_apply_motion(&mut h);
    click_shown(&mut h, "walk");
    click_shown_by(&mut h, button("Apply"));

    let message = h.state().message.clone().unwrap_or_default();
    assert!(
        message.contains("no bone of the rig is driven by the capture"),
        "{message}"
    );
    assert!(h.state().log.entries.last().is_some_and(|e| e.error));
    assert_eq!(animations(&h), before);
    // The window stays open to try again; Cancel closes it, still nothing added.
    click_shown_by(&mut h, button("Cancel"));
    assert!(h.query_by_label("Animation name:").is_none());
    assert_eq!(animations(&h), before);
    // The one edit Ctrl+Z undoes is the animation added before, not anything of the motion's.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert!(animations(&h).is_empty());
}
