//! Animate mode's timeline: keys, scrubbing, the dopesheet (select, move, copy, paste, curves,
//! undo, the keyboard) and playback with onion skins.

use super::*;

#[test]
fn set_two_keys_and_scrub_the_timeline() {
    let mut h = open_character("animate");
    h.key_press(Key::Num3);
    h.run();
    assert_eq!(h.state().mode, Mode::Animate);
    let grip = torso_point(&h);
    let first = [grip[0] + 20.0, grip[1] - 10.0];
    drag(&mut h, grip, first);
    assert_eq!(
        h.state().edited_pose().ik.len(),
        1,
        "{:?}",
        h.state().message
    );
    click_shown(&mut h, "Set key");
    for _ in 0..24 {
        click_shown(&mut h, "Next frame");
    }
    assert!(
        (h.state().animate.time_s - 1.0).abs() < 1e-9,
        "{}",
        h.state().animate.time_s
    );
    // Grab the pin where the first key left it and move it to the other side.
    let second = [grip[0] - 20.0, grip[1] - 10.0];
    drag(&mut h, first, second);
    click_shown(&mut h, "Set key");
    let anim = crate::document::animation_named(h.state().doc.state(), "animation");
    assert_eq!(crate::document::key_times(&anim), vec![0.0, 1.0]);
    for _ in 0..12 {
        click_shown(&mut h, "Previous frame");
    }
    let halfway = h.state().edited_pose();
    assert_eq!(halfway.ik.len(), 1);
    assert!(
        distance(halfway.ik[0].to, [grip[0], grip[1] - 10.0]) < 1.0,
        "{:?}",
        halfway.ik[0].to
    );
    // The canvas shows that pose: the posed mesh was solved for it.
    assert_eq!(
        h.state().pose_mode.posed.as_ref().expect("posed").pose,
        halfway
    );
    // Setting keys is undoable like any edit.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    let anim = crate::document::animation_named(h.state().doc.state(), "animation");
    assert_eq!(crate::document::key_times(&anim), vec![0.0]);
}

#[test]
fn dopesheet_select_move_copy_paste_curve_and_undo() {
    use crate::anim::edit::{KeyRef, TransformChannel::*};
    let mut h = open_character("dopesheet");
    h.key_press(Key::Num3);
    h.run();
    key_a_nod_from_the_numbers_panel(&mut h);
    assert_eq!(h.state().animate.animation, "nod");
    assert!(h.state().doc.state().animations.contains_key("nod"));
    assert_eq!(
        head_rotate_keys(&h),
        vec![
            (0.0, 0.0, serde_json::Value::Null),
            (0.5, 20.0, serde_json::Value::Null)
        ],
        "{:?}",
        h.state().message
    );
    assert_eq!(times_of(&h, Translate), vec![0.0, 0.5]);

    // Select the rotate key at 0.5 s: the playhead goes there.
    let at = key_on_sheet(&h, Rotate, 0.5);
    click_screen(&mut h, at);
    let selected = KeyRef {
        timeline: head(Rotate),
        time_s: 0.5,
    };
    assert_eq!(h.state().timeline.selection, vec![selected.clone()]);
    assert!((h.state().animate.time_s - 0.5).abs() < 1e-9);

    // Drag it to 0.75 s (a little off: it snaps to the frame); only that channel moves.
    let sheet = h.state().timeline.sheet.clone().expect("sheet");
    let to = Pos2::new(
        sheet.x_of(0.75) + 0.2 * sheet.px_per_s / 24.0,
        sheet.rows[0].1,
    );
    let from = key_on_sheet(&h, Rotate, 0.5);
    drag_screen(&mut h, from, to);
    let rotate = head_rotate_keys(&h);
    assert_eq!(rotate.len(), 2, "{:?}", h.state().message);
    assert!((rotate[1].0 - 0.75).abs() < 1e-9, "{rotate:?}");
    assert_eq!(rotate[1].1, 20.0);
    assert_eq!(times_of(&h, Translate), vec![0.0, 0.5]);
    assert!((h.state().timeline.selection[0].time_s - 0.75).abs() < 1e-9);

    // Copy it, put the playhead at 1 s on the ruler, paste: a 20° key at 1 s.
    click_shown(&mut h, "Copy keys");
    let ruler_y = sheet.ruler.center().y;
    click_screen(&mut h, Pos2::new(sheet.x_of(1.0), ruler_y));
    assert!(
        (h.state().animate.time_s - 1.0).abs() < 1e-9,
        "{}",
        h.state().animate.time_s
    );
    click_shown(&mut h, "Paste keys");
    let rotate = head_rotate_keys(&h);
    assert_eq!(rotate.len(), 3, "{:?}", h.state().message);
    assert!(
        (rotate[2].0 - 1.0).abs() < 1e-9 && rotate[2].1 == 20.0,
        "{rotate:?}"
    );

    // Select the first key and make its segment a Bézier: handles at the thirds.
    let at = key_on_sheet(&h, Rotate, 0.0);
    click_screen(&mut h, at);
    assert_eq!(h.state().timeline.selection.len(), 1);
    click_shown(&mut h, "Bézier");
    let curve = head_rotate_keys(&h)[0].2.clone();
    let numbers: Vec<f64> = serde_json::from_value(curve.clone()).expect("a Bézier: {curve}");
    let expected = [0.25, 20.0 / 3.0, 0.5, 40.0 / 3.0];
    assert!(
        numbers
            .iter()
            .zip(expected)
            .all(|(a, b)| (a - b).abs() < 1e-9),
        "{numbers:?}"
    );

    // Drag the first handle down and right: one more undo step, the handle stays in the segment.
    let layout = h.state().timeline.curve.clone().expect("the curve editor");
    let [first, _] = layout.handles.expect("Bézier handles");
    drag_screen(&mut h, first, first + egui::vec2(30.0, 25.0));
    let dragged: Vec<f64> =
        serde_json::from_value(head_rotate_keys(&h)[0].2.clone()).expect("still a Bézier");
    assert!(dragged[0] > numbers[0] + 1e-3, "{dragged:?}");
    assert!(dragged[1] < numbers[1] - 1e-3, "{dragged:?}");
    assert!(
        dragged[0] <= 0.75 && dragged[2..] == numbers[2..],
        "{dragged:?}"
    );

    // Undo, step by step, back to the two keys as set.
    let undo = |h: &mut Harness<'_, EditorApp>| {
        h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
        h.run();
    };
    undo(&mut h);
    assert_eq!(head_rotate_keys(&h)[0].2, curve);
    undo(&mut h);
    assert_eq!(head_rotate_keys(&h)[0].2, serde_json::Value::Null);
    undo(&mut h);
    assert_eq!(head_rotate_keys(&h).len(), 2);
    undo(&mut h);
    assert_eq!(times_of(&h, Rotate), vec![0.0, 0.5]);

    // Box-select the column at 0.5 s (all four channels) and delete it with the Delete key.
    let sheet = h.state().timeline.sheet.clone().expect("sheet");
    let (top, bottom) = (
        sheet.rows.first().expect("rows").1 - 8.0,
        sheet.rows.last().expect("rows").1 + 8.0,
    );
    drag_screen(
        &mut h,
        Pos2::new(sheet.x_of(0.5) - 10.0, top),
        Pos2::new(sheet.x_of(0.5) + 10.0, bottom),
    );
    assert_eq!(h.state().timeline.selection.len(), 4);
    h.key_press(Key::Delete);
    h.run();
    for channel in [Rotate, Translate, Scale, Shear] {
        assert_eq!(times_of(&h, channel), vec![0.0]);
    }
    assert!(
        h.state().doc.state().handles.names().any(|n| n == "head"),
        "Delete took the keys, not a handle"
    );
    undo(&mut h);
    assert_eq!(times_of(&h, Shear), vec![0.0, 0.5]);
}

#[test]
fn playback_steps_frames_loops_or_stops_and_onion_skins_show_neighbours() {
    let (dir, path) = character_with_nod("playback");
    let mut h = opened_in(dir, &path);
    h.run();
    h.key_press(Key::Num3);
    h.run();
    click_shown(&mut h, "nod");
    assert_eq!(h.state().animate.animation, "nod");
    let fps = h.state().render_settings.fps;
    let on_frame = |t: f64| ((t * fps) - (t * fps).round()).abs() < 1e-6;
    // Play (a click; the playing editor asks for frame after frame, so frames are stepped).
    press_shown(&mut h, "Play");
    h.step();
    let mut wrapped = false;
    let mut last = 0.0;
    for _ in 0..240 {
        h.step();
        let t = h.state().animate.time_s;
        assert!(on_frame(t) && t < 0.5 - 1e-9, "{t}");
        wrapped |= t < last;
        last = t;
    }
    assert!(wrapped, "playback never looped");
    // Without looping it stops on the last key.
    press_shown(&mut h, "Pause");
    h.step();
    h.run();
    click_shown(&mut h, "Loop");
    assert!(!h.state().timeline.looping);
    press_shown(&mut h, "Play");
    h.step();
    for _ in 0..240 {
        h.step();
        if h.query_by_label("Play").is_some() {
            break;
        }
    }
    h.run();
    h.get_by_label("Play");
    assert!((h.state().animate.time_s - 0.5).abs() < 1e-9);
    // Playing again from the end starts over (Space plays and pauses too).
    // (The harness' clock moves a quarter second a frame: the press's frame shows the
    // rewind, the release's frame has played on.)
    h.key_down(Key::Space);
    h.step();
    assert_eq!(h.state().animate.time_s, 0.0);
    assert!(h.state().animate.playing);
    h.key_up(Key::Space);
    h.step();
    assert!(h.state().animate.time_s > 0.0);
    h.key_press(Key::Space);
    h.step();
    h.run();
    h.get_by_label("Play");

    // Onion skins: at the end only earlier frames exist; in the middle both sides.
    let frames_to =
        |h: &Harness<'_, EditorApp>, t: f64| ((t - h.state().animate.time_s) * fps).round() as i64;
    let steps = frames_to(&h, 0.5);
    let button = if steps > 0 {
        "Next frame"
    } else {
        "Previous frame"
    };
    for _ in 0..steps.abs() {
        click_shown(&mut h, button);
    }
    assert!((h.state().animate.time_s - 0.5).abs() < 1e-9);
    click_shown(&mut h, "Onion skin");
    let scene = h.state().doc.posable().expect("posable").clone();
    let placed = h.state().placed.expect("placed");
    let at_end = h.state_mut().onion_shapes(&scene, &placed);
    for _ in 0..frames_to(&h, 0.25).abs() {
        click_shown(&mut h, "Previous frame");
    }
    assert!((h.state().animate.time_s - 0.25).abs() < 1e-9);
    let middle = h.state_mut().onion_shapes(&scene, &placed);
    assert!(!at_end.is_empty());
    assert_eq!(
        middle.len(),
        2 * at_end.len(),
        "two frames each side vs two before"
    );
    click_shown(&mut h, "Onion skin");
    assert!(h.state_mut().onion_shapes(&scene, &placed).is_empty());
}

#[test]
fn keyboard_copy_paste_and_shift_click_in_the_dopesheet() {
    use crate::anim::edit::{KeyRef, TransformChannel::*};
    let mut h = open_character("keyboard");
    key_nod(h.state_mut(), &[(0.0, 0.0), (0.5, 30.0)]);
    h.key_press(Key::Num3);
    h.run();
    click_shown(&mut h, "nod");
    // Click one key, shift-click another: both selected; shift-click again: deselected.
    let at = key_on_sheet(&h, Rotate, 0.5);
    click_screen(&mut h, at);
    let translate = key_on_sheet(&h, Translate, 0.5);
    // One frame per event: shift down, press, release, shift up.
    h.event(egui::Event::ModifiersChanged(Modifiers::SHIFT));
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos: translate,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Modifiers::SHIFT,
        });
    }
    h.event(egui::Event::ModifiersChanged(Modifiers::NONE));
    h.step();
    h.run();
    let selection = &h.state().timeline.selection;
    assert_eq!(selection.len(), 2, "{selection:?}");
    assert!(selection.contains(&KeyRef {
        timeline: head(Translate),
        time_s: 0.5
    }));
    assert!(
        (h.state().animate.time_s - 0.5).abs() < 1e-9,
        "a plain click moves the playhead to its key"
    );
    // Ctrl+C, playhead to 1 s, Ctrl+V: both keys pasted at 1 s.
    h.key_press_modifiers(Modifiers::COMMAND, Key::C);
    h.run();
    assert_eq!(h.state().timeline.clipboard.len(), 2);
    // A click on the ruler at 1 s moves the playhead there.
    let sheet = h.state().timeline.sheet.clone().expect("the dopesheet");
    click_screen(&mut h, Pos2::new(sheet.x_of(1.0), sheet.ruler.center().y));
    assert!((h.state().animate.time_s - 1.0).abs() < 1e-9);
    h.key_press_modifiers(Modifiers::COMMAND, Key::V);
    h.run();
    assert_eq!(times_of(&h, Rotate), vec![0.0, 0.5, 1.0]);
    assert_eq!(times_of(&h, Translate), vec![0.0, 0.5, 1.0]);
    assert_eq!(times_of(&h, Scale), vec![0.0, 0.5], "not copied");
    assert_eq!(head_rotate_keys(&h)[2].1, 30.0);
    // The pasted keys are the selection now; Delete removes exactly them.
    h.key_press(Key::Delete);
    h.run();
    assert_eq!(times_of(&h, Rotate), vec![0.0, 0.5]);
    assert_eq!(times_of(&h, Translate), vec![0.0, 0.5]);
}

/// A rig made for Spine (`sinew target`, saved in the document) plays in animate mode as
/// Spine's runtime evaluates its curves, and the timeline says so.
#[test]
fn a_rig_made_for_spine_previews_spine_curves_and_says_so() {
    let (dir, path) = character_rig("target");
    let mut doc = crate::io::RigDocument::load(&path).expect("loads");
    doc.target = Some(crate::io::RuntimeTarget::Spine42);
    doc.save(&path).expect("saved");
    let mut h = opened_in(dir, &path);
    h.run();
    h.key_press(Key::Num3);
    h.run();
    assert_eq!(h.state().mode, Mode::Animate);
    h.get_by_label("Plays as Spine 4.2 (its curves)");
    // Key a pose, then step: the playhead poses the animation.
    let grip = torso_point(&h);
    drag(&mut h, grip, [grip[0] + 20.0, grip[1] - 10.0]);
    click_shown(&mut h, "Set key");
    click_shown(&mut h, "Next frame");
    let played = h
        .state()
        .pose_mode
        .posed
        .as_ref()
        .and_then(|p| p.played.as_ref())
        .expect("posed at the playhead");
    assert_eq!(
        played.options.sampling.curves,
        crate::anim::CurveEvaluation::SpineRuntime
    );
}
