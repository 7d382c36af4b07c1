//! How UI tests click a widget: only where a user could. kittest's own `click` presses a
//! widget's place even when it is scrolled away, clipped, off the screen or covered;
//! [`press_shown_by`] first moves the pointer to that place and asks egui's own hit test whether
//! the widget is under it ([`assert_shown`]), and fails the test where it is not.
//!
//! The editor's unit tests use this module as `editor::tests::shown`; the integration test
//! `tests/editor_portal.rs` includes the same file by its path, so both click through one
//! check. It names nothing of the crate (only egui and kittest), as both must compile it.

use eframe::egui::{self, Pos2};
use egui_kittest::kittest::{By, NodeT, Queryable};
use egui_kittest::Harness;

/// Where kittest's `click` presses `node`: its id and its rect's centre.
pub fn press_point(node: &egui_kittest::Node<'_>) -> (egui::accesskit::NodeId, Pos2) {
    (node.accesskit_node().locate().0, node.rect().center())
}

/// Fails unless a user pointing where kittest's `click` presses (`at`, the centre of the
/// widget `id`'s rect) would be on that widget: the pointer is moved there and egui's own hit
/// test of the next frame must find the widget under it. So a widget scrolled out of its
/// area, clipped, off the screen or under a window or popup fails the test, where `click`
/// would press whatever is drawn there instead. So does input still queued when the widget was
/// located (a key press whose frames have not run): the place was read from a frame that input
/// had yet to change, where a user sees the key's effect before pointing.
pub fn assert_shown<State>(
    h: &mut Harness<'_, State>,
    (id, at): (egui::accesskit::NodeId, Pos2),
    what: &str,
) {
    let screen = h.ctx.content_rect();
    assert!(
        screen.contains(at),
        "{what}: at {at:?}, off the screen {screen:?}"
    );
    let frame = h.ctx.cumulative_frame_nr();
    let on_it = under_pointer(h, at, id);
    // One frame per queued event: more than the pointer's one means input was still queued.
    assert_eq!(
        h.ctx.cumulative_frame_nr(),
        frame + 1,
        "{what}: located while input was still queued (run a key's frames before clicking)"
    );
    assert!(
        on_it,
        "{what}: not under the pointer at its centre {at:?} (scrolled away, clipped or covered)"
    );
}

/// Moves the pointer to `at` and steps one frame: whether egui's hit test then finds the
/// widget (or Ui) `id` under it.
pub fn under_pointer<State>(
    h: &mut Harness<'_, State>,
    at: Pos2,
    id: egui::accesskit::NodeId,
) -> bool {
    h.hover_at(at);
    h.step();
    h.ctx.interaction_snapshot(|s| {
        s.contains_pointer
            .iter()
            .any(|widget| widget.accesskit_id() == id)
    })
}

/// How the UI tests click a widget: the one widget `by` finds, once [`assert_shown`] says
/// a user would be on it (kittest's own `click` presses a widget even where it is hidden). The
/// caller runs the frames: `step` while the editor keeps repainting (playing, computing),
/// [`click_shown_by`] otherwise.
pub fn press_shown_by<State>(h: &mut Harness<'_, State>, by: By<'_>) {
    let what = format!("{by:?}");
    let at = press_point(&h.get(by.clone()));
    assert_shown(h, at, &what);
    // The one place the UI tests call kittest's click (clippy.toml disallows it elsewhere).
    #[allow(clippy::disallowed_methods)]
    h.get(by).click();
}

/// [`press_shown_by`], then the frames run to rest.
pub fn click_shown_by<State>(h: &mut Harness<'_, State>, by: By<'_>) {
    press_shown_by(h, by);
    h.run();
}

/// [`click_shown_by`] the widget labelled `label`.
pub fn click_shown<State>(h: &mut Harness<'_, State>, label: &str) {
    click_shown_by(h, By::new().label(label));
}

/// [`press_shown_by`] the widget labelled `label`; the caller steps the frames.
pub fn press_shown<State>(h: &mut Harness<'_, State>, label: &str) {
    press_shown_by(h, By::new().label(label));
}
