//! The selection across mode switches, driven by input events only: clicks on the tree's rows
//! and the canvas, the mode keys, Ctrl+Z.

use super::*;

/// Whether the middle of the widget labelled `label` (where a click reaches it) lies in the
/// part of the side panel the window shows: below the menu bar (the canvas area's top), above
/// the status bar and above animate mode's timeline where it spans under the side panel.
fn in_view(h: &Harness<'_, EditorApp>, label: &str) -> bool {
    let top = h.state().placed.expect("the canvas was drawn").origin.y;
    let rect = h.get_by_label(label).rect();
    let mut bottom = h.get_by_label_contains(" layers, ").rect().top();
    let timeline = format!("Animation '{}'", h.state().animate.animation);
    if let Some(timeline) = h.query_by_label(&timeline).map(|t| t.rect()) {
        if timeline.left() < rect.right() {
            bottom = bottom.min(timeline.top());
        }
    }
    (top..=bottom).contains(&rect.center().y)
}

/// What the UI shows selected: the tree's highlighted row, in view, and, in pose and animate
/// mode, the numbers panel's line; in rig mode the "Selected:" line. `None` for colorize mode
/// (no tree).
fn shown_selection(h: &Harness<'_, EditorApp>, bone: &str) -> Option<bool> {
    let tree = tree_selected(h, bone) && in_view(h, bone);
    match h.state().mode {
        Mode::Pose | Mode::Animate => {
            Some(tree && h.query_by_label(&format!("Bone '{bone}'")).is_some())
        }
        Mode::Rig => Some(tree && h.query_by_label(&format!("Selected: {bone}")).is_some()),
        Mode::Colorize => None,
    }
}

#[test]
fn the_selection_stays_across_mode_switches_while_its_handle_exists() {
    let mut h = open_character("keep-selection");
    // Pose mode: the lantern picked in the tree is highlighted there, its numbers shown.
    h.key_press(Key::Num2);
    h.run();
    click_label(&mut h, "lantern");
    assert_eq!(shown_selection(&h, "lantern"), Some(true));

    // Every mode and back again, by key: the lantern stays selected wherever a tree shows.
    for (key, mode) in [
        (Key::Num3, Mode::Animate),
        (Key::Num2, Mode::Pose),
        (Key::Num3, Mode::Animate),
        (Key::Num1, Mode::Rig),
        (Key::Num4, Mode::Colorize),
        (Key::Num3, Mode::Animate),
        (Key::Num2, Mode::Pose),
    ] {
        h.key_press(key);
        h.run();
        assert_eq!(h.state().mode, mode);
        if mode != Mode::Colorize {
            assert_eq!(
                shown_selection(&h, "lantern"),
                Some(true),
                "after switching to {mode:?}: selected {:?}",
                h.state().selected
            );
        }
    }
    // The mode buttons of the menu bar too.
    for label in ["Animate mode", "Rig mode", "Pose mode"] {
        click_shown(&mut h, label);
        assert_eq!(shown_selection(&h, "lantern"), Some(true), "after {label}");
    }

    // A point added in rig mode (the Point tool, a click on the canvas) is selected; undone in
    // pose mode, it is gone, and so is the selection: no mode shows a handle that does not exist.
    h.key_press(Key::Num1);
    h.run();
    click_shown(&mut h, "Point");
    click(&mut h, Point::new(40.0, 40.0));
    let added = h
        .state()
        .selected
        .clone()
        .expect("the new point is selected");
    assert!(h.query_by_label(&format!("Selected: {added}")).is_some());
    h.key_press(Key::Num2);
    h.run();
    assert!(h.query_by_label(&format!("Point '{added}'")).is_some());
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert!(h.query_by_label(&added).is_none(), "the point was undone");
    for key in [Key::Num3, Key::Num1] {
        h.key_press(key);
        h.run();
        assert!(
            h.query_by_label(&format!("Selected: {added}")).is_none()
                && h.query_by_label(&format!("Point '{added}'")).is_none(),
            "{:?} shows the undone point selected",
            h.state().mode
        );
        assert_eq!(h.state().selected, None);
    }
}
