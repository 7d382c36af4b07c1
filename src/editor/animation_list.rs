//! Animate mode's list of animations: pick the one edited, create, rename, duplicate and
//! delete animations, or add one from a capture (*Apply motion…*, [`super::apply_motion`]):
//! the document's [`AnimationEdit`] commands, undoable like any edit.
//! No name is ever typed to pick an animation, so none is created by a typo.
//!
//! In: the document's animations, clicks and the typed new name. Out: `Animations` commands
//! and the animation animate mode edits.

use super::EditorApp;
use crate::document::{unused_animation_name, AnimationEdit, Command};
use eframe::egui;

/// What a new animation is called, before a number makes it unique.
pub const NEW_ANIMATION_NAME: &str = "animation";

/// The list's own state: the name field of Rename.
#[derive(Default)]
pub struct AnimationList {
    /// The name Rename gives; follows the animation picked.
    pub rename_to: String,
    /// The animation `rename_to` was filled from.
    filled_for: String,
}

impl EditorApp {
    /// Makes `name` the animation edited (the playhead stays; an unkeyed pose is dropped).
    pub fn pick_animation(&mut self, name: &str) {
        self.animate.animation = name.to_string();
        self.animate.shown = None;
    }

    /// The names the list shows: the document's animations, and the one edited when it has
    /// no key yet (its first key creates it).
    pub fn animation_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self.doc.state().animations.keys().cloned().collect();
        if !names.contains(&self.animate.animation) {
            names.push(self.animate.animation.clone());
        }
        names
    }

    /// The side panel's section in animate mode.
    pub(super) fn animation_list(&mut self, ui: &mut egui::Ui) {
        // Beside the heading: the panel keeps its height for the tree.
        ui.horizontal(|ui| {
            ui.heading("Animations");
            if ui
                .button("Apply motion…")
                .on_hover_text(
                    "a walk, run, jump… from the motion library or a BVH capture, retargeted \
                     onto this rig's bones as an animation",
                )
                .clicked()
            {
                self.ask_motion();
            }
        });
        let current = self.animate.animation.clone();
        let exists = self.doc.state().animations.contains_key(&current);
        if self.animations.filled_for != current {
            self.animations.filled_for = current.clone();
            self.animations.rename_to = current.clone();
        }
        let mut picked = None;
        for name in self.animation_names() {
            let text = if self.doc.state().animations.contains_key(&name) {
                name.clone()
            } else {
                format!("{name} (no keys yet)")
            };
            if ui.selectable_label(name == current, text).clicked() {
                picked = Some(name);
            }
        }
        if let Some(name) = picked {
            self.pick_animation(&name);
        }
        ui.horizontal_wrapped(|ui| {
            if ui
                .button("New animation")
                .on_hover_text("an empty animation, edited from now on")
                .clicked()
            {
                let name = unused_animation_name(self.doc.state(), NEW_ANIMATION_NAME);
                if self.apply(Command::Animations(AnimationEdit::Add {
                    name: name.clone(),
                })) {
                    self.pick_animation(&name);
                    self.message = Some(format!("new animation '{name}'"));
                }
            }
            if ui
                .add_enabled(exists, egui::Button::new("Duplicate animation"))
                .clicked()
            {
                let to = unused_animation_name(self.doc.state(), &current);
                if self.apply(Command::Animations(AnimationEdit::Duplicate {
                    from: current.clone(),
                    to: to.clone(),
                })) {
                    self.pick_animation(&to);
                    self.message = Some(format!("duplicated '{current}' as '{to}'"));
                }
            }
            if ui
                .add_enabled(exists, egui::Button::new("Delete animation"))
                .clicked()
                && self.apply(Command::Animations(AnimationEdit::Delete {
                    name: current.clone(),
                }))
            {
                let next = self
                    .doc
                    .state()
                    .animations
                    .keys()
                    .next()
                    .cloned()
                    .unwrap_or_else(|| NEW_ANIMATION_NAME.to_string());
                self.pick_animation(&next);
                self.message = Some(format!(
                    "deleted animation '{current}' (Ctrl+Z brings it back)"
                ));
            }
        });
        ui.horizontal(|ui| {
            let label = ui.label("Rename to:");
            let field = ui
                .add(
                    egui::TextEdit::singleline(&mut self.animations.rename_to).desired_width(110.0),
                )
                .labelled_by(label.id);
            let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            let clicked = ui
                .add_enabled(exists, egui::Button::new("Rename animation"))
                .clicked();
            let to = self.animations.rename_to.clone();
            if (clicked || (entered && exists))
                && to != current
                && self.apply(Command::Animations(AnimationEdit::Rename {
                    from: current.clone(),
                    to: to.clone(),
                }))
            {
                self.pick_animation(&to);
                self.animations.filled_for = to.clone();
                self.message = Some(format!("renamed '{current}' to '{to}'"));
            }
        });
    }
}
