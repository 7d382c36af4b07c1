//! Files: open, import, save and autosave (written on other threads when they must trace and
//! mesh first), the view saved beside a document, File → Export Spine and File → Render, and
//! the File menu that drives them.
//!
//! In: paths typed in the File menu or dropped on the window. Out: the document read or
//! written through [`crate::document`], messages for the status bar.

use super::canvas::View;
use super::{animate_mode, EditorApp, Mode};
use crate::document::{Command, Document, DocumentError};
use crate::pipeline::Layer;
use crate::skin::Blend;
use eframe::egui;
use std::path::{Path, PathBuf};

/// Seconds between autosaves of a changed document.
pub const AUTOSAVE_INTERVAL_S: f64 = 30.0;

/// File → Render's output scale, output px per canvas px.
const RENDER_SCALE_RANGE: (f64, f64) = (0.05, 8.0);

/// The view saved beside a document (`NAME.view.json`), so reopening shows it as it was left.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViewState {
    pub zoom: f32,
    /// Canvas origin offset, points.
    pub pan: [f32; 2],
    pub mode: Mode,
    pub selected: Option<String>,
    pub animation: String,
    pub time_s: f64,
    /// Animate mode's playback starts again at the end (default true).
    #[serde(default = "loops_by_default")]
    pub looping: bool,
    /// Animate mode's onion skins (default off).
    #[serde(default)]
    pub onion: animate_mode::OnionOptions,
    /// File → Render's settings; the timeline plays at their frame rate.
    #[serde(default)]
    pub render: crate::playback::RenderSettings,
}

fn loops_by_default() -> bool {
    true
}

/// A save or autosave being written on another thread: its outcome arrives here.
pub(super) type Writing = std::sync::mpsc::Receiver<Result<PathBuf, DocumentError>>;

/// A save being written on another thread (one that must trace and mesh first).
pub(super) struct Saving {
    /// The snapshot written, for [`Document::saved`].
    pub(super) job: crate::document::SaveJob,
    pub(super) receive: Writing,
    /// False once another document was opened meanwhile: its outcome is then only reported.
    this_document: bool,
}

/// Writes `job` on another thread, waking the UI (`ctx`) when it is done.
fn write_in_background(job: crate::document::SaveJob, ctx: Option<egui::Context>) -> Writing {
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        // The editor may have closed meanwhile.
        let _ = send.send(job.run());
        if let Some(ctx) = ctx {
            ctx.request_repaint();
        }
    });
    receive
}

/// The outcome of a background write once it is done (`None` while it runs).
fn written(receive: &Writing) -> Option<Result<PathBuf, String>> {
    match receive.try_recv() {
        Err(std::sync::mpsc::TryRecvError::Empty) => None,
        Ok(outcome) => Some(outcome.map_err(|e| e.to_string())),
        Err(std::sync::mpsc::TryRecvError::Disconnected) => {
            Some(Err("the writing thread stopped".into()))
        }
    }
}

/// The view side file of the document at `path`.
pub fn view_path(path: &Path) -> PathBuf {
    crate::document::side_file(path, "view")
}

/// The view saved beside `path`, if there is a readable one (a bad one is ignored: the view is
/// a convenience, the document is what matters).
pub fn load_view(path: &Path) -> Option<ViewState> {
    serde_json::from_slice(&std::fs::read(view_path(path)).ok()?).ok()
}

impl EditorApp {
    /// The File menu: open, import, save, export for Spine, render, and colorize mode's files.
    pub(super) fn file_menu(&mut self, ui: &mut egui::Ui) {
        let label = ui.label("Rig or PNG path:");
        ui.text_edit_singleline(&mut self.open_path)
            .labelled_by(label.id);
        if ui.button("Open rig").clicked() {
            let path = PathBuf::from(&self.open_path);
            self.open(&path);
        }
        if ui.button("Import layer").clicked() {
            let path = PathBuf::from(&self.open_path);
            self.import_layer(&path);
        }
        if ui.button("Save").clicked() {
            self.save();
        }
        ui.separator();
        ui.label("Export folder:");
        ui.text_edit_singleline(&mut self.export_dir);
        spine_options_ui(ui, &mut self.spine_options);
        if ui.button("Export Spine").clicked() {
            let dir = PathBuf::from(&self.export_dir);
            self.message = Some(self.export_spine(&dir));
        }
        ui.label("Render the current animation to (.gif, .png sheet or a folder):");
        ui.text_edit_singleline(&mut self.render_path);
        render_settings_ui(ui, &mut self.render_settings);
        if ui
            .add_enabled(self.render.is_none(), egui::Button::new("Render"))
            .clicked()
        {
            let ctx = ui.ctx().clone();
            self.start_render(&ctx);
        }
        self.colorize_file_menu(ui);
    }

    /// Imports a PNG as a new front layer; a bad file leaves the document as it was.
    pub fn import_layer(&mut self, path: &Path) {
        let loaded = crate::io::load_png(path);
        match loaded {
            Ok(image) => {
                let name = path
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_else(|| "layer".into());
                if self.apply(Command::AddLayer(Layer {
                    name,
                    path: path.to_path_buf(),
                    image,
                })) {
                    self.view = None;
                }
            }
            Err(e) => self.message = Some(e.to_string()),
        }
    }

    /// Opens a rig file in place of the current document; on failure the current one stays.
    pub fn open(&mut self, path: &Path) {
        match Document::open(path) {
            Ok(doc) => {
                // Colorize mode's line art and strokes are not part of the rig document.
                let colorize = std::mem::take(&mut self.colorize);
                // An autosave still being written stays watched, so a new one for the same
                // file does not start beside it; a save still being written is reported when
                // it is done.
                let autosaving = self.autosaving.take();
                let saving = self.saving.take().map(|saving| Saving {
                    this_document: false,
                    ..saving
                });
                *self = EditorApp::new(doc);
                self.autosaving = autosaving;
                self.saving = saving;
                self.colorize = colorize;
                if let Some(view) = load_view(path) {
                    self.restore_view(view);
                }
            }
            Err(e) => self.message = Some(format!("cannot open {}: {e}", path.display())),
        }
    }

    /// What the view looks like now, for [`ViewState`]'s side file.
    pub fn view_state(&self) -> ViewState {
        let view = self.view.unwrap_or_default();
        ViewState {
            zoom: view.zoom,
            pan: [view.pan.x, view.pan.y],
            mode: self.mode,
            selected: self.selected.clone(),
            animation: self.animate.animation.clone(),
            time_s: self.animate.time_s,
            looping: self.timeline.looping,
            onion: self.timeline.onion,
            render: self.render_settings.clone(),
        }
    }

    /// Puts the view back as `state` describes it (a handle that no longer exists is dropped).
    pub fn restore_view(&mut self, state: ViewState) {
        self.view = Some(View {
            zoom: state.zoom.clamp(0.05, 32.0),
            pan: egui::vec2(state.pan[0], state.pan[1]),
        });
        self.mode = state.mode;
        self.selected = state
            .selected
            .filter(|n| self.doc.state().handles.names().any(|m| m == n));
        self.rig_mode.rename_to = self.selected.clone().unwrap_or_default();
        self.animate.animation = state.animation;
        self.animate.time_s = if state.time_s.is_finite() {
            state.time_s.max(0.0)
        } else {
            0.0
        };
        self.timeline.looping = state.looping;
        self.timeline.onion = animate_mode::OnionOptions {
            frames: state.onion.frames.clamp(1, animate_mode::MAX_ONION_FRAMES),
            opacity: if state.onion.opacity.is_finite() {
                state.onion.opacity.clamp(0.05, 1.0)
            } else {
                animate_mode::OnionOptions::default().opacity
            },
            ..state.onion
        };
        // The settings' ranges as File → Render edits them (a hand-edited file could ask
        // the timeline for 1e300 frames per second).
        let defaults = crate::playback::RenderSettings::default();
        let within = |v: f64, lo: f64, hi: f64, default: f64| {
            if v.is_finite() {
                v.clamp(lo, hi)
            } else {
                default
            }
        };
        self.render_settings = crate::playback::RenderSettings {
            fps: within(
                state.render.fps,
                1.0,
                crate::playback::MAX_FPS,
                defaults.fps,
            ),
            scale: within(
                state.render.scale,
                RENDER_SCALE_RANGE.0,
                RENDER_SCALE_RANGE.1,
                defaults.scale,
            ),
            ..state.render
        };
    }

    /// Saves the document and, beside it, the view; returns the message for the status bar.
    /// A document that must first be traced and meshed (never rigged) is written on another
    /// thread: the message then says it is being saved, and the status bar says when it is.
    pub fn save_to(&mut self, path: &Path) -> String {
        if self.saving.is_some() {
            return "still saving: try again when it is done".into();
        }
        if self.doc.save_needs_build() {
            let job = self.doc.save_job(path);
            let receive = write_in_background(job.clone(), self.repaint.clone());
            self.saving = Some(Saving {
                job,
                receive,
                this_document: true,
            });
            return format!("saving {}…", path.display());
        }
        if let Err(e) = self.doc.save(path) {
            return e.to_string();
        }
        self.save_view(path)
    }

    /// Writes the view beside the document saved at `path`; returns the status-bar message.
    pub(super) fn save_view(&self, path: &Path) -> String {
        let view = serde_json::to_vec_pretty(&self.view_state()).unwrap_or_default();
        match crate::io::atomic::write_atomic(&view_path(path), &view) {
            Ok(()) => format!("saved {}", path.display()),
            Err(e) => format!("saved {}, but not the view: {e}", path.display()),
        }
    }

    /// Picks up a save finished on another thread: the document takes its path (and is clean
    /// if unchanged since), the view is written beside it. A save of a document since closed
    /// is only reported.
    pub(super) fn poll_saving(&mut self) {
        let Some(outcome) = self.saving.as_ref().and_then(|s| written(&s.receive)) else {
            return;
        };
        let Some(saving) = self.saving.take() else {
            return;
        };
        self.message = Some(match outcome {
            Ok(path) if saving.this_document => {
                self.doc.saved(&saving.job);
                self.save_view(&path)
            }
            Ok(path) => format!("saved {}", path.display()),
            Err(e) => format!("cannot save {}: {e}", saving.job.target().display()),
        });
    }

    /// Whether a save is being written on another thread.
    pub fn saving(&self) -> bool {
        self.saving.is_some()
    }

    /// Exports the document for Spine's runtimes (default options, as `sinew export spine`)
    /// into `dir`; returns the message for the status bar.
    pub fn export_spine(&mut self, dir: &Path) -> String {
        let name = self
            .doc
            .path
            .as_deref()
            .and_then(Path::file_stem)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "skeleton".into());
        let options = self.spine_options.clone();
        match std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))
            .and_then(|()| {
                crate::jobs::export_spine(&self.doc, dir, &name, &options)
                    .map_err(|e| e.to_string())
            }) {
            Ok(written) => format!("exported {} files to {}", written.len(), dir.display()),
            Err(e) => e,
        }
    }

    /// Renders the current animation to [`EditorApp::render_path`] on another thread; the
    /// status bar says when it is written.
    pub fn start_render(&mut self, ctx: &egui::Context) {
        let job = match self.doc.render_job() {
            Ok(job) => job,
            Err(e) => {
                self.message = Some(e.to_string());
                return;
            }
        };
        let (send, receive) = std::sync::mpsc::channel();
        let (name, settings, output) = (
            self.animate.animation.clone(),
            self.render_settings.clone(),
            PathBuf::from(&self.render_path),
        );
        let ctx = ctx.clone();
        std::thread::spawn(move || {
            let (doc, images) = job;
            let message =
                match crate::jobs::render_animation(doc, &images, &name, &settings, &output) {
                    Ok(report) => format!(
                        "rendered {} frames to {}",
                        report.frame_count,
                        output.display()
                    ),
                    Err(e) => e.to_string(),
                };
            // The editor may have closed meanwhile.
            let _ = send.send(message);
            ctx.request_repaint();
        });
        self.message = Some("rendering…".into());
        self.render = Some(receive);
    }

    /// Whether a render is running.
    pub fn rendering(&self) -> bool {
        self.render.is_some()
    }

    pub(super) fn poll_render(&mut self) {
        if let Some(message) = self.render.as_ref().and_then(|r| r.try_recv().ok()) {
            self.message = Some(message);
            self.render = None;
        }
    }

    /// Where Save writes: the document's file, or else the File menu's path when it names a
    /// `.json` file (the field also takes the PNGs to import, which must never be written
    /// over).
    pub(super) fn save_target(&self) -> Option<PathBuf> {
        self.doc.path.clone().or_else(|| {
            let typed = PathBuf::from(self.open_path.trim());
            typed
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("json"))
                .then_some(typed)
        })
    }

    pub(super) fn save(&mut self) {
        let Some(path) = self.save_target() else {
            self.message = Some("type a .json file name in the File menu first".into());
            return;
        };
        self.message = Some(self.save_to(&path));
    }

    pub(super) fn autosave(&mut self, ctx: &egui::Context) {
        self.poll_autosave();
        self.poll_saving();
        let now = ctx.input(|i| i.time);
        if now - self.last_autosave_s < AUTOSAVE_INTERVAL_S {
            return;
        }
        self.last_autosave_s = now;
        self.autosave_scribbles();
        if self.doc.dirty && self.autosaving.is_none() {
            if let Some(path) = self.doc.path.clone() {
                self.start_autosave(&path, ctx);
            }
        }
    }

    /// Writes the document's autosave on another thread, a snapshot of the current state; does
    /// nothing while the previous one is still being written.
    pub fn start_autosave(&mut self, fallback: &Path, ctx: &egui::Context) {
        if self.autosaving.is_some() {
            return;
        }
        let job = self.doc.autosave_job(fallback);
        self.autosaving = Some(write_in_background(job, Some(ctx.clone())));
    }

    /// Picks up a finished autosave: a failure goes to the status bar.
    pub(super) fn poll_autosave(&mut self) {
        let Some(outcome) = self.autosaving.as_ref().and_then(written) else {
            return;
        };
        self.autosaving = None;
        if let Err(e) = outcome {
            self.message = Some(format!("autosave failed: {e}"));
        }
    }

    /// Whether an autosave is being written.
    pub fn autosaving(&self) -> bool {
        self.autosaving.is_some()
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
            egui::DragValue::new(&mut options.bake_fps)
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
        ui.add_enabled(on, egui::DragValue::new(&mut n).range(range));
        *value = on.then_some(n);
    });
    ui.end_row();
}

/// The fields of `sinew render`'s options.
fn render_settings_ui(ui: &mut egui::Ui, settings: &mut crate::playback::RenderSettings) {
    use crate::anim::CurveEvaluation;
    egui::Grid::new("render settings").show(ui, |ui| {
        ui.label("Frames per second");
        ui.add(
            egui::DragValue::new(&mut settings.fps)
                .range(1.0..=crate::playback::MAX_FPS)
                .speed(0.2),
        );
        ui.end_row();
        ui.label("Scale (output px per canvas px)");
        ui.add(
            egui::DragValue::new(&mut settings.scale)
                .range(RENDER_SCALE_RANGE.0..=RENDER_SCALE_RANGE.1)
                .speed(0.01),
        );
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
    });
}
