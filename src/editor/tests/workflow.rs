//! The whole loop of making an animation, driven by input events only: open the File menu,
//! type a path, import a PNG, draw two bones, compute weights, pose, key, ease a segment, set
//! a key inside it, play, save with Ctrl+S, reopen. No editor state is set directly.

use super::*;
use crate::anim::edit::TimelineId;

/// The IK drag's keys (time, target) in the document's animation "animation".
fn drag_keys(h: &Harness<'_, EditorApp>) -> Vec<(f64, Point)> {
    let anim = crate::document::animation_named(h.state().doc.state(), "animation");
    anim.ik
        .first()
        .map(|t| t.to.iter().map(|k| (k.time, k.value)).collect())
        .unwrap_or_default()
}

fn press_times(h: &mut Harness<'_, EditorApp>, label: &str, times: usize) {
    for _ in 0..times {
        click_shown(h, label);
    }
}

#[test]
fn import_rig_pose_key_ease_key_inside_play_save_and_reopen() {
    let tmp = crate::test_scratch::scratch("editor-loop");
    let dir = tmp.path();
    let png = bar_png(dir);
    let json = dir.join("bar.json");
    let mut h = harness(EditorApp::new(Document::new()));
    h.run();

    // File menu: type the PNG's path into its field and import it.
    click_shown(&mut h, "File");
    type_into(&mut h, "Rig or PNG path:", &png.display().to_string());
    click_shown(&mut h, "Import layer");
    assert_eq!(
        h.state().doc.state().layers.len(),
        1,
        "{:?}",
        h.state().message
    );

    // Two bones along the bar, the second continuing the first's skeleton.
    click_shown(&mut h, "Bone");
    drag(&mut h, [16.0, 24.0], [48.0, 24.0]);
    drag(&mut h, [48.0, 24.0], [80.0, 24.0]);
    let bones = h.state().doc.state().handles.bones.clone();
    assert_eq!(bones.len(), 2, "{:?}", h.state().message);
    assert_eq!(bones[1].parent.as_deref(), Some(bones[0].name.as_str()));

    click_shown(&mut h, "Compute weights");
    wait_for_weights(&mut h);
    assert!(h.state().doc.posable().is_some(), "{:?}", h.state().message);

    // Animate: drag the bar's end up and key it at 0 s; at 1 s drag it down and key it.
    h.key_press(Key::Num3);
    h.run();
    // (Gripped below the bones' line: a drag that starts on a bone turns the bone.)
    let (up, down) = ([80.0, 22.0], [80.0, 42.0]);
    drag(&mut h, [80.0, 32.0], up);
    click_shown(&mut h, "Set key");
    press_times(&mut h, "Next frame", 24);
    drag(&mut h, up, down);
    click_shown(&mut h, "Set key");
    let keys = drag_keys(&h);
    assert_eq!(keys.len(), 2, "{:?}", h.state().message);
    assert!((keys[1].0 - 1.0).abs() < 1e-9);

    // Set key with nothing changed says so and adds no undo step.
    click_shown(&mut h, "Set key");
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("nothing to key"), "{message}");

    // Ease the segment: select the first key in the dopesheet, make it a Bézier, drag a
    // handle.
    let sheet = h.state().timeline.sheet.clone().expect("the dopesheet");
    let at = sheet
        .key_pos(&TimelineId::Ik { index: 0 }, 0.0)
        .expect("a row for the drag");
    click_screen(&mut h, at);
    assert_eq!(h.state().timeline.selection.len(), 1);
    click_shown(&mut h, "Bézier");
    let layout = h.state().timeline.curve.clone().expect("the curve editor");
    let [first, _] = layout.handles.expect("Bézier handles");
    drag_screen(&mut h, first, first + egui::vec2(40.0, 0.0));
    let eased = crate::document::animation_named(h.state().doc.state(), "animation");
    assert!(
        matches!(eased.ik[0].to[0].curve, crate::anim::Curve::Bezier(_)),
        "{:?}",
        eased.ik[0].to[0].curve
    );

    // The playhead inside the eased segment (0.5 s, via the frame buttons): keying the pose
    // shown there splits the curve (de Casteljau), and the motion stays what it was.
    // (Selecting the key put the playhead on it, at 0 s.)
    assert_eq!(h.state().animate.time_s, 0.0);
    press_times(&mut h, "Next frame", 12);
    assert!((h.state().animate.time_s - 0.5).abs() < 1e-9);
    let options = crate::anim::SampleOptions::default();
    let at = |anim: &crate::anim::Animation, k: usize| {
        anim.sample_with(k as f64 / 20.0, false, &options).ik[0].to
    };
    click_shown(&mut h, "Set key");
    assert_eq!(drag_keys(&h).len(), 3, "{:?}", h.state().message);
    let split = crate::document::animation_named(h.state().doc.state(), "animation");
    for k in 0..=20 {
        let (a, b) = (at(&eased, k), at(&split, k));
        assert!(
            distance(a, b) < 1e-6,
            "at {} s: {a:?} vs {b:?}",
            k as f64 / 20.0
        );
    }

    // Pose inside the other half of the eased segment and key it: accepted too.
    press_times(&mut h, "Next frame", 6);
    let grip = h.state().edited_pose().ik[0].to;
    drag(&mut h, grip, [grip[0] - 6.0, grip[1]]);
    click_shown(&mut h, "Set key");
    let keys = drag_keys(&h);
    assert_eq!(keys.len(), 4, "{:?}", h.state().message);
    assert!((keys[2].0 - 0.75).abs() < 1e-9 && (keys[2].1[0] - (grip[0] - 6.0)).abs() < 0.5);

    // Play: the playhead moves on its own; pause stops it.
    // (A playing editor asks for frame after frame: frames are stepped, not run to rest.)
    press_shown(&mut h, "Play");
    h.step();
    let mut shown = Vec::new();
    for _ in 0..20 {
        h.step();
        shown.push(h.state().animate.time_s);
    }
    shown.sort_by(f64::total_cmp);
    shown.dedup();
    assert!(shown.len() > 2, "playback showed only {shown:?}");
    press_shown(&mut h, "Pause");
    h.step();
    h.run();
    let stopped = h.state().animate.time_s;
    for _ in 0..10 {
        h.step();
    }
    assert_eq!(h.state().animate.time_s, stopped);

    // Ctrl+S: a document never saved asks where; Enter saves.
    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run();
    type_into(&mut h, "Path:", &json.display().to_string());
    h.key_press(Key::Enter);
    h.run();
    wait_for(&mut h, |app| !app.saving());
    assert!(json.is_file(), "{:?}", h.state().message);
    assert!(!h.state().doc.dirty());
    let saved = crate::document::animation_named(h.state().doc.state(), "animation");

    // Reopen it: Ctrl+N, then File → Open recent.
    h.key_press_modifiers(Modifiers::COMMAND, Key::N);
    h.run();
    assert!(h.state().doc.path.is_none());
    click_shown(&mut h, "File");
    // A submenu's button reads "Open recent ⏵".
    click_shown_by(&mut h, By::new().label_contains("Open recent"));
    click_shown(&mut h, &json.display().to_string());
    assert_eq!(h.state().doc.path.as_deref(), Some(json.as_path()));
    assert!(h.state().doc.posable().is_some());
    assert_eq!(
        crate::document::animation_named(h.state().doc.state(), "animation"),
        saved
    );
}
