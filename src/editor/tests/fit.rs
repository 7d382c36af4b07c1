//! The fitted view following the canvas area across modes, and the user's own view kept,
//! driven by input events only (mode keys, a middle-button drag, Home, the View menu).

use super::*;

/// The screen box (points) of the character's rest mesh, every part's vertices projected with
/// the view the canvas was drawn with.
fn character_box(h: &Harness<'_, EditorApp>) -> egui::Rect {
    let placed = h.state().placed.expect("the canvas was drawn");
    let scene = h.state().doc.posable().expect("posable").clone();
    let shown: Vec<Pos2> = scene
        .doc
        .parts
        .iter()
        .flat_map(|p| p.mesh.vertices.iter())
        .map(|&v| placed.screen_from_canvas(v))
        .collect();
    egui::Rect::from_points(&shown)
}

/// The canvas area (the picture's rectangle), points.
fn canvas_area(h: &Harness<'_, EditorApp>) -> egui::Rect {
    h.state().drawing.picture.as_ref().expect("a picture").rect
}

fn assert_character_in_view(h: &Harness<'_, EditorApp>, when: &str) {
    let (shown, area) = (character_box(h), canvas_area(h));
    assert!(
        area.contains_rect(shown),
        "{when}: the character spans {shown:?}, the canvas area is {area:?}"
    );
}

/// A middle-button drag over the canvas by `by` points (a pan), one frame per event.
fn middle_drag(h: &mut Harness<'_, EditorApp>, by: egui::Vec2) {
    let from = canvas_area(h).center();
    let button = |pos, pressed| egui::Event::PointerButton {
        pos,
        button: egui::PointerButton::Middle,
        pressed,
        modifiers: Modifiers::NONE,
    };
    h.hover_at(from);
    h.step();
    h.event(button(from, true));
    h.step();
    for k in 1..=4 {
        h.hover_at(from + by * (k as f32 / 4.0));
        h.step();
    }
    h.event(button(from + by, false));
    h.step();
    h.run();
}

#[test]
fn an_untouched_view_refits_as_the_mode_changes_the_canvas_area_and_a_users_view_is_kept() {
    let mut h = open_character("fit-modes");
    h.key_press(Key::Num2);
    h.run();
    assert_character_in_view(&h, "pose mode");
    let pose_area = canvas_area(&h);
    let pose_view = h.state().view.expect("a view");

    // Animate mode: the timeline takes the bottom of the window; the view fits the smaller area.
    h.key_press(Key::Num3);
    h.run();
    assert!(
        canvas_area(&h).height() < pose_area.height() - 50.0,
        "the test needs animate mode's canvas area to be shorter"
    );
    assert_character_in_view(&h, "animate mode");
    // Back in pose mode, the pose mode's fit again.
    h.key_press(Key::Num2);
    h.run();
    let back = h.state().view.expect("a view");
    assert!(
        (back.zoom - pose_view.zoom).abs() < 1e-3 && (back.pan - pose_view.pan).length() < 0.5,
        "{back:?} vs {pose_view:?}"
    );

    // The user's own view (a pan with the middle button) is kept through mode switches.
    middle_drag(&mut h, egui::vec2(60.0, -40.0));
    let panned = h.state().view.expect("a view");
    assert!((panned.pan - pose_view.pan).length() > 50.0, "{panned:?}");
    for key in [Key::Num3, Key::Num1, Key::Num2] {
        h.key_press(key);
        h.run();
        assert_eq!(h.state().view, Some(panned), "{:?}", h.state().mode);
    }

    // Home fits it again (animate mode's area), and the fit follows the area from then on.
    h.key_press(Key::Num3);
    h.run();
    h.key_press(Key::Home);
    h.run();
    assert_character_in_view(&h, "animate mode after Home");
    h.key_press(Key::Num2);
    h.run();
    assert_character_in_view(&h, "pose mode after Home in animate mode");
    assert!((h.state().view.expect("a view").zoom - pose_view.zoom).abs() < 1e-3);

    // So does the View menu's Zoom to fit, from a pan of the user's.
    middle_drag(&mut h, egui::vec2(-80.0, 30.0));
    h.key_press(Key::Num3);
    h.run();
    click_shown(&mut h, "View");
    click_shown_by(&mut h, By::new().label_contains("Zoom to fit"));
    assert_character_in_view(&h, "animate mode after View → Zoom to fit");
}

/// An editor on a new document in a window of `size` points, after its first frames.
fn empty_editor_sized(size: egui::Vec2) -> Harness<'static, EditorApp> {
    let mut h = harness_sized(EditorApp::new(Document::new()), size);
    h.run();
    h
}

/// Ctrl+O, the path typed, Enter.
fn open_by_keys(h: &mut Harness<'_, EditorApp>, path: &std::path::Path) {
    h.key_press_modifiers(Modifiers::COMMAND, Key::O);
    h.run();
    type_into(h, "Path:", &path.display().to_string());
    h.key_press(Key::Enter);
    h.run();
    assert_eq!(h.state().doc.path.as_deref(), Some(path));
    // The frames that draw the opened document.
    wait_for(h, |app| app.drawing.picture.is_some());
}

#[test]
fn a_fitted_view_reopens_fitted_to_the_new_window_and_a_users_view_as_left() {
    let mut h = open_character("fit-reopen");
    let path = h.state().doc.path.clone().expect("a saved document");
    // Pose mode, where the canvas shows the posed picture.
    h.key_press(Key::Num2);
    h.run();
    let saved_zoom = h.state().view.expect("a view").zoom;
    // Ctrl+S with the editor's fit untouched.
    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run();
    wait_for(&mut h, |app| !app.saving());

    // Reopened in a smaller window, the canvas is fitted to it: the whole character shows,
    // at a smaller zoom than it was saved with.
    let mut small = empty_editor_sized(egui::vec2(900.0, 600.0));
    open_by_keys(&mut small, &path);
    assert_character_in_view(&small, "reopened in a smaller window");
    let zoom = small.state().view.expect("a view").zoom;
    assert!(zoom < saved_zoom * 0.9, "zoom {zoom} vs saved {saved_zoom}");
    // And it stays the editor's fit: it follows the canvas area as the mode changes.
    small.key_press(Key::Num3);
    small.run();
    assert_character_in_view(&small, "animate mode after reopening");

    // The user's own view (a pan) is saved as it is and reopened as it was, in any window.
    middle_drag(&mut h, egui::vec2(60.0, -40.0));
    let panned = h.state().view.expect("a view");
    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run();
    wait_for(&mut h, |app| !app.saving());
    let mut other = empty_editor_sized(egui::vec2(900.0, 600.0));
    open_by_keys(&mut other, &path);
    assert_eq!(other.state().view, Some(panned));
}
