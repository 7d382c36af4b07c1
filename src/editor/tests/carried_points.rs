//! Point handles carried by bones, through the UI: the Point tool puts a new point on the
//! selected bone, pose mode turns it with the bone, the Parent box and the tree rehang it.

use super::*;
use crate::geom::Vec2;

/// The point named `name`'s carrying bone.
fn carrier(h: &Harness<'_, EditorApp>, name: &str) -> Option<String> {
    let handles = &h.state().doc.state().handles;
    let point = handles.points.iter().find(|p| p.name == name);
    point.expect("point").parent.clone()
}

/// Where the document's pose shows the rest position `at` of handle column `column`.
fn shown_at(h: &Harness<'_, EditorApp>, column: usize, at: Point) -> Point {
    let scene = h.state().doc.posable().expect("posable").clone();
    let shown = scene
        .handle_transforms(&h.state().doc.state().pose)
        .expect("forward kinematics");
    shown[column].apply(at)
}

#[test]
fn a_point_placed_on_a_selected_bone_turns_with_it_and_the_tree_rehangs_it() {
    let mut h = open_character("carried-point");
    assert_eq!(h.state().mode, Mode::Rig);
    let (head_column, head_bone, bones) = {
        let handles = &h.state().doc.state().handles;
        let i = handles.bones.iter().position(|b| b.name == "head").unwrap();
        (i, handles.bones[i].clone(), handles.bones.len())
    };
    // Beside the head bone's tail, on the face.
    let at = head_bone.tail + Vec2::new(6.0, 4.0);

    // The head bone selected in the tree, then the Point tool: the new point rides on it.
    click_label(&mut h, "head");
    click_shown(&mut h, "Point");
    click(&mut h, at);
    let points = h.state().doc.state().handles.points.len();
    let point = h
        .state()
        .doc
        .state()
        .handles
        .points
        .last()
        .expect("a point")
        .clone();
    assert!(distance(point.at, at) < 1.0, "{point:?}");
    assert_eq!(point.parent.as_deref(), Some("head"), "{point:?}");
    assert_eq!(h.state().selected.as_deref(), Some(point.name.as_str()));
    // The next point, placed with the first selected, shares its bone.
    click(&mut h, at + Vec2::new(0.0, 6.0));
    let second = h.state().doc.state().handles.points.last().unwrap().clone();
    assert_eq!(second.parent.as_deref(), Some("head"), "{second:?}");
    h.key_press(Key::Delete);
    h.run();
    assert_eq!(h.state().doc.state().handles.points.len(), points);

    // Weights computed, pose mode: turning the head turns the point with it.
    press_shown(&mut h, "Compute weights");
    wait_for_weights(&mut h);
    h.key_press(Key::Num2);
    h.run();
    assert_eq!(h.state().mode, Mode::Pose);
    click_label(&mut h, "head");
    set_number(&mut h, "Rotation", 30.0);
    let column = bones + h.state().doc.state().handles.points.len() - 1;
    let on_point = shown_at(&h, column, point.at);
    assert!(distance(on_point, point.at) > 2.0, "the point stayed");
    assert!(distance(on_point, shown_at(&h, head_column, point.at)) < 1e-9);

    // Rig mode: the Parent box makes it loose (listed with the loose points), Ctrl+Z hangs it
    // back.
    h.key_press(Key::Num1);
    h.run();
    // Its tree row (the weights readout under the pointer names it too).
    wheel_into_view(&mut h, button(&point.name));
    click_shown_by(&mut h, button(&point.name));
    click_shown_by(&mut h, combo_box("Parent"));
    click_shown(&mut h, "(none)");
    assert_eq!(carrier(&h, &point.name), None, "{:?}", h.state().message);
    let below_points_heading = |h: &Harness<'_, EditorApp>| {
        h.get(button(&point.name)).rect().top() > h.get_by_label("Points").rect().top()
    };
    assert!(below_points_heading(&h));
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(carrier(&h, &point.name).as_deref(), Some("head"));
    assert!(!below_points_heading(&h));

    // The tree: its row, under the head's, dragged onto the chest's row.
    drag_row(&mut h, &point.name, "chest");
    assert_eq!(
        carrier(&h, &point.name).as_deref(),
        Some("chest"),
        "{:?}",
        h.state().message
    );
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("now hangs from 'chest'"), "{message}");
    assert_eq!(
        h.state().doc.state().handles.points.last().unwrap().at,
        point.at,
        "the point moved"
    );
}
