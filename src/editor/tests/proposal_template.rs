//! *Propose handles* records the template its proposal followed in the document: one undoable
//! edit with the handles, saved, and offered again by the Template box when the document is
//! reopened.

use super::*;
use crate::io::{RecordedTemplate, RigDocument};

/// The automatic rig's Template box, showing `value`.
fn template_box(value: &str) -> By<'_> {
    By::new().role(egui::accesskit::Role::ComboBox).value(value)
}

/// Presses *Propose handles* and waits for the proposal to be installed.
fn propose(h: &mut Harness<'_, EditorApp>) {
    wheel_into_view(h, By::new().label("Propose handles"));
    press_shown(h, "Propose handles");
    wait_until(h, "the automatic rig", |app| !app.rig_tools.proposing());
}

fn recorded(h: &Harness<'_, EditorApp>) -> Option<RecordedTemplate> {
    h.state().doc.state().autorig.map(|r| r.template)
}

/// The Template box's text for a recorded template.
fn shown_as(template: RecordedTemplate) -> &'static str {
    match template {
        RecordedTemplate::None => "None",
        RecordedTemplate::Humanoid => "Humanoid",
        RecordedTemplate::Quadruped => "Quadruped",
    }
}

#[test]
fn propose_handles_records_its_template_which_a_reopened_document_offers_again() {
    let (dir, path) = character_rig("template");
    let mut h = opened_in(dir, &path);
    h.run();
    assert_eq!(recorded(&h), None);
    wheel_into_view(&mut h, template_box("Auto"));

    // Proposed with the template chosen automatically: the document records the one taken,
    // and the message names it and says why.
    let hand_made = h.state().doc.state().handles.clone();
    propose(&mut h);
    assert_ne!(h.state().doc.state().handles, hand_made);
    let template = recorded(&h).unwrap_or_else(|| panic!("{:?}", h.state().message));
    let message = h.state().message.clone().unwrap_or_default();
    let name = crate::autorig::template_name(match template {
        RecordedTemplate::None => None,
        RecordedTemplate::Humanoid => Some(crate::autorig::Template::Humanoid),
        RecordedTemplate::Quadruped => Some(crate::autorig::Template::Quadruped),
    });
    assert!(
        message.contains(&format!("template: {name} (")),
        "the message names the template and why: {message}"
    );

    // The handles and the record are one edit: Ctrl+Z takes both back, Ctrl+Shift+Z redoes.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(h.state().doc.state().handles, hand_made);
    assert_eq!(recorded(&h), None);
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    h.run();
    assert_eq!(recorded(&h), Some(template));

    // Saved with Ctrl+S: the file records it.
    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run();
    wait_for(&mut h, |app| !app.saving());
    assert!(!h.state().doc.dirty(), "{:?}", h.state().message);
    let saved = RigDocument::load(&path).expect("loads");
    assert_eq!(saved.autorig.map(|r| r.template), Some(template));

    // Reopened, the Template box offers the recorded template.
    h.state_mut().finish_writes();
    let mut again = harness(EditorApp::new(Document::open(&path).expect("opens")));
    again.run();
    assert_eq!(recorded(&again), Some(template));
    wheel_into_view(&mut again, template_box(shown_as(template)));
    assert_eq!(
        again.state().rig_tools.autorig.template,
        rig_tools::template_choice(template)
    );

    // The user's choice wins once made: another template picked in the box is the one the
    // next proposal follows and the document records.
    let other = match template {
        RecordedTemplate::None => RecordedTemplate::Humanoid,
        _ => RecordedTemplate::None,
    };
    click_shown_by(&mut again, template_box(shown_as(template)));
    click_shown_by(&mut again, button(shown_as(other)));
    again.get(template_box(shown_as(other)));
    propose(&mut again);
    assert_eq!(recorded(&again), Some(other), "{:?}", again.state().message);
    let message = again.state().message.clone().unwrap_or_default();
    let other_name = shown_as(other).to_lowercase();
    assert!(
        message.contains(&format!(
            "template: {other_name} (as chosen in the Template box)"
        )),
        "{message}"
    );
    again.state_mut().finish_writes();
}
