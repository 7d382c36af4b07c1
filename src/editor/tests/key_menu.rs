//! The dopesheet's context menu, driven by input events only: a right click selects and opens
//! the menu; its entries set curves (one undo step), copy, paste at the playhead and delete.

use super::*;
use crate::anim::edit::TransformChannel::*;

/// A right click (press and release of the secondary button) at `at`, screen points.
fn right_click_screen(h: &mut Harness<'_, EditorApp>, at: Pos2) {
    h.hover_at(at);
    h.step();
    for pressed in [true, false] {
        h.input_mut().events.push(egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Secondary,
            pressed,
            modifiers: Modifiers::NONE,
        });
        h.step();
    }
    h.run();
}

/// The curve of the head's `channel` key at `time_s` in "nod", as stored.
fn curve_at(h: &Harness<'_, EditorApp>, channel: &str, time_s: f64) -> serde_json::Value {
    let anim = crate::document::animation_named(h.state().doc.state(), "nod");
    let json = serde_json::to_value(anim).expect("an animation writes as JSON");
    let keys = json["bones"]["head"][channel]
        .as_array()
        .cloned()
        .unwrap_or_default();
    let key = keys
        .iter()
        .find(|k| (k["time"].as_f64().unwrap_or(0.0) - time_s).abs() < 1e-9);
    let key = key.unwrap_or_else(|| panic!("a {channel} key at {time_s} s: {keys:?}"));
    key.get("curve").cloned().unwrap_or(serde_json::Value::Null)
}

#[test]
fn a_right_click_on_keys_opens_a_menu_that_sets_curves_copies_pastes_and_deletes() {
    let mut h = open_character("key-menu");
    h.key_press(Key::Num3);
    h.run();
    // The head keyed at 0° at 0 s and 20° at 0.5 s: every transform channel has two keys.
    key_a_nod_from_the_numbers_panel(&mut h);
    let channels = ["rotate", "translate", "scale", "shear"];

    // A right click on the "all keys" row at 0 s selects every key there; "Stepped" sets all
    // their curves, one undo step takes them all back.
    let sheet = h.state().timeline.sheet.clone().expect("the dopesheet");
    right_click_screen(&mut h, egui::pos2(sheet.x_of(0.0), sheet.summary_y));
    assert_eq!(
        h.state().timeline.selection.len(),
        4,
        "one key per channel at 0 s"
    );
    click_shown(&mut h, "Stepped");
    for channel in channels {
        assert_eq!(
            curve_at(&h, channel, 0.0),
            serde_json::json!("stepped"),
            "{channel}"
        );
    }
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    for channel in channels {
        assert_eq!(
            curve_at(&h, channel, 0.0),
            serde_json::Value::Null,
            "{channel}"
        );
    }

    // A right click on a selected key keeps the selection; after a click on the rotate key
    // alone, the menu's ease sets only its handles, level with its keys at the thirds of the
    // segment; the other channels keep their curves.
    let at = key_on_sheet(&h, Rotate, 0.0);
    right_click_screen(&mut h, at);
    assert_eq!(h.state().timeline.selection.len(), 4);
    h.key_press(Key::Escape);
    h.run();
    click_screen(&mut h, at);
    // One key selected, the curve editor opens beside the sheet: the key is found again.
    let at = key_on_sheet(&h, Rotate, 0.0);
    right_click_screen(&mut h, at);
    assert_eq!(h.state().timeline.selection.len(), 1);
    click_shown(&mut h, "Bézier ease in and out");
    let numbers: Vec<f64> =
        serde_json::from_value(curve_at(&h, "rotate", 0.0)).expect("four Bézier numbers");
    let expected = [0.5 / 3.0, 0.0, 1.0 / 3.0, 20.0];
    assert!(
        numbers
            .iter()
            .zip(expected)
            .all(|(a, b)| (a - b).abs() < 1e-6),
        "{numbers:?}"
    );
    assert_eq!(curve_at(&h, "translate", 0.0), serde_json::Value::Null);

    // Copied from the menu, pasted from it at the playhead (frame 6, 0.25 s), deleted from it.
    let at = key_on_sheet(&h, Rotate, 0.5);
    right_click_screen(&mut h, at);
    click_shown(&mut h, "Copy");
    for _ in 0..6 {
        click_shown(&mut h, "Next frame");
    }
    let at = key_on_sheet(&h, Rotate, 0.0);
    right_click_screen(&mut h, at);
    click_shown(&mut h, "Paste at the playhead");
    let rotate_times = |h: &Harness<'_, EditorApp>| -> Vec<f64> {
        head_rotate_keys(h).iter().map(|k| k.0).collect()
    };
    assert_eq!(rotate_times(&h), [0.0, 0.25, 0.5]);
    assert_eq!(head_rotate_keys(&h)[1].1, 20.0, "the copied key's value");
    let at = key_on_sheet(&h, Rotate, 0.25);
    right_click_screen(&mut h, at);
    click_shown(&mut h, "Delete");
    assert_eq!(rotate_times(&h), [0.0, 0.5]);
}
