//! Physics constraints in the tree view: listed under their bone, their numbers edited as
//! undoable commands, non-finite numbers refused by the fields, bad numbers by the document
//! with a message, the rig kept posable.

use super::*;

fn tail_sway(h: &Harness<'_, EditorApp>) -> crate::rig::PhysicsConstraint {
    let physics = &h.state().doc.state().handles.physics;
    physics
        .iter()
        .find(|c| c.name == "tail_sway")
        .expect("the tail's constraint")
        .clone()
}

/// Wheels the side panel to `label` and types `text` into it, then Enter.
fn enter(h: &mut Harness<'_, EditorApp>, label: &str, text: &str) {
    wheel_into_view(h, By::new().label(label));
    type_into(h, label, text);
    h.key_press(Key::Enter);
    h.run();
}

#[test]
fn a_physics_constraints_fields_in_the_tree_edit_it_and_refuse_bad_numbers() {
    let mut h = open_character("physics-fields");
    h.key_press(Key::Num2);
    h.run();
    assert!(h.query_by_label("Physics mass").is_none());
    click_label(&mut h, "physics tail_sway");
    let before = tail_sway(&h);
    assert_eq!(before.bone, "tail_4");
    let mass = h.get_by_label("Physics mass").value().unwrap_or_default();
    assert_eq!(mass.parse::<f64>().ok(), Some(1.5), "{mass}");

    // Strength and gravity typed in; each is one undo step. The rig stays posable.
    enter(&mut h, "Physics strength", "80");
    assert_eq!(tail_sway(&h).strength, 80.0, "{:?}", h.state().message);
    enter(&mut h, "Physics gravity", "2.5");
    enter(&mut h, "Moves x", "0.5");
    let after = tail_sway(&h);
    assert_eq!((after.gravity, after.x), (2.5, 0.5));
    assert!(
        h.state().doc.posable().is_some(),
        "the edit made the rig stale"
    );
    let scene_physics = &h
        .state()
        .doc
        .posable()
        .expect("posable")
        .doc
        .handles
        .physics;
    assert_eq!(scene_physics, &h.state().doc.state().handles.physics);

    // Non-finite numbers (NaN, which egui's own field clamped to infinity, infinities, an
    // overflow) are refused by the field: it keeps its value and makes no command.
    let message = h.state().message.clone();
    for text in ["NaN", "inf", "-infinity", "1e999"] {
        enter(&mut h, "Physics damping", text);
        assert_eq!(tail_sway(&h), after, "{text}");
        assert_eq!(h.state().message, message, "{text}");
        let shown = h
            .get_by_label("Physics damping")
            .value()
            .unwrap_or_default();
        assert_eq!(
            shown.parse::<f64>().ok(),
            Some(after.damping),
            "{text}: {shown}"
        );
    }
    // A mass of 0 is refused with the document's message; nothing changes.
    enter(&mut h, "Physics mass", "0");
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("\"mass\" is 0: at least"), "{message}");
    assert_eq!(tail_sway(&h), after);

    // Undo, three steps, back to the constraint as opened.
    for _ in 0..3 {
        h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
        h.run();
    }
    assert_eq!(tail_sway(&h), before);
}
