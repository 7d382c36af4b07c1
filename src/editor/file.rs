//! Files: open, import, save and autosave (written on other threads when they must trace and
//! mesh first), the view saved beside a document, File → Export Spine and File → Render, and
//! the shared save/open logic the File menu ([`super::file_menu`]), drops and the close dialog
//! call.
//!
//! In: paths typed in the File menu or dropped on the window. Out: the document read or
//! written through [`crate::document`], messages for the status bar.

use super::canvas::View;
use super::{animate_mode, EditorApp, Mode};
use crate::document::{Command, Document, DocumentError};
use crate::pipeline::Layer;
use eframe::egui;
use std::path::{Path, PathBuf};

/// Seconds between autosaves of a changed document.
pub const AUTOSAVE_INTERVAL_S: f64 = 30.0;

/// File → Render's output scale, output px per canvas px.
pub(super) const RENDER_SCALE_RANGE: (f64, f64) = (0.05, 8.0);

/// The view saved beside a document (`NAME.view.json`), so reopening shows it as it was left.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViewState {
    pub zoom: f32,
    /// Canvas origin offset, points.
    pub pan: [f32; 2],
    /// The view was the editor's fit, untouched by the user: reopening fits the canvas to the
    /// window it opens in (its size may differ) instead of restoring `zoom` and `pan`
    /// (default false: files written before this was kept restore them).
    #[serde(default)]
    pub fitted: bool,
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
    /// Imports a PNG as a new front layer; a bad file leaves the document as it was. A layered
    /// file (PSD/PSB, ORA, a Spine script's JSON) adds each visible layer as a front layer, its
    /// image written to `FILE.parts/` beside the file (see [`crate::art`]).
    pub fn import_layer(&mut self, path: &Path) {
        if crate::art::is_layered(path) {
            let options = crate::art::ArtOptions {
                parts_dir: path.with_extension("parts"),
                ..Default::default()
            };
            let loaded = crate::art::load_art(&[path.to_path_buf()], &options)
                .map_err(|e| e.to_string())
                .and_then(|art| art.write_parts().map(|_| art).map_err(|e| e.to_string()));
            match loaded {
                Ok(art) => {
                    let added = art
                        .layers
                        .into_iter()
                        .all(|l| self.apply(Command::AddLayer(l)));
                    if added {
                        self.view = None;
                        if !art.notes.is_empty() {
                            self.message = Some(art.notes.join("; "));
                        }
                    }
                }
                Err(e) => self.fail(e),
            }
            return;
        }
        let loaded = crate::io::load_png(path);
        match loaded {
            Ok(image) => {
                let name = path
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_else(|| "layer".into());
                if self.apply(Command::AddLayer(Layer::whole(name, path, image))) {
                    self.view = None;
                }
            }
            Err(e) => self.fail(e.to_string()),
        }
    }

    /// Opens a rig file in place of the current document; on failure the current one stays.
    pub fn open(&mut self, path: &Path) {
        match Document::open(path) {
            Ok(doc) => {
                self.replace_document(doc);
                if let Some(view) = load_view(path) {
                    self.restore_view(view);
                }
                self.remember_recent(path);
            }
            Err(e) => self.fail(format!("cannot open {}: {e}", path.display())),
        }
    }

    /// Starts a new, empty document in place of the current one (File → New, Ctrl+N).
    pub fn new_document(&mut self) {
        self.replace_document(Document::new());
        self.message = Some("new document".into());
    }

    /// Puts `doc` in place of the current document, with a fresh view. What is not part of the
    /// document carries over: colorize mode's line art and strokes, the recent files, the
    /// message log, writes still under way.
    fn replace_document(&mut self, doc: Document) {
        let colorize = std::mem::take(&mut self.colorize);
        let log = std::mem::take(&mut self.log);
        let recent = std::mem::take(&mut self.recent);
        let recent_file = self.recent_file.take();
        // An autosave still being written stays watched, so a new one for the same file does
        // not start beside it; a save still being written is reported when it is done.
        let autosaving = self.autosaving.take();
        let saving = self.saving.take().map(|saving| Saving {
            this_document: false,
            ..saving
        });
        let repaint = self.repaint.take();
        // Whether dialogs are native is the desktop's, not the document's.
        let dialogs = std::mem::take(&mut self.dialogs);
        *self = EditorApp::new(doc);
        self.dialogs = dialogs;
        self.autosaving = autosaving;
        self.saving = saving;
        self.colorize = colorize;
        self.log = log;
        self.recent = recent;
        self.recent_file = recent_file;
        self.repaint = repaint;
    }

    /// What the view looks like now, for [`ViewState`]'s side file.
    pub fn view_state(&self) -> ViewState {
        let view = self.view.unwrap_or_default();
        ViewState {
            zoom: view.zoom,
            pan: [view.pan.x, view.pan.y],
            fitted: self.view_untouched(),
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
        // A fitted view is fitted again on the first frame, to the area it opens in; the
        // user's view is put back as left, and kept whatever size the canvas area takes.
        self.view = (!state.fitted).then(|| View {
            zoom: state.zoom.clamp(0.05, 32.0),
            pan: egui::vec2(state.pan[0], state.pan[1]),
        });
        self.fitted = None;
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
            self.message_is_error = true;
            return format!("cannot save {}: {e}", path.display());
        }
        self.remember_recent(path);
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
                self.remember_recent(&path);
                self.save_view(&path)
            }
            Ok(path) => format!("saved {}", path.display()),
            Err(e) => {
                self.message_is_error = true;
                format!("cannot save {}: {e}", saving.job.target().display())
            }
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
                self.fail(e.to_string());
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

    /// File → Save (Ctrl+S): to the document's file; a document never saved asks where.
    pub(super) fn save(&mut self) {
        let Some(path) = self.save_target() else {
            self.message = Some("type a .json file name to save to first".into());
            self.ask_path(super::file_menu::PathAction::SaveAs);
            return;
        };
        self.message = Some(self.save_to(&path));
    }

    /// File → Save as: a rig document is a `.json` file (a typed PNG path must never be
    /// written over); the document takes the new path once it is written.
    pub fn save_as(&mut self, path: &Path) {
        if !path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        {
            self.fail(format!(
                "{}: a rig document is saved as a .json file",
                path.display()
            ));
            return;
        }
        self.message = Some(self.save_to(path));
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
        if self.doc.dirty() && self.autosaving.is_none() {
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
            self.fail(format!("autosave failed: {e}"));
        }
    }

    /// Whether an autosave is being written.
    pub fn autosaving(&self) -> bool {
        self.autosaving.is_some()
    }
}
