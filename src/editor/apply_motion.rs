//! Animate mode's *Apply motion…*: a capture clip (one of the bundled library's motions, or a
//! BVH file) retargeted onto the document's rig and stored as an animation, one undoable edit
//! (what `sinew animate` does on the command line, through the same
//! [`crate::motion::apply_motion`]).
//!
//! In: the window's choices (the motion, or a file typed or picked in a native dialog; the
//! view, facing, in place, loop; the animation's name) and the document's handles. Out: an
//! [`AnimationEdit::Put`] command (replacing an animation of that name), the animation picked
//! for editing, and a message saying what retargeting did; or the library's error as the
//! message, the document unchanged.

use super::native_dialog::DialogFor;
use super::EditorApp;
use crate::document::{AnimationEdit, Command};
use crate::io::RigDocument;
use crate::motion::{self, library, Facing, LoopMode, RetargetOptions, RetargetReport, View};
use eframe::egui::{self, Key};
use std::path::{Path, PathBuf};

/// Where the clip comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MotionSource {
    /// A motion of the bundled library, by name.
    Library(&'static str),
    /// The BVH file in [`ApplyMotionWindow::file`].
    File,
}

/// The *Apply motion* window's state.
pub struct ApplyMotionWindow {
    pub open: bool,
    pub source: MotionSource,
    /// The capture file's path (typed, or picked in a native dialog).
    pub file: String,
    /// View, facing, in place and loop (the rest at their defaults, as `sinew animate`).
    pub options: RetargetOptions,
    /// The animation's name.
    pub name: String,
    /// The default name `name` was last filled with: while the user has not edited it, the
    /// name follows the motion picked.
    named_after: String,
    /// The file field takes the keyboard on the next frame.
    focus_file: bool,
}

impl Default for ApplyMotionWindow {
    fn default() -> Self {
        let first = library::MOTIONS.first().map_or("", |m| m.name);
        ApplyMotionWindow {
            open: false,
            source: MotionSource::Library(first),
            file: String::new(),
            options: RetargetOptions::default(),
            name: first.to_string(),
            named_after: first.to_string(),
            focus_file: false,
        }
    }
}

impl ApplyMotionWindow {
    /// The name an animation of the source gets by default: the motion's, or the file's stem.
    fn default_name(&self) -> String {
        match &self.source {
            MotionSource::Library(name) => name.to_string(),
            MotionSource::File => Path::new(self.file.trim())
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
        }
    }

    /// Keeps the name following the source while the user has not typed one of their own.
    fn follow_source(&mut self) {
        let default = self.default_name();
        if default != self.named_after {
            if self.name == self.named_after || self.name.trim().is_empty() {
                self.name = default.clone();
            }
            self.named_after = default;
        }
    }
}

/// A unit enum's serde name (`legs`, `side`), as `sinew animate` prints it.
fn serde_name<T: serde::Serialize>(value: &T) -> String {
    serde_json::to_value(value)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// What the message says retargeting did: length, keys, views per group, contacts, loop.
pub fn report_message(name: &str, replaced: bool, report: &RetargetReport) -> String {
    let views: Vec<String> = report
        .views
        .iter()
        .map(|(g, v)| format!("{} {}", serde_name(g), serde_name(v)))
        .collect();
    format!(
        "{} animation '{name}': {:.2} s, {} keys from {} frames ({} bones driven; {}; {} foot \
         contacts planted{}) (Ctrl+Z takes it back)",
        if replaced {
            "replaced"
        } else {
            "applied motion as"
        },
        report.duration_s,
        report.keys,
        report.frames,
        report.driven.len(),
        if views.is_empty() {
            "no view".to_string()
        } else {
            views.join(", ")
        },
        report.contacts,
        if report.looped { "; loops" } else { "" },
    )
}

impl EditorApp {
    /// Opens the *Apply motion* window (animate mode's *Apply motion…* button).
    pub fn ask_motion(&mut self) {
        self.motion.open = true;
    }

    /// The rig document the motion is retargeted into: the document's handles and events,
    /// with the built rig's parts (the new animation is checked against them as a saved one
    /// would be). Its animations are left out: only the new one is checked.
    fn motion_target(&self) -> RigDocument {
        let state = self.doc.state();
        let mut target = match &state.rig {
            Some(scene) => {
                let mut doc = scene.doc.clone();
                doc.animations.clear();
                doc
            }
            None => {
                let canvas = state.layers.first().map_or([1, 1], |l| l.canvas_px);
                RigDocument::new(canvas)
            }
        };
        target.handles = state.handles.clone();
        target.events = state.events.clone();
        target
    }

    /// *Apply*: reads the clip, retargets it onto the rig and stores it under the window's
    /// name as one undoable edit, picked for editing. True when applied; on a failure the
    /// message says why and the document is unchanged.
    pub fn apply_motion(&mut self) -> bool {
        let name = self.motion.name.trim().to_string();
        let (clip, from) = match &self.motion.source {
            MotionSource::Library(m) => {
                let Some(motion) = library::find(m) else {
                    self.fail(format!(
                        "no motion '{m}' in the library (it has: {})",
                        library::names()
                    ));
                    return false;
                };
                (motion.clip(), format!("motion '{m}'"))
            }
            MotionSource::File => {
                let path = PathBuf::from(self.motion.file.trim());
                if path.as_os_str().is_empty() {
                    self.fail("give a capture file (.bvh) to apply, or pick a motion");
                    return false;
                }
                (
                    motion::read(&path, &motion::BvhLimits::default()),
                    format!("the capture {}", path.display()),
                )
            }
        };
        let clip = match clip {
            Ok(clip) => clip,
            Err(e) => {
                self.fail(format!("cannot read {from}: {e}"));
                return false;
            }
        };
        let mut target = self.motion_target();
        let report =
            match motion::apply_motion(&mut target, &clip, None, &name, &self.motion.options) {
                Ok(report) => report,
                Err(e) => {
                    self.fail(e.to_string());
                    return false;
                }
            };
        let Some(animation) = target.animations.remove(&name) else {
            self.fail(format!("retargeting stored no animation '{name}'"));
            return false;
        };
        let replaced = self.doc.state().animations.contains_key(&name);
        if !self.apply(Command::Animations(AnimationEdit::Put {
            name: name.clone(),
            animation: Box::new(animation),
        })) {
            return false;
        }
        self.pick_animation(&name);
        self.message = Some(report_message(&name, replaced, &report));
        true
    }

    /// The *Apply motion* window, while open.
    pub(super) fn apply_motion_window(&mut self, ctx: &egui::Context) {
        if !self.motion.open {
            return;
        }
        self.motion.follow_source();
        let (mut apply, mut cancel, mut browse) = (false, false, false);
        egui::Window::new("Apply motion")
            .collapsible(false)
            .resizable(false)
            .show(ctx, |ui| {
                ui.label("A capture retargeted onto this rig's bones, added as an animation.");
                ui.strong("Motion:");
                egui::Grid::new("motions").num_columns(2).show(ui, |ui| {
                    for m in library::MOTIONS {
                        let picked = self.motion.source == MotionSource::Library(m.name);
                        if ui.selectable_label(picked, m.name).clicked() {
                            self.motion.source = MotionSource::Library(m.name);
                        }
                        ui.weak(m.about);
                        ui.end_row();
                    }
                });
                ui.horizontal(|ui| {
                    if ui
                        .button("From file…")
                        .on_hover_text("a BVH motion-capture file")
                        .clicked()
                    {
                        browse = true;
                    }
                    if self.motion.source == MotionSource::File {
                        let label = ui.label("Capture file (.bvh):");
                        let field = ui
                            .add(
                                egui::TextEdit::singleline(&mut self.motion.file)
                                    .desired_width(260.0),
                            )
                            .labelled_by(label.id);
                        if std::mem::take(&mut self.motion.focus_file) {
                            field.request_focus();
                        }
                    }
                });
                ui.separator();
                ui.horizontal(|ui| {
                    ui.label("View:");
                    let view = &mut self.motion.options.view;
                    ui.radio_value(view, View::Auto, "Auto")
                        .on_hover_text("per limb group, the plane of its largest motion");
                    ui.radio_value(view, View::Side, "Side")
                        .on_hover_text("a character drawn in profile");
                    ui.radio_value(view, View::Front, "Front")
                        .on_hover_text("a character facing the viewer");
                });
                ui.horizontal(|ui| {
                    ui.label("Facing:");
                    let facing = &mut self.motion.options.facing;
                    ui.radio_value(facing, Facing::Right, "Right");
                    ui.radio_value(facing, Facing::Left, "Left");
                });
                ui.horizontal(|ui| {
                    ui.label("Loop:");
                    let looping = &mut self.motion.options.loop_mode;
                    ui.radio_value(looping, LoopMode::Auto, "When its ends match")
                        .on_hover_text("a cycle when its first and last frames nearly match");
                    ui.radio_value(looping, LoopMode::Blend, "Always");
                    ui.radio_value(looping, LoopMode::Off, "Never");
                });
                ui.checkbox(&mut self.motion.options.in_place, "In place")
                    .on_hover_text("no travel: the character walks or runs on the spot");
                ui.horizontal(|ui| {
                    let label = ui.label("Animation name:");
                    ui.add(egui::TextEdit::singleline(&mut self.motion.name).desired_width(160.0))
                        .labelled_by(label.id)
                        .on_hover_text("an animation of this name is replaced");
                });
                ui.horizontal(|ui| {
                    apply = ui.button("Apply").clicked();
                    cancel = ui.button("Cancel").clicked();
                });
            });
        if browse {
            self.motion.source = MotionSource::File;
            self.motion.focus_file = true;
            let current =
                Some(PathBuf::from(self.motion.file.trim())).filter(|p| !p.as_os_str().is_empty());
            self.native_dialog(DialogFor::MotionFile, current);
        }
        if ctx.input(|i| i.key_pressed(Key::Escape)) {
            cancel = true;
        }
        if apply && self.apply_motion() {
            self.motion.open = false;
        }
        if cancel {
            self.motion.open = false;
        }
    }
}
