//! The dopesheet's context menu: a right click on a key selects it (keeping the selection when
//! the key is in it; on the "all keys" row, every key at that time) and opens a menu that copies,
//! pastes at the playhead and deletes keys, and sets the curve of every selected key that has
//! one (linear, stepped, or a Bézier easing out of and into its keys) in one undo step.
//!
//! In: the dopesheet's response and layout, the timelines' key times. Out: the selection and
//! `PasteKeys`, `DeleteTimelineKeys` and `SetCurves` commands (through the same functions as
//! the buttons and shortcuts).

use super::timeline::{Hit, SheetLayout};
use super::EditorApp;
use crate::anim::edit::{self, KeyRef, TimelineId};
use crate::anim::Curve;
use crate::document::Command;
use eframe::egui;

/// The curve kinds the menu sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CurveKind {
    Linear,
    Stepped,
    Ease,
}

impl EditorApp {
    /// Selects what a right click hit and shows the keys' menu while it is open.
    pub(super) fn key_context_menu(
        &mut self,
        response: &egui::Response,
        layout: &SheetLayout,
        timelines: &[(TimelineId, Vec<f64>)],
    ) {
        if response.secondary_clicked() {
            if let Some(at) = response.interact_pointer_pos() {
                match self.hit(layout, at, timelines) {
                    Hit::Key(key) if !self.is_selected(&key.timeline, key.time_s) => {
                        self.timeline.selection = vec![key];
                    }
                    Hit::Summary(time_s) => {
                        self.timeline.selection = edit::keys_at(timelines, time_s);
                    }
                    _ => {}
                }
            }
        }
        response.context_menu(|ui| self.key_menu(ui));
    }

    fn key_menu(&mut self, ui: &mut egui::Ui) {
        let selected = !self.timeline.selection.is_empty();
        let animation = crate::document::animation_named(self.doc.state(), &self.animate.animation);
        let curved: Vec<(KeyRef, edit::Segment)> = self
            .timeline
            .selection
            .iter()
            .filter_map(|k| Some((k.clone(), edit::segment(&animation, k).ok()?)))
            .collect();
        if ui
            .add_enabled(selected, egui::Button::new("Copy"))
            .clicked()
        {
            self.copy_keys();
            if let Ok(text) = serde_json::to_string(&self.timeline.clipboard) {
                ui.ctx().copy_text(text);
            }
            ui.close();
        }
        let pastable = !self.timeline.clipboard.is_empty();
        if ui
            .add_enabled(pastable, egui::Button::new("Paste at the playhead"))
            .clicked()
        {
            self.paste_keys();
            ui.close();
        }
        if ui
            .add_enabled(selected, egui::Button::new("Delete"))
            .clicked()
        {
            self.delete_selected_keys();
            ui.close();
        }
        ui.separator();
        let kinds = [
            (CurveKind::Linear, "Linear"),
            (CurveKind::Stepped, "Stepped"),
            (CurveKind::Ease, "Bézier ease in and out"),
        ];
        for (kind, label) in kinds {
            if ui
                .add_enabled(!curved.is_empty(), egui::Button::new(label))
                .on_disabled_hover_text("none of the selected keys starts a curve")
                .clicked()
            {
                let curves = curved
                    .iter()
                    .map(|(key, segment)| {
                        let curve = match kind {
                            CurveKind::Linear => Curve::Linear,
                            CurveKind::Stepped => Curve::Stepped,
                            CurveKind::Ease => Curve::Bezier(segment.ease_bezier()),
                        };
                        (key.clone(), curve)
                    })
                    .collect();
                if self.apply(Command::SetCurves {
                    animation: self.animate.animation.clone(),
                    curves,
                }) {
                    self.message = Some(format!(
                        "{} curve{} set to {}",
                        curved.len(),
                        if curved.len() == 1 { "" } else { "s" },
                        label.to_lowercase()
                    ));
                }
                ui.close();
            }
        }
    }
}
