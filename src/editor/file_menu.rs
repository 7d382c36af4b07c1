//! The File menu, its windows and its shortcuts, as desktop applications have them: New
//! (Ctrl+N), Open… (Ctrl+O), Import layer…, Save (Ctrl+S), Save as… (Ctrl+Shift+S), recent
//! files, Export Spine… and Render… (each a window with its path and options).
//!
//! In: clicks, typed paths and key presses (each key event read with its own modifiers, so a
//! quick Ctrl+S is a save and never the S of pose mode's scale). Out: calls of [`super::file`]'s
//! open, import, save, export and render, the same ones drops and the close dialog use.
//!
//! The menu keeps working text fields: it closes on a click outside it or on an action, never on
//! a click into a field. Paths are typed (in the menu's field or in the path window a shortcut
//! opens), or picked in a native dialog where the desktop's portal answers
//! ([`super::native_dialog`]).

use super::native_dialog::DialogFor;
use super::number_field::number_field;
use super::EditorApp;
use crate::skin::Blend;
use eframe::egui::{self, Key, Modifiers};
use std::path::PathBuf;

/// At most this many recent files are listed.
pub const MAX_RECENT: usize = 8;

/// What a typed path is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathAction {
    OpenRig,
    ImportLayer,
    SaveAs,
}

impl PathAction {
    fn title(self) -> &'static str {
        match self {
            PathAction::OpenRig => "Open rig",
            PathAction::ImportLayer => "Import layer",
            PathAction::SaveAs => "Save as",
        }
    }

    /// The window's confirm button.
    fn verb(self) -> &'static str {
        match self {
            PathAction::OpenRig => "Open",
            PathAction::ImportLayer => "Import",
            PathAction::SaveAs => "Save to this path",
        }
    }
}

/// A window asking for a path (the typed form of an open or save dialog).
#[derive(Clone, Debug)]
pub struct PathWindow {
    pub action: PathAction,
    pub path: String,
    /// The field takes the keyboard when the window opens.
    focus: bool,
}

/// The File menu's windows and lists beside the document.
#[derive(Default)]
pub struct FileWindows {
    pub path: Option<PathWindow>,
    /// File → Export Spine… is open.
    pub export: bool,
    /// File → Render… is open.
    pub render: bool,
    /// Ctrl+N on a modified document: asking whether to discard the changes.
    pub confirm_new: bool,
}

/// Whether `key` was pressed with exactly `modifiers` in one of this frame's key events
/// (not the frame's last modifier state, which a quick release changes), and takes the event.
pub fn take_key(ctx: &egui::Context, modifiers: Modifiers, key: Key) -> bool {
    ctx.input_mut(|i| i.consume_key(modifiers, key))
}

/// Whether `key` was pressed on its own (no Ctrl, Alt or Command in that key event).
pub fn plain_key(i: &egui::InputState, key: Key) -> bool {
    i.events.iter().any(|e| {
        matches!(e, egui::Event::Key { key: k, pressed: true, modifiers, .. }
            if *k == key && !(modifiers.ctrl || modifiers.alt || modifiers.command || modifiers.mac_cmd))
    })
}

impl EditorApp {
    /// The File menu; a click into its fields keeps it open, a click on an action closes it.
    pub(super) fn file_menu_button(&mut self, ui: &mut egui::Ui) {
        let config = egui::containers::menu::MenuConfig::new()
            .close_behavior(egui::PopupCloseBehavior::CloseOnClickOutside);
        egui::containers::menu::MenuButton::new("File")
            .config(config)
            .ui(ui, |ui| self.file_menu(ui));
    }

    fn file_menu(&mut self, ui: &mut egui::Ui) {
        let act = |ui: &mut egui::Ui, label: &str, shortcut: &str| {
            let button = egui::Button::new(label);
            let button = if shortcut.is_empty() {
                button
            } else {
                button.shortcut_text(shortcut)
            };
            let clicked = ui.add(button).clicked();
            if clicked {
                ui.close();
            }
            clicked
        };
        if act(ui, "New", "Ctrl+N") {
            self.ask_new();
        }
        if act(ui, "Open…", "Ctrl+O") {
            self.ask_path(PathAction::OpenRig);
        }
        if act(ui, "Import layer…", "") {
            self.ask_path(PathAction::ImportLayer);
        }
        if act(ui, "Save", "Ctrl+S") {
            self.save();
        }
        if act(ui, "Save as…", "Ctrl+Shift+S") {
            self.ask_path(PathAction::SaveAs);
        }
        if !self.recent.is_empty() {
            ui.menu_button("Open recent", |ui| {
                let mut chosen = None;
                for path in &self.recent {
                    if ui.button(path.display().to_string()).clicked() {
                        chosen = Some(path.clone());
                        ui.close();
                    }
                }
                if let Some(path) = chosen {
                    self.open(&path);
                }
            });
        }
        ui.separator();
        let label = ui.label("Rig or PNG path:");
        ui.text_edit_singleline(&mut self.open_path)
            .labelled_by(label.id);
        ui.horizontal(|ui| {
            if ui.button("Open rig").clicked() {
                ui.close();
                let path = PathBuf::from(self.open_path.trim());
                self.open(&path);
            }
            if ui.button("Import layer").clicked() {
                ui.close();
                let path = PathBuf::from(self.open_path.trim());
                self.import_layer(&path);
            }
            if ui.button("Save here").clicked() {
                ui.close();
                let path = PathBuf::from(self.open_path.trim());
                self.save_as(&path);
            }
        });
        ui.separator();
        if act(ui, "Export Spine…", "") {
            self.files.export = true;
        }
        if act(ui, "Render…", "") {
            self.files.render = true;
        }
        self.colorize_file_menu(ui);
    }

    /// Ctrl+N, Ctrl+O, Ctrl+S and Ctrl+Shift+S (read before any other key, so the S of a
    /// Ctrl+S never reaches pose mode's scale).
    pub(super) fn file_shortcuts(&mut self, ctx: &egui::Context) {
        if take_key(ctx, Modifiers::COMMAND | Modifiers::SHIFT, Key::S) {
            self.ask_path(PathAction::SaveAs);
        }
        if take_key(ctx, Modifiers::COMMAND, Key::S) {
            self.save();
        }
        if take_key(ctx, Modifiers::COMMAND, Key::O) {
            self.ask_path(PathAction::OpenRig);
        }
        if take_key(ctx, Modifiers::COMMAND, Key::N) {
            self.ask_new();
        }
    }

    /// Asks for a path to `action`: the native dialog where a portal answers, else the path
    /// window, with the document's path filled in for a save.
    pub fn ask_path(&mut self, action: PathAction) {
        let current = match action {
            PathAction::SaveAs => self.doc.path.clone(),
            _ => None,
        };
        if self.native_dialog(super::native_dialog::DialogFor::Path(action), current) {
            return;
        }
        let path = match action {
            PathAction::SaveAs => self
                .doc
                .path
                .as_ref()
                .map(|p| p.display().to_string())
                .unwrap_or_default(),
            _ => String::new(),
        };
        self.files.path = Some(PathWindow {
            action,
            path,
            focus: true,
        });
    }

    /// File → New: at once for a document without unsaved changes, else after asking.
    fn ask_new(&mut self) {
        if self.doc.dirty() {
            self.files.confirm_new = true;
        } else {
            self.new_document();
        }
    }

    /// The File menu's windows: the path window, Export Spine, Render, and New's question.
    pub(super) fn file_windows(&mut self, ctx: &egui::Context) {
        self.path_window(ctx);
        self.export_window(ctx);
        self.render_window(ctx);
        if self.files.confirm_new {
            egui::Window::new("New document")
                .collapsible(false)
                .resizable(false)
                .show(ctx, |ui| {
                    ui.label("Discard the unsaved changes and start a new document?");
                    ui.horizontal(|ui| {
                        if ui.button("Discard and start new").clicked() {
                            self.files.confirm_new = false;
                            self.new_document();
                        }
                        if ui.button("Keep editing").clicked() {
                            self.files.confirm_new = false;
                        }
                    });
                });
        }
    }

    fn path_window(&mut self, ctx: &egui::Context) {
        let Some(mut window) = self.files.path.take() else {
            return;
        };
        let (mut done, mut confirmed) = (false, false);
        egui::Window::new(window.action.title())
            .collapsible(false)
            .resizable(false)
            .show(ctx, |ui| {
                let label = ui.label("Path:");
                let field = ui
                    .add(egui::TextEdit::singleline(&mut window.path).desired_width(360.0))
                    .labelled_by(label.id);
                if std::mem::take(&mut window.focus) {
                    field.request_focus();
                }
                let entered = field.lost_focus() && ui.input(|i| i.key_pressed(Key::Enter));
                ui.horizontal(|ui| {
                    confirmed = ui.button(window.action.verb()).clicked() || entered;
                    done = ui.button("Cancel").clicked();
                });
            });
        if ctx.input(|i| i.key_pressed(Key::Escape)) {
            done = true;
        }
        if confirmed {
            let path = PathBuf::from(window.path.trim());
            match window.action {
                PathAction::OpenRig => self.open(&path),
                PathAction::ImportLayer => self.import_layer(&path),
                PathAction::SaveAs => self.save_as(&path),
            }
            return;
        }
        if !done {
            self.files.path = Some(window);
        }
    }

    fn export_window(&mut self, ctx: &egui::Context) {
        let mut open = self.files.export;
        egui::Window::new("Export Spine")
            .open(&mut open)
            .collapsible(false)
            .show(ctx, |ui| {
                let label = ui.label("Export folder:");
                ui.horizontal(|ui| {
                    ui.text_edit_singleline(&mut self.export_dir)
                        .labelled_by(label.id);
                    self.browse_button(ui, DialogFor::ExportFolder);
                });
                spine_options_ui(ui, &mut self.spine_options);
                if ui.button("Export").clicked() {
                    let dir = PathBuf::from(self.export_dir.trim());
                    let message = self.export_spine(&dir);
                    self.message = Some(message);
                }
            });
        self.files.export &= open;
    }

    fn render_window(&mut self, ctx: &egui::Context) {
        let mut open = self.files.render;
        // Over the canvas's right side, not over the side panel's lists.
        let right_top = ctx.content_rect().right_top() + egui::vec2(-16.0, 48.0);
        egui::Window::new("Render")
            .open(&mut open)
            .collapsible(false)
            .pivot(egui::Align2::RIGHT_TOP)
            .default_pos(right_top)
            .show(ctx, |ui| {
                let label =
                    ui.label("Render the current animation to (.gif, .png sheet or a folder):");
                ui.horizontal(|ui| {
                    ui.text_edit_singleline(&mut self.render_path)
                        .labelled_by(label.id);
                    self.browse_button(ui, DialogFor::RenderPath);
                });
                render_settings_ui(ui, &mut self.render_settings);
                if ui
                    .add_enabled(self.render.is_none(), egui::Button::new("Render"))
                    .clicked()
                {
                    let ctx = ui.ctx().clone();
                    self.start_render(&ctx);
                }
            });
        self.files.render &= open;
    }

    /// Puts `path` first in the recent files (File → Open recent).
    pub(super) fn remember_recent(&mut self, path: &std::path::Path) {
        let path = path.to_path_buf();
        self.recent.retain(|p| *p != path);
        self.recent.insert(0, path);
        self.recent.truncate(MAX_RECENT);
        if let Some(file) = &self.recent_file {
            let list: Vec<String> = self
                .recent
                .iter()
                .map(|p| p.display().to_string())
                .collect();
            // The list is a convenience: failing to keep it is not worth a message.
            if let Ok(json) = serde_json::to_vec_pretty(&list) {
                if let Some(dir) = file.parent() {
                    let _ = std::fs::create_dir_all(dir);
                }
                let _ = crate::io::atomic::write_atomic(file, &json);
            }
        }
    }

    /// Reads the recent files kept in `file` (a JSON list of paths), and keeps them there.
    pub fn keep_recent_in(&mut self, file: PathBuf) {
        if let Some(list) = std::fs::read(&file)
            .ok()
            .and_then(|b| serde_json::from_slice::<Vec<String>>(&b).ok())
        {
            self.recent = list
                .into_iter()
                .map(PathBuf::from)
                .take(MAX_RECENT)
                .collect();
        }
        self.recent_file = Some(file);
    }
}

/// The fields of `sinew export spine`'s options.
fn spine_options_ui(ui: &mut egui::Ui, options: &mut crate::export::spine::SpineOptions) {
    use crate::export::spine::{BakeMode, SpineVersion};
    egui::Grid::new("spine options").show(ui, |ui| {
        ui.label("Spine version");
        egui::ComboBox::from_id_salt("spine version")
            .selected_text(format!("{:?}", options.version))
            .show_ui(ui, |ui| {
                for v in [SpineVersion::V4_1, SpineVersion::V4_2, SpineVersion::V4_3] {
                    ui.selectable_value(&mut options.version, v, format!("{v:?}"));
                }
            });
        ui.end_row();
        ui.label("Bake");
        egui::ComboBox::from_id_salt("spine bake")
            .selected_text(format!("{:?}", options.bake))
            .show_ui(ui, |ui| {
                for b in [BakeMode::Auto, BakeMode::All] {
                    ui.selectable_value(&mut options.bake, b, format!("{b:?}"));
                }
            });
        ui.end_row();
        ui.label("Bake keys per second");
        ui.add(
            number_field(&mut options.bake_fps)
                .range(1.0..=crate::playback::MAX_FPS)
                .speed(0.2),
        );
        ui.end_row();
        optional_count(
            ui,
            "At most influences per vertex",
            &mut options.max_influences,
            4,
            1..=16,
        );
        optional_count(
            ui,
            "At most vertices per mesh",
            &mut options.max_vertices,
            200,
            3..=100_000,
        );
        // `sinew export spine --preset game`: the two limits above, as the preset sets them.
        ui.label("");
        if ui
            .button("Game preset")
            .on_hover_text("At most 250 vertices per mesh and 4 influences per vertex")
            .clicked()
        {
            let game = crate::export::spine::SpinePreset::Game.options();
            options.max_influences = game.max_influences;
            options.max_vertices = game.max_vertices;
        }
        ui.end_row();
    });
}

/// A checkbox and a number for an optional limit (`None`: unchecked); `default` when checked.
fn optional_count(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut Option<usize>,
    default: usize,
    range: std::ops::RangeInclusive<usize>,
) {
    ui.label(label);
    ui.horizontal(|ui| {
        let mut on = value.is_some();
        let mut n = value.unwrap_or(default);
        ui.checkbox(&mut on, "");
        ui.add_enabled(on, number_field(&mut n).range(range));
        *value = on.then_some(n);
    });
    ui.end_row();
}

/// The fields of `sinew render`'s options.
fn render_settings_ui(ui: &mut egui::Ui, settings: &mut crate::playback::RenderSettings) {
    use crate::anim::CurveEvaluation;
    egui::Grid::new("render settings").show(ui, |ui| {
        let label = ui.label("Frames per second");
        ui.add(
            number_field(&mut settings.fps)
                .range(1.0..=crate::playback::MAX_FPS)
                .speed(0.2),
        )
        .labelled_by(label.id);
        ui.end_row();
        let label = ui.label("Scale (output px per canvas px)");
        ui.add(
            number_field(&mut settings.scale)
                .range(super::file::RENDER_SCALE_RANGE.0..=super::file::RENDER_SCALE_RANGE.1)
                .speed(0.01),
        )
        .labelled_by(label.id);
        ui.end_row();
        ui.label("Background");
        ui.horizontal(|ui| {
            let mut opaque = settings.background.is_some();
            ui.checkbox(&mut opaque, "");
            match (opaque, settings.background) {
                (true, Some(mut rgba)) => {
                    ui.color_edit_button_srgba_unmultiplied(&mut rgba);
                    settings.background = Some(rgba);
                }
                (true, None) => settings.background = Some([255, 255, 255, 255]),
                (false, _) => {
                    settings.background = None;
                    ui.label("transparent");
                }
            }
        });
        ui.end_row();
        ui.label("Blend");
        egui::ComboBox::from_id_salt("render blend")
            .selected_text(format!("{:?}", settings.blend))
            .show_ui(ui, |ui| {
                for blend in [Blend::Linear, Blend::Dqs, Blend::Stretch] {
                    ui.selectable_value(&mut settings.blend, blend, format!("{blend:?}"));
                }
            });
        ui.end_row();
        let mut spine = settings.sampling.curves == CurveEvaluation::SpineRuntime;
        ui.checkbox(&mut spine, "Curves as Spine's runtimes play them");
        settings.sampling.curves = if spine {
            CurveEvaluation::SpineRuntime
        } else {
            CurveEvaluation::Exact
        };
        ui.end_row();
        if spine {
            // The export those runtimes play (`sinew spine --spine-version`, `--fps`).
            use crate::export::spine::SpineVersion;
            let export = &mut settings.export;
            let label = ui.label("Spine version");
            let name = |v: SpineVersion| &v.version_string()[..3];
            egui::ComboBox::from_id_salt("render spine version")
                .selected_text(name(export.version))
                .show_ui(ui, |ui| {
                    for v in [SpineVersion::V4_1, SpineVersion::V4_2, SpineVersion::V4_3] {
                        ui.selectable_value(&mut export.version, v, name(v));
                    }
                })
                .response
                .labelled_by(label.id);
            ui.end_row();
            let label = ui.label("Bake keys per second");
            ui.add(
                number_field(&mut export.bake_fps)
                    .range(1.0..=crate::export::spine::MAX_BAKE_FPS)
                    .speed(0.2),
            )
            .labelled_by(label.id);
            ui.end_row();
        }
    });
}
