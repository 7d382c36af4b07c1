//! The tree view and the View menu's keys, driven by input events only.

use super::*;

/// The same view, up to a fraction of a point (the side panel's width settles over the first
/// frames, and the fit with it).
fn same_view(a: Option<View>, b: View) -> bool {
    a.is_some_and(|a| (a.zoom - b.zoom).abs() < 1e-3 && (a.pan - b.pan).length() < 1.0)
}

#[test]
fn the_tree_selects_with_the_canvas_renames_in_place_and_hides_parts() {
    let mut h = open_character("tree");
    // Rig mode: a bone picked in the tree is the canvas's selection.
    click_label(&mut h, "lantern");
    assert_eq!(h.state().selected.as_deref(), Some("lantern"));
    assert!(tree_selected(&h, "lantern"));

    // F2 renames the selected handle in place; Enter commits, the selection follows.
    h.key_press(Key::F2);
    h.run();
    type_into(&mut h, "New name:", "lamp");
    h.key_press(Key::Enter);
    h.run();
    let handles = h.state().doc.state().handles.clone();
    let lamp = handles.bones.iter().find(|b| b.name == "lamp");
    assert_eq!(
        lamp.and_then(|b| b.parent.as_deref()),
        Some("arm_lower_r"),
        "{:?}",
        h.state().message
    );
    assert_eq!(h.state().selected.as_deref(), Some("lamp"));
    assert!(h.query_by_label("lantern").is_none());

    // Rename in place, then Escape: nothing renamed.
    h.key_press(Key::F2);
    h.run();
    type_into(&mut h, "New name:", "torch");
    h.key_press(Key::Escape);
    h.run();
    assert!(h.state().doc.state().handles.names().any(|n| n == "lamp"));
    assert!(h.query_by_label("New name:").is_none());

    // Pose mode: a click on the chest on the canvas selects it in the tree too. (Renaming
    // made the rig stale: compute the weights again first.)
    click_label(&mut h, "Compute weights");
    wait_for_weights(&mut h);
    h.key_press(Key::Num2);
    h.run();
    click(&mut h, Point::new(256.0, 225.0));
    assert_eq!(h.state().selected.as_deref(), Some("chest"));
    assert!(tree_selected(&h, "chest"));
    assert!(!tree_selected(&h, "lamp"));

    // The head part's eye box hides it on the canvas: the picture leaves it out and shows
    // what is behind it; ticked again, it is back.
    let on_head = screen(&h, part_point(&h, "head"));
    let shown = |h: &Harness<'_, EditorApp>| {
        let picture = h.state().drawing.picture.as_ref().expect("a picture");
        let head = picture
            .draws
            .iter()
            .find(|d| d.name == "head")
            .expect("head");
        (head.visible, picture.pixel_at(on_head))
    };
    let before = shown(&h);
    assert!(before.0);
    click_label(&mut h, "show head");
    let hidden = shown(&h);
    assert!(!hidden.0);
    assert_ne!(hidden.1, before.1, "the head's pixel did not change");
    click_label(&mut h, "show head");
    assert_eq!(shown(&h), before);
    // Hiding is the view's, not the document's.
    assert!(!h.state().doc.dirty() || h.state().doc.can_undo());
}

#[test]
fn home_fits_f_frames_the_selection_and_ctrl_0_shows_actual_size() {
    let mut h = open_character("view-keys");
    h.key_press(Key::Num2);
    h.run();
    let fitted = h.state().view.expect("a view");
    assert!(
        (fitted.zoom - 1.0).abs() > 0.05,
        "the test needs a fit ≠ 100 %"
    );

    // Ctrl+0: one canvas px per point, the point at the area's centre kept there.
    let area = h.state().drawing.picture.as_ref().expect("a picture").rect;
    let centre_px = h
        .state()
        .placed
        .expect("placed")
        .canvas_from_screen(area.center());
    h.key_press_modifiers(Modifiers::COMMAND, Key::Num0);
    h.run();
    assert_eq!(h.state().view.expect("a view").zoom, 1.0);
    let kept = screen(&h, centre_px);
    assert!(
        kept.distance(area.center()) < 0.5,
        "{kept:?} vs {:?}",
        area.center()
    );

    // Home: fitted again.
    h.key_press(Key::Home);
    h.run();
    assert!(same_view(h.state().view, fitted), "{:?}", h.state().view);

    // F frames the selected bone: its middle at the area's centre, zoomed in on it.
    click(&mut h, Point::new(256.0, 225.0));
    assert_eq!(h.state().selected.as_deref(), Some("chest"));
    h.key_press(Key::F);
    h.run();
    let view = h.state().view.expect("a view");
    assert!(
        view.zoom > 3.0 * fitted.zoom,
        "zoom {} vs {}",
        view.zoom,
        fitted.zoom
    );
    let middle = screen(&h, Point::new(256.0, 230.0));
    assert!(
        middle.distance(area.center()) < 0.5,
        "{middle:?} vs {:?}",
        area.center()
    );

    // The View menu does the same, its entries showing their keys.
    click_shown(&mut h, "View");
    click_shown_by(&mut h, By::new().label_contains("Zoom to fit"));
    assert!(same_view(h.state().view, fitted), "{:?}", h.state().view);
}

fn parent_of(h: &Harness<'_, EditorApp>, bone: &str) -> Option<String> {
    let handles = &h.state().doc.state().handles;
    let bone = handles.bones.iter().find(|b| b.name == bone).expect("bone");
    bone.parent.clone()
}

#[test]
fn a_bone_dragged_onto_another_in_the_tree_hangs_from_it_undoably_and_loops_are_refused() {
    let mut h = open_character("reparent");
    assert_eq!(h.state().mode, Mode::Rig);
    let rest = |h: &Harness<'_, EditorApp>| {
        let handles = &h.state().doc.state().handles;
        let b = handles.bones.iter().find(|b| b.name == "lantern").unwrap();
        (b.head, b.tail)
    };
    let before = rest(&h);
    assert_eq!(parent_of(&h, "lantern").as_deref(), Some("arm_lower_r"));

    // The lantern's row onto the left forearm's: it hangs from it, where it was drawn.
    drag_row(&mut h, "lantern", "arm_lower_l");
    assert_eq!(
        parent_of(&h, "lantern").as_deref(),
        Some("arm_lower_l"),
        "{:?}",
        h.state().message
    );
    assert_eq!(rest(&h), before, "the bone moved");
    let message = h.state().message.clone().unwrap_or_default();
    assert!(
        message.contains("now hangs from 'arm_lower_l'"),
        "{message}"
    );

    // Ctrl+Z puts it back under the lower arm.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(parent_of(&h, "lantern").as_deref(), Some("arm_lower_r"));

    // The upper arm onto the lantern (below it): a loop, refused with a message.
    drag_row(&mut h, "arm_upper_r", "lantern");
    assert_eq!(parent_of(&h, "arm_upper_r"), None);
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("cannot be the parent"), "{message}");

    // The lantern onto the "no parent" row: a skeleton's root of its own.
    drag_row(&mut h, "lantern", "(drop here: no parent)");
    assert_eq!(parent_of(&h, "lantern"), None, "{:?}", h.state().message);
    assert_eq!(rest(&h), before);
    // A plain click still selects.
    click_label(&mut h, "chest");
    assert_eq!(h.state().selected.as_deref(), Some("chest"));
}

#[test]
fn a_drag_held_at_the_trees_bottom_edge_scrolls_it_to_rows_below() {
    let mut h = open_character("tree-autoscroll");
    assert_eq!(h.state().mode, Mode::Rig);
    // The tree's visible part: from under its heading to above the separator before the
    // weights' heading.
    let top = h.get_by_label("Tree").rect().bottom();
    let bottom = h.get_by_label("Weights").rect().top() - 12.0;
    let start = press_point(&h.get_by_label("head"));
    assert!(
        start.1.y > top && start.1.y < bottom,
        "the head's row shows"
    );
    assert_shown(&mut h, start, "head");
    let start = start.1;
    let lantern = |h: &Harness<'_, EditorApp>| h.get_by_label("lantern").rect().center();
    assert!(
        lantern(&h).y > bottom + 20.0,
        "the lantern's row starts out of view"
    );

    // The head's row pressed and dragged down to the tree's bottom edge, held there.
    h.drag_at(start);
    h.step();
    h.hover_at(start + egui::vec2(0.0, 12.0));
    h.step();
    let edge = egui::pos2(start.x, bottom - 4.0);
    h.hover_at(edge);
    let mut steps = 0;
    while lantern(&h).y > bottom - 30.0 {
        h.step();
        steps += 1;
        assert!(
            steps < 240,
            "the tree did not scroll: lantern at {:?}",
            lantern(&h)
        );
    }
    // The pointer off the edge: the scrolling stops (the rows' places reach the test a frame
    // or two late, so wait until they stand still), then the drop on the lantern's row, now in
    // view: the head hangs from it.
    h.hover_at(egui::pos2(start.x, (top + bottom) / 2.0));
    let mut was = lantern(&h);
    for _ in 0..10 {
        h.step();
        if lantern(&h) == was {
            break;
        }
        was = lantern(&h);
    }
    let end = lantern(&h);
    assert!(
        end.y > top && end.y < bottom,
        "the lantern's row shows: {end:?}"
    );
    h.hover_at(end);
    h.step();
    h.drop_at(end);
    h.step();
    h.run();
    assert_eq!(
        parent_of(&h, "head").as_deref(),
        Some("lantern"),
        "{:?}",
        h.state().message
    );

    // Without a drag, resting the pointer at the edge scrolls nothing.
    let before = lantern(&h);
    h.hover_at(edge);
    for _ in 0..10 {
        h.step();
    }
    assert_eq!(lantern(&h), before);
}

#[test]
fn a_slots_attachment_list_in_the_tree_keys_attachment_swaps_at_the_playhead() {
    let (mut h, animation) = new_animation_on_skinned_character("attachment-list");
    let keys = |h: &Harness<'_, EditorApp>| bag_attachment_keys(h, &animation);
    let drawn = |h: &Harness<'_, EditorApp>| -> Vec<String> {
        let picture = h.state().drawing.picture.as_ref().expect("a picture");
        let draws = picture.draws.iter().filter(|d| d.visible);
        draws.map(|d| d.name.clone()).collect()
    };
    // The bag slot lists its own part, the pail and nothing; its own part is ticked.
    assert!(tree_selected(&h, "bag shows bag"));
    assert!(drawn(&h).contains(&"bag".to_string()));

    // A click on the pail keys it at 0 s; the canvas shows the pail.
    click_label(&mut h, "bag shows bag_pail");
    assert_eq!(
        keys(&h),
        [(0.0, Some("bag_pail".to_string()))],
        "{:?}",
        h.state().message
    );
    assert!(tree_selected(&h, "bag shows bag_pail"));
    let names = drawn(&h);
    assert!(names.contains(&"bag_pail".to_string()) && !names.contains(&"bag".to_string()));

    // Twelve frames on (0.5 s at 24 fps), "nothing" keys the slot hidden.
    for _ in 0..12 {
        click_shown(&mut h, "Next frame");
    }
    click_label(&mut h, "bag shows nothing");
    assert_eq!(keys(&h), [(0.0, Some("bag_pail".into())), (0.5, None)]);
    let names = drawn(&h);
    assert!(!names.iter().any(|n| n.starts_with("bag")), "{names:?}");
    assert!(tree_selected(&h, "bag shows nothing"));

    // Ctrl+Z takes the second key back; the pail is shown there again.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(keys(&h), [(0.0, Some("bag_pail".into()))]);
    assert!(drawn(&h).contains(&"bag_pail".to_string()));
}

#[test]
fn rig_mode_draws_one_attachment_per_slot_and_the_tree_picks_which() {
    let (dir, path) = character_rig_with("rig-attachments", true);
    let mut h = opened_in(dir, &path);
    h.run();
    assert_eq!(h.state().mode, Mode::Rig);
    let drawn = |h: &Harness<'_, EditorApp>| -> Vec<String> {
        let app = h.state();
        let layers = &app.doc.state().layers;
        let names = layers.iter().map(|l| l.name.clone());
        names.filter(|n| app.rig_shows_part(n)).collect()
    };
    let has = |h: &Harness<'_, EditorApp>, part: &str| drawn(h).iter().any(|n| n == part);
    // Each slot shows its own part, not every attachment stacked: the lantern, the closed hand.
    assert!(has(&h, "bag") && !has(&h, "bag_pail"), "{:?}", drawn(&h));
    assert!(has(&h, "arm_lower_l") && !has(&h, "arm_lower_l_open"));
    assert!(tree_selected(&h, "bag shows bag"));

    // The tree shows the pail instead, to see and weigh it: a view, not an edit.
    click_label(&mut h, "bag shows bag_pail");
    assert!(has(&h, "bag_pail") && !has(&h, "bag"), "{:?}", drawn(&h));
    assert!(tree_selected(&h, "bag shows bag_pail"));
    assert!(
        !h.state().doc.can_undo(),
        "viewing an attachment is not an edit"
    );
    click_label(&mut h, "bag shows nothing");
    assert!(!has(&h, "bag_pail") && !has(&h, "bag"));

    // Pose mode shows what the pose shows (the lantern): rig mode's choice is its own.
    h.key_press(Key::Num2);
    h.run();
    assert!(tree_selected(&h, "bag shows bag"));
    h.key_press(Key::Num1);
    h.run();
    assert!(tree_selected(&h, "bag shows nothing"));
}

#[test]
fn selecting_in_the_tree_never_moves_the_tree_under_the_pointer() {
    let mut h = open_character("tree-still");
    let rows = ["hip", "chest", "head", "tail_1", "lantern"];
    let rects = |h: &Harness<'_, EditorApp>| rows.map(|r| h.get_by_label(r).rect());
    // Pose mode (2) and animate mode (3): from nothing selected, three bones picked one after
    // another by a click on their rows. The rows stay where they were.
    for mode in [Key::Num2, Key::Num3] {
        h.key_press(mode);
        h.run();
        wheel_into_view(&mut h, By::new().label("chest"));
        let before = rects(&h);
        for pick in ["chest", "head", "hip"] {
            click_shown(&mut h, pick);
            assert_eq!(h.state().selected.as_deref(), Some(pick));
            assert_eq!(rects(&h), before, "after picking {pick}");
        }
        h.key_press(Key::Escape);
        h.run();
    }
}
