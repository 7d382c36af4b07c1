//! Binding handles to parts in rig mode (the handles' `bind`): the selected handle's boxes, one
//! per part, each tick one undoable edit that makes the weights stale.

use super::*;

/// The box "weighs PART" of the selected handle.
fn weighs_box(part: &str) -> String {
    format!("weighs {part}")
}

/// Whether the box "weighs PART" is ticked.
fn ticked(h: &Harness<'_, EditorApp>, part: &str) -> bool {
    let label = weighs_box(part);
    let by = By::new()
        .role(egui::accesskit::Role::CheckBox)
        .label(&label);
    h.get(by).accesskit_node().toggled() == Some(egui::accesskit::Toggled::True)
}

fn bind_of(h: &Harness<'_, EditorApp>, handle: &str) -> Option<Vec<String>> {
    h.state().doc.state().handles.bind.get(handle).cloned()
}

#[test]
fn a_bone_selected_in_the_tree_is_bound_to_parts_by_ticking_them_and_ctrl_z_unbinds_it() {
    let mut h = open_character("bind");
    h.get_by_label("Weights are up to date");
    assert_eq!(bind_of(&h, "chest"), None, "the chest starts unbound");

    // The chest's row in the tree selects it; its panel says it weighs every part, and
    // unfolds to a box per part.
    wheel_into_view(&mut h, button("chest"));
    click_shown_by(&mut h, button("chest"));
    assert_eq!(h.state().selected.as_deref(), Some("chest"));
    click_label(&mut h, "Weighs: all parts");
    wheel_into_view(&mut h, By::new().label(&weighs_box("torso")));
    assert!(!ticked(&h, "torso"));

    // Ticking the torso binds the chest to it alone; the weights need computing again.
    click_shown(&mut h, &weighs_box("torso"));
    assert_eq!(
        bind_of(&h, "chest"),
        Some(vec!["torso".to_string()]),
        "{:?}",
        h.state().message
    );
    assert!(ticked(&h, "torso"));
    h.get_by_label("Weighs only: torso");
    assert!(
        h.state().doc.posable().is_none(),
        "a bind makes the weights stale"
    );
    h.get_by_label("Weights need computing");

    // A second part joins it (in draw order: the head is in front of the torso).
    wheel_into_view(&mut h, By::new().label(&weighs_box("head")));
    click_shown(&mut h, &weighs_box("head"));
    assert_eq!(
        bind_of(&h, "chest"),
        Some(vec!["torso".to_string(), "head".to_string()])
    );

    // Ctrl+Z takes each tick back, one at a time; the weights are current again at the end.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(bind_of(&h, "chest"), Some(vec!["torso".to_string()]));
    assert!(!ticked(&h, "head"));
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(bind_of(&h, "chest"), None);
    assert!(!ticked(&h, "torso"));
    assert!(
        h.state().doc.posable().is_some(),
        "undo restores the weights"
    );

    // A bone bound in the handles file shows its parts ticked (the boxes stay unfolded from
    // one selection to the next); unticking the last part unbinds it (it weighs every part
    // again).
    wheel_into_view(&mut h, button("tail_1"));
    click_shown_by(&mut h, button("tail_1"));
    assert_eq!(bind_of(&h, "tail_1"), Some(vec!["tail".to_string()]));
    h.get_by_label("Weighs only: tail");
    wheel_into_view(&mut h, By::new().label(&weighs_box("tail")));
    assert!(ticked(&h, "tail"));
    assert!(!ticked(&h, "torso"));
    click_shown(&mut h, &weighs_box("tail"));
    assert_eq!(bind_of(&h, "tail_1"), None, "{:?}", h.state().message);
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("weighs every part"), "{message}");
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(bind_of(&h, "tail_1"), Some(vec!["tail".to_string()]));
}
