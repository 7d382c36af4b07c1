//! The dopesheet's rows for attachment swaps and deform keys: keys moved, copied, pasted,
//! deleted as on the other rows; stepped rows without a curve, deform rows with one.

use super::*;
use crate::anim::edit::TimelineId;

fn key_at(h: &Harness<'_, EditorApp>, timeline: &TimelineId, time_s: f64) -> Pos2 {
    h.state()
        .timeline
        .sheet
        .as_ref()
        .expect("the dopesheet was drawn")
        .key_pos(timeline, time_s)
        .expect("a row for the timeline")
}

#[test]
fn attachment_keys_move_copy_paste_and_delete_in_their_row() {
    let (mut h, animation) = new_animation_on_skinned_character("attachment-row");
    let keys = |h: &Harness<'_, EditorApp>| bag_attachment_keys(h, &animation);
    click_label(&mut h, "bag shows bag_pail");
    assert_eq!(keys(&h), [(0.0, Some("bag_pail".into()))]);
    let row = TimelineId::Attachment { slot: "bag".into() };
    let sheet = h.state().timeline.sheet.clone().expect("sheet");
    assert!(
        sheet.names.contains(&"bag attachment".to_string()),
        "{:?}",
        sheet.names
    );

    // Select the key: a stepped row has no curve to edit.
    let at = key_at(&h, &row, 0.0);
    click_screen(&mut h, at);
    assert_eq!(h.state().timeline.selection.len(), 1);
    h.get_by_label_contains("only steps from key to key");
    assert!(h.query_by_label("Bézier").is_none());

    // Dragged to 0.25 s (snapped to its frame).
    drag_screen(&mut h, at, Pos2::new(sheet.x_of(0.25) + 1.0, at.y));
    assert_eq!(
        keys(&h),
        [(0.25, Some("bag_pail".into()))],
        "{:?}",
        h.state().message
    );

    // Copied, pasted at 1 s (playhead put there on the ruler), then the pasted key deleted.
    h.key_press_modifiers(Modifiers::COMMAND, Key::C);
    h.run();
    click_screen(&mut h, Pos2::new(sheet.x_of(1.0), sheet.ruler.center().y));
    h.key_press_modifiers(Modifiers::COMMAND, Key::V);
    h.run();
    assert_eq!(
        keys(&h),
        [
            (0.25, Some("bag_pail".into())),
            (1.0, Some("bag_pail".into()))
        ],
        "{:?}",
        h.state().message
    );
    assert_eq!(h.state().timeline.selection.len(), 1);
    h.key_press(Key::Delete);
    h.run();
    assert_eq!(keys(&h), [(0.25, Some("bag_pail".into()))]);
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(keys(&h).len(), 2);
}

/// The character with animation "squash": the torso's mesh deformed, keys at 0 and 0.5 s.
fn character_with_squash(name: &str) -> (TempDir, PathBuf, usize) {
    let (dir, path) = character_rig(name);
    let mut doc = crate::io::RigDocument::load(&path).expect("loads");
    let vertices = doc
        .parts
        .iter()
        .find(|p| p.name == "torso")
        .expect("a torso")
        .mesh
        .vertices
        .len();
    let squash: Vec<[f64; 2]> = (0..vertices).map(|i| [0.0, (i % 3) as f64]).collect();
    let json = serde_json::json!({"squash": {"deform": {"torso": [
        {"time": 0, "value": vec![[0.0, 0.0]; vertices]},
        {"time": 0.5, "value": squash}]}}});
    doc.animations = crate::anim::animations_from_json(&json).expect("an animation");
    doc.save(&path).expect("saved");
    (dir, path, vertices)
}

#[test]
fn deform_keys_have_a_row_with_curves_and_move_copy_and_paste() {
    let (dir, path, vertices) = character_with_squash("deform-row");
    let mut h = opened_in(dir, &path);
    h.run();
    h.key_press(Key::Num3);
    h.run();
    assert_eq!(h.state().animate.animation, "squash");
    let row = TimelineId::Deform {
        part: "torso".into(),
    };
    let sheet = h.state().timeline.sheet.clone().expect("sheet");
    assert_eq!(sheet.names, ["torso deform"]);
    let deform = |h: &Harness<'_, EditorApp>| {
        crate::document::animation_named(h.state().doc.state(), "squash").deform["torso"].clone()
    };

    // Its first key eases into the second: one 0..1 Bézier for all the offsets.
    let at = key_at(&h, &row, 0.0);
    click_screen(&mut h, at);
    click_shown(&mut h, "Bézier");
    let eased = deform(&h);
    assert_eq!(
        eased[0].curve,
        crate::anim::Curve::Bezier(vec![0.5 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 2.0 / 3.0]),
        "{:?}",
        h.state().message
    );

    // The second key dragged to 0.75 s, copied and pasted at 1.5 s (the curve's graph made
    // the panel taller: the dopesheet is read again).
    let sheet = h.state().timeline.sheet.clone().expect("sheet");
    let at = key_at(&h, &row, 0.5);
    drag_screen(&mut h, at, Pos2::new(sheet.x_of(0.75), at.y));
    let moved = deform(&h);
    assert_eq!(moved[1].time, 0.75, "{:?}", h.state().message);
    assert_eq!(moved[1].value, eased[1].value);
    assert_eq!(
        h.state().timeline.selection,
        [crate::anim::edit::KeyRef {
            timeline: row.clone(),
            time_s: 0.75
        }]
    );
    h.key_press_modifiers(Modifiers::COMMAND, Key::C);
    h.run();
    assert_eq!(
        h.state().timeline.clipboard.len(),
        1,
        "{:?}",
        h.state().message
    );
    click_screen(&mut h, Pos2::new(sheet.x_of(1.5), sheet.ruler.center().y));
    h.key_press_modifiers(Modifiers::COMMAND, Key::V);
    h.run();
    let pasted = deform(&h);
    assert_eq!(pasted.len(), 3, "{:?}", h.state().message);
    assert_eq!((pasted[2].time, pasted[2].value.len()), (1.5, vertices));
    assert_eq!(pasted[2].value, eased[1].value);
}

#[test]
fn delete_key_removes_every_kind_of_key_at_the_playhead() {
    let (mut h, animation) = new_animation_on_skinned_character("delete-key");
    // An attachment swap at 0 s, through the tree.
    click_label(&mut h, "bag shows bag_pail");
    assert_eq!(
        bag_attachment_keys(&h, &animation),
        [(0.0, Some("bag_pail".into()))]
    );
    let keyed = |h: &Harness<'_, EditorApp>| {
        let anim = crate::document::animation_named(h.state().doc.state(), &animation);
        crate::anim::edit::timelines(&anim).len()
    };
    assert_eq!(keyed(&h), 1, "{:?}", h.state().message);
    // *Delete key* takes every key at the playhead, the swap included, as one undo step.
    click_shown(&mut h, "Delete key");
    assert!(bag_attachment_keys(&h, &animation).is_empty());
    assert_eq!(keyed(&h), 0);
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(bag_attachment_keys(&h, &animation).len(), 1);
    assert_eq!(keyed(&h), 1);
}
