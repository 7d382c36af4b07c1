//! Animate mode's events: defining an event, adding it at the playhead, its payload edited
//! from the dopesheet's events row, moved and undone, saved and read back.

use super::*;
use crate::anim::edit::TimelineId;

/// (time, name, int, float, string) of the edited animation's events, as the document holds them.
fn events(h: &Harness<'_, EditorApp>) -> Vec<(f64, String, Option<i32>, Option<String>)> {
    let anim =
        crate::document::animation_named(h.state().doc.state(), &h.state().animate.animation);
    anim.events
        .iter()
        .map(|k| (k.time, k.name.clone(), k.int, k.string.clone()))
        .collect()
}

fn event_on_sheet(h: &Harness<'_, EditorApp>, time_s: f64) -> Pos2 {
    h.state()
        .timeline
        .sheet
        .as_ref()
        .expect("the dopesheet was drawn")
        .key_pos(&TimelineId::Events, time_s)
        .expect("an events row")
}

/// Through the *Define event* window: event `name` with default int `int`.
fn define_event(h: &mut Harness<'_, EditorApp>, name: &str, int: i32) {
    click_shown(h, "Define event…");
    type_into(h, "New event name:", name);
    set_number(h, "Default int", f64::from(int));
    click_shown(h, "Define");
}

#[test]
fn an_event_key_is_defined_added_edited_moved_and_saved() {
    let mut h = open_character("events");
    h.key_press(Key::Num3);
    h.run();
    click_shown(&mut h, "New animation");
    define_event(&mut h, "footstep", 1);
    let defs = h.state().doc.state().events.clone();
    assert_eq!(
        defs.get("footstep").map(|d| d.int),
        Some(1),
        "{:?}",
        h.state().message
    );
    assert!(
        h.query_by_label("New event name:").is_none(),
        "the window stayed open"
    );
    // A taken name is refused with the document's message.
    define_event(&mut h, "footstep", 2);
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("already defined"), "{message}");
    assert_eq!(h.state().doc.state().events["footstep"].int, 1);
    // The window stays open with the refused name; its close button closes it, and *Define
    // event…* (no longer under it) opens it again.
    assert_eq!(
        h.get_by_label("New event name:").value().as_deref(),
        Some("footstep")
    );
    click_shown(&mut h, "Close window");
    assert!(
        h.query_by_label("New event name:").is_none(),
        "the close button left the window open"
    );
    define_event(&mut h, "cue", 0);
    if h.query_by_label("New event name:").is_some() {
        panic!("{:?}", h.state().message);
    }

    // Twelve frames on (0.5 s at 24 fps), the event picked is added at the playhead.
    for _ in 0..12 {
        click_shown(&mut h, "Next frame");
    }
    click_shown_by(&mut h, combo_box("Event to add"));
    click_shown(&mut h, "footstep");
    click_shown(&mut h, "Add event");
    assert_eq!(
        events(&h),
        [(0.5, "footstep".to_string(), None, None)],
        "{:?}",
        h.state().message
    );

    // Select it in the dopesheet's events row (after clicks on the ruler and on the row's
    // empty part took the playhead and the selection away): its payload shows beside the
    // dopesheet.
    let sheet = h.state().timeline.sheet.clone().expect("sheet");
    let names = sheet.names.clone();
    assert!(names.contains(&"events".to_string()), "{names:?}");
    click_screen(&mut h, Pos2::new(sheet.x_of(1.0), sheet.ruler.center().y));
    let row_y = event_on_sheet(&h, 0.5).y;
    click_screen(&mut h, Pos2::new(sheet.x_of(1.5), row_y));
    assert!(h.state().timeline.selection.is_empty());
    assert!(h.query_by_label("Event int").is_none());
    let at = event_on_sheet(&h, 0.5);
    click_screen(&mut h, at);
    assert!((h.state().animate.time_s - 0.5).abs() < 1e-9);
    set_number(&mut h, "Event int", 3.0);
    type_into(&mut h, "Event string", "left");
    h.key_press(Key::Enter);
    h.run();
    assert_eq!(
        events(&h),
        [(
            0.5,
            "footstep".to_string(),
            Some(3),
            Some("left".to_string())
        )],
        "{:?}",
        h.state().message
    );
    // The audio path is the definition's.
    type_into(&mut h, "Audio path", "sfx/step.wav");
    h.key_press(Key::Enter);
    h.run();
    assert_eq!(
        h.state().doc.state().events["footstep"].audio.as_deref(),
        Some("sfx/step.wav"),
        "{:?}",
        h.state().message
    );
    // A float beyond the limit is refused with a message; the key keeps its payload.
    type_into(&mut h, "Event float", "2e6");
    h.key_press(Key::Enter);
    h.run();
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("within ±1e6"), "{message}");
    let anim =
        crate::document::animation_named(h.state().doc.state(), &h.state().animate.animation);
    assert_eq!(anim.events[0].float, None);

    // Another name picked from the definitions, then undone (one step each).
    click_shown_by(&mut h, combo_box("Event name"));
    click_shown(&mut h, "cue");
    assert_eq!(events(&h)[0].1, "cue", "{:?}", h.state().message);
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(events(&h)[0].1, "footstep");

    // Dragged to 0.75 s in the dopesheet, then back with Ctrl+Z.
    let sheet = h.state().timeline.sheet.clone().expect("sheet");
    let from = event_on_sheet(&h, 0.5);
    drag_screen(&mut h, from, Pos2::new(sheet.x_of(0.75), from.y));
    assert_eq!(events(&h)[0].0, 0.75, "{:?}", h.state().message);
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(events(&h)[0].0, 0.5);

    // Saved with Ctrl+S and read back: the key and the definitions are in the file.
    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run();
    wait_for(&mut h, |app| !app.saving());
    assert!(!h.state().doc.dirty(), "{:?}", h.state().message);
    let path = h
        .state()
        .doc
        .path
        .clone()
        .expect("saved where it was opened");
    let saved = crate::io::RigDocument::load(&path).expect("the saved file loads");
    saved
        .check_animations()
        .expect("its animations fit the rig");
    let key = &saved.animations[&h.state().animate.animation].events[0];
    assert_eq!(
        (key.time, key.name.as_str(), key.int, key.string.as_deref()),
        (0.5, "footstep", Some(3), Some("left"))
    );
    let def = &saved.events["footstep"];
    assert_eq!((def.int, def.audio.as_deref()), (1, Some("sfx/step.wav")));
    assert!(saved.events.contains_key("cue"));
}
