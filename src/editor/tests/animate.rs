//! Animate and pose mode's panels driven by input events only: the list of animations, the
//! numbers panel, auto-key, the K shortcut and the dopesheet's row names.

use super::*;
use crate::anim::edit::{TimelineId, TransformChannel};

fn names(h: &Harness<'_, EditorApp>) -> Vec<String> {
    h.state().doc.state().animations.keys().cloned().collect()
}

#[test]
fn animations_are_created_renamed_duplicated_picked_and_deleted_from_the_list() {
    let mut h = open_character("animation-list");
    h.key_press(Key::Num3);
    h.run();
    // A document without animations edits one that has no keys yet; the list says so.
    h.get_by_label("animation (no keys yet)");
    assert!(names(&h).is_empty());

    click_shown(&mut h, "New animation");
    assert_eq!(names(&h), ["animation"]);
    type_into(&mut h, "Rename to:", "walk");
    click_shown(&mut h, "Rename animation");
    assert_eq!(names(&h), ["walk"]);
    assert_eq!(h.state().animate.animation, "walk");

    // Key something into "walk" (K), then duplicate it: the copy has the same keys and is
    // the one edited.
    let grip = torso_point(&h);
    drag(&mut h, grip, [grip[0] + 15.0, grip[1]]);
    h.key_press(Key::K);
    h.run();
    let walk = crate::document::animation_named(h.state().doc.state(), "walk");
    assert_eq!(walk.ik.len(), 1, "{:?}", h.state().message);
    click_shown(&mut h, "Duplicate animation");
    assert_eq!(names(&h), ["walk", "walk 2"]);
    assert_eq!(h.state().animate.animation, "walk 2");
    assert_eq!(
        crate::document::animation_named(h.state().doc.state(), "walk 2"),
        walk
    );

    // Renaming onto a name taken is refused with a message; nothing changes.
    type_into(&mut h, "Rename to:", "walk");
    click_shown(&mut h, "Rename animation");
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("already exists"), "{message}");
    assert_eq!(names(&h), ["walk", "walk 2"]);

    // Pick "walk" from the list, delete it: "walk 2" is edited; Ctrl+Z brings "walk" back.
    click_shown(&mut h, "walk");
    assert_eq!(h.state().animate.animation, "walk");
    click_shown(&mut h, "Delete animation");
    assert_eq!(names(&h), ["walk 2"]);
    assert_eq!(h.state().animate.animation, "walk 2");
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(names(&h), ["walk", "walk 2"]);
}

#[test]
fn the_numbers_panel_poses_the_selected_bone_in_pose_mode() {
    let mut h = open_character("numbers");
    h.key_press(Key::Num2);
    h.run();
    // Nothing selected: one line says so, no fields (their labels would suggest values).
    h.get_by_label_contains("Nothing selected. Click a bone or point");
    assert!(h.query_by_label("Rotation").is_none());
    let tree_at = h.get_by_label("hip").rect();
    click(&mut h, Point::new(256.0, 225.0));
    // The fields appear in the room kept for them: the tree below stays where it was.
    assert_eq!(h.get_by_label("hip").rect(), tree_at);
    assert_eq!(h.state().selected.as_deref(), Some("chest"));
    set_number(&mut h, "Rotation", 30.0);
    set_number(&mut h, "Translation x", 4.0);
    set_number(&mut h, "Scale y", 1.5);
    let chest = h.state().doc.state().pose.bones["chest"].clone();
    assert_eq!(chest.rotate, 30.0, "{:?}", h.state().message);
    assert_eq!(chest.translate, [4.0, 0.0]);
    assert_eq!(chest.scale, [1.0, 1.5]);
    // The canvas shows it: the chest's head moved by the translation (in the hip's frame).
    let head = shown_head(&h, "chest");
    assert!(
        (distance(head, Point::new(256.0, 262.0)) - 4.0).abs() < 1e-6,
        "{head:?}"
    );
    // Each entered number is one undo step.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(h.state().doc.state().pose.bones["chest"].scale, [1.0, 1.0]);

    // Dragging a field shows the pose live and commits once, on release.
    let field = press_point(&h.get_by_label("Rotation"));
    assert_shown(&mut h, field, "Rotation");
    let field = field.1;
    let before_drag = h.state().doc.state().pose.clone();
    h.drag_at(field);
    h.step();
    for k in 1..=3 {
        h.hover_at(field + egui::vec2(10.0 * k as f32, 0.0));
        h.step();
    }
    assert_eq!(
        h.state().doc.state().pose,
        before_drag,
        "committed mid-drag"
    );
    h.drop_at(field + egui::vec2(30.0, 0.0));
    h.step();
    h.run();
    let rotate = h.state().doc.state().pose.bones["chest"].rotate;
    assert!(rotate > 30.0 + 1.0, "dragged to {rotate}");
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(h.state().doc.state().pose, before_drag);
}

#[test]
fn auto_key_keys_each_edit_at_the_playhead_and_rows_are_named_by_handle() {
    let mut h = open_character("auto-key");
    h.key_press(Key::Num3);
    h.run();
    click_shown(&mut h, "Auto-key");
    assert!(h.state().timeline.auto_key);

    // Turning the head in the numbers panel keys its rotation only, at once.
    click(&mut h, Point::new(256.0, 150.0));
    assert_eq!(h.state().selected.as_deref(), Some("head"));
    set_number(&mut h, "Rotation", 15.0);
    let anim = crate::document::animation_named(h.state().doc.state(), "animation");
    let head = &anim.bones["head"];
    assert_eq!(head.rotate.as_ref().map(Vec::len), Some(1), "{anim:?}");
    assert!(head.translate.is_none() && head.scale.is_none() && head.shear.is_none());

    // At 0.5 s, a drag of the torso is keyed as it is released, and its row in the dopesheet
    // is named after the handle nearest the point grabbed, not `ik[0]`.
    for _ in 0..12 {
        click_shown(&mut h, "Next frame");
    }
    let grip = torso_point(&h);
    drag(&mut h, grip, [grip[0] + 12.0, grip[1]]);
    let anim = crate::document::animation_named(h.state().doc.state(), "animation");
    assert_eq!(anim.ik.len(), 1, "{:?}", h.state().message);
    assert!((anim.ik[0].to[0].time - 0.5).abs() < 1e-9);
    assert!(h.state().animate.shown.is_none(), "keyed, not waiting");
    h.run();
    let sheet = h.state().timeline.sheet.clone().expect("the dopesheet");
    let row = sheet
        .rows
        .iter()
        .position(|(t, _)| *t == TimelineId::Ik { index: 0 })
        .expect("a row for the drag");
    let nearest = super::super::timeline::row_names(
        &[(TimelineId::Ik { index: 0 }, vec![0.5])],
        &anim,
        &h.state().doc.state().handles,
    );
    assert_eq!(sheet.names[row], nearest[0]);
    assert!(
        ["chest drag", "hip drag"].contains(&sheet.names[row].as_str()),
        "{}",
        sheet.names[row]
    );
    let rotate = TimelineId::Bone {
        bone: "head".into(),
        channel: TransformChannel::Rotate,
    };
    let head_row = sheet.rows.iter().position(|(t, _)| *t == rotate);
    assert_eq!(sheet.names[head_row.expect("head rotate")], "head rotate");

    // Off again: an edit waits for Set key.
    click_shown(&mut h, "Auto-key");
    set_number(&mut h, "Rotation", 40.0);
    assert!(h.state().animate.shown.is_some());
    let again = crate::document::animation_named(h.state().doc.state(), "animation");
    assert_eq!(again, anim);
}

#[test]
fn set_key_keys_the_rotated_bone_s_rotation_and_the_selected_bone_only() {
    let mut h = open_character("set-key-changes");
    h.key_press(Key::Num3);
    h.run();
    assert!(!h.state().timeline.auto_key);
    // Turn the head in the numbers panel (it waits for Set key), then select the lantern in
    // the tree: K keys the head's rotation and the lantern's four channels, nothing else.
    click(&mut h, Point::new(256.0, 150.0));
    assert_eq!(h.state().selected.as_deref(), Some("head"));
    set_number(&mut h, "Rotation", 15.0);
    assert!(h.state().animate.shown.is_some());
    click_label(&mut h, "lantern");
    assert_eq!(h.state().selected.as_deref(), Some("lantern"));
    h.key_press(Key::K);
    h.run();
    let anim = crate::document::animation_named(h.state().doc.state(), "animation");
    let timelines: Vec<_> = crate::anim::edit::timelines(&anim)
        .into_iter()
        .map(|(t, times)| (t, times.len()))
        .collect();
    let bone = |bone: &str, channel| TimelineId::Bone {
        bone: bone.into(),
        channel,
    };
    let mut expected = vec![(bone("head", TransformChannel::Rotate), 1)];
    for channel in TransformChannel::ALL {
        expected.push((bone("lantern", channel), 1));
    }
    let mut got = timelines;
    got.sort_by_key(|(t, _)| format!("{t:?}"));
    expected.sort_by_key(|(t, _)| format!("{t:?}"));
    assert_eq!(got, expected, "{:?}", h.state().message);
    let lantern = &anim.bones["lantern"];
    let head = &anim.bones["head"];
    assert_eq!(head.rotate.as_ref().map(|k| k[0].value), Some(15.0));
    assert_eq!(lantern.rotate.as_ref().map(|k| k[0].value), Some(0.0));
}
