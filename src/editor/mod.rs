//! The editor (`sinew edit`): an egui/eframe view over [`crate::document::Document`].
//!
//! In: a rig file (or nothing), pointer and keyboard input. Out: document commands (every edit
//! goes through [`Document::apply`], so undo, checking and saving live in the library) and a
//! picture of the document. Rig builds run on a background thread ([`worker`]); the pose mode
//! keeps one precomputed skinning-IK solver per built rig and only solves while a point is
//! dragged.
//!
//! Modes: **Rig** (layers, handles, weights: draw bones and points, select, move, rename,
//! reparent, delete, compute weights with progress and cancel, see a handle's weights as a heat
//! map) and **Pose** (drag any point of the drawing and the skinning IK moves the whole shape;
//! shift-click pins a point; every drag stays as a pin of the pose) and **Animate** (keys,
//! dopesheet, curves, playback and onion skins: [`timeline`]). **Colorize** ([`colorize`])
//! scribbles colors on a line-art PNG and shows the colored result as it is solved. Rig mode's
//! Paint tool, the handle locks and the per-vertex weights readout live in [`paint`].

pub mod canvas;
pub mod closing;
pub mod colorize;
pub mod gizmo;
mod identity;
pub mod paint;
pub mod rig_tools;
pub mod timeline;
pub mod worker;

#[cfg(test)]
mod tests;

use crate::document::{Command, Document, DocumentError};
use crate::geom::Point;
use crate::ik::RigIk;
use crate::pipeline::{Layer, Scene};
use crate::rig::pose::IkDrag;
use crate::rig::{Bone, PointHandle, Pose};
use crate::skin::Blend;
use canvas::{Placed, View};
use eframe::egui::{self, Color32, Key, Modifiers, Pos2, Sense, TextureHandle};
use identity::Identity;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;
use worker::Worker;

/// Seconds between autosaves of a changed document.
pub const AUTOSAVE_INTERVAL_S: f64 = 30.0;
/// The timeline shows at least this many seconds.
pub const MIN_TIMELINE_S: f64 = 2.0;
/// File → Render's output scale, output px per canvas px.
const RENDER_SCALE_RANGE: (f64, f64) = (0.05, 8.0);
/// A press and release closer than this (canvas px) is a click, not a drag.
pub const CLICK_SLOP_PX: f64 = 2.0;

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
    pub onion: timeline::OnionOptions,
    /// File → Render's settings; the timeline plays at their frame rate.
    #[serde(default)]
    pub render: crate::playback::RenderSettings,
}

fn loops_by_default() -> bool {
    true
}

/// A save or autosave being written on another thread: its outcome arrives here.
type Writing = std::sync::mpsc::Receiver<Result<PathBuf, DocumentError>>;

/// A save being written on another thread (one that must trace and mesh first).
struct Saving {
    /// The snapshot written, for [`Document::saved`].
    job: crate::document::SaveJob,
    receive: Writing,
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

/// What the canvas edits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    Rig,
    Pose,
    Animate,
    Colorize,
}

/// What a press on the canvas does in rig mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tool {
    /// Pick a handle; drag it to move it.
    Select,
    /// Press at the head, release at the tail. Starting on a bone's tail makes it the parent.
    Bone,
    /// Click to place a point handle.
    Point,
    /// Click vertices of a cage; click the first one again (or press Enter) to close it.
    Cage,
    /// Click vertices of a region (its inside moves rigidly); close as a cage.
    Region,
    /// Paint the selected handle's weights (see [`paint`]).
    Paint,
}

/// A pointer gesture in progress.
enum Gesture {
    NewBone {
        head: [f64; 2],
        parent: Option<String>,
        tail: [f64; 2],
    },
    MoveHandle {
        name: String,
        from: [f64; 2],
        to: [f64; 2],
    },
    PoseDrag {
        /// Index of the drag in the live pose's `ik` list.
        index: usize,
        pose: Pose,
    },
    /// Grab, rotate or scale the selected handle by forward kinematics.
    Fk(Box<gizmo::FkGesture>),
    /// A cage or region being drawn, vertex by vertex (canvas px).
    NewPolygon {
        kind: rig_tools::PolygonKind,
        points: Vec<[f64; 2]>,
    },
    Pan,
    Paint(paint::PaintStroke),
}

/// Posed vertex positions of a built rig, for one pose.
struct Posed {
    scene: Identity<Scene>,
    pose: Pose,
    positions: Vec<Vec<Point>>,
    /// Per handle column, the transform shown (forward kinematics or the IK's solution).
    transforms: Vec<crate::rig::Affine>,
    /// The handles where the pose puts them (bones' heads and tails, points), for drawing.
    handles: crate::rig::Handles,
}

/// The editor's state: the document plus what only the view needs.
pub struct EditorApp {
    pub doc: Document,
    pub mode: Mode,
    pub tool: Tool,
    pub selected: Option<String>,
    /// `None` fits the canvas into the window on the next frame.
    pub view: Option<View>,
    /// Where the canvas was drawn last frame (tests convert canvas px to screen with it).
    pub placed: Option<Placed>,
    /// The last message for the user (errors, saves).
    pub message: Option<String>,
    /// Time spent in the editor's own code for the last frame (solve, skin, mesh build), ms.
    pub last_frame_ms: f64,
    pub show_help: bool,
    textures: Vec<(Identity<Layer>, TextureHandle)>,
    worker: Option<Worker>,
    gesture: Option<Gesture>,
    ik: Option<(Identity<Scene>, RigIk)>,
    /// The rig whose skinning-IK precomputation was started in the background.
    ik_warmed: Option<Identity<Scene>>,
    posed: Option<Posed>,
    open_path: String,
    rename_to: String,
    last_autosave_s: f64,
    /// The autosave being written on another thread (a document never rigged is traced and
    /// meshed to be saved, too slow for the UI thread on large images).
    autosaving: Option<Writing>,
    /// A save being written on another thread.
    saving: Option<Saving>,
    /// Where a request to close the window stands.
    closing: closing::Closing,
    /// The UI's context, for threads started outside a frame's call chain to wake it.
    repaint: Option<egui::Context>,
    /// Screenshot to take after a few frames, then quit (for `--screenshot`).
    screenshot: Option<(PathBuf, u32)>,
    /// Animate mode: the animation edited, the playhead, playback.
    pub animation: String,
    pub time_s: f64,
    pub playing: bool,
    /// Animate mode: the pose edited since the playhead last moved (not yet keyed).
    shown: Option<Pose>,
    /// Where File → Export writes.
    pub export_dir: String,
    /// File → Export Spine's options (those of `sinew export spine`).
    pub spine_options: crate::export::spine::SpineOptions,
    /// Where File → Render writes.
    pub render_path: String,
    /// File → Render's options (those of `sinew render`).
    pub render_settings: crate::playback::RenderSettings,
    /// A render under way on another thread: its message when done.
    render: Option<std::sync::mpsc::Receiver<String>>,
    /// Rig mode's polygon tools, mesh preview and automatic rig.
    pub rig_tools: rig_tools::RigTools,
    /// Colorize mode: line art, scribbles, the background solve.
    pub colorize: colorize::ColorizeEditor,
    /// Rig mode's brush settings.
    pub paint: paint::PaintSettings,
    /// Animate mode: key selection, clipboard, loop, onion skins, curve editor.
    pub timeline: timeline::TimelineState,
}

impl EditorApp {
    pub fn new(doc: Document) -> Self {
        let first_animation = doc
            .state()
            .animations
            .keys()
            .next()
            .cloned()
            .unwrap_or_else(|| "animation".into());
        let open_path = doc
            .path
            .as_ref()
            .map(|p| p.display().to_string())
            .unwrap_or_default();
        EditorApp {
            doc,
            mode: Mode::Rig,
            tool: Tool::Select,
            selected: None,
            view: None,
            placed: None,
            message: None,
            last_frame_ms: 0.0,
            show_help: false,
            textures: Vec::new(),
            worker: None,
            gesture: None,
            ik: None,
            ik_warmed: None,
            posed: None,
            open_path,
            rename_to: String::new(),
            last_autosave_s: 0.0,
            autosaving: None,
            saving: None,
            closing: Default::default(),
            repaint: None,
            screenshot: None,
            animation: first_animation,
            time_s: 0.0,
            playing: false,
            shown: None,
            export_dir: "export".into(),
            spine_options: Default::default(),
            render_path: "render.gif".into(),
            render_settings: Default::default(),
            rig_tools: Default::default(),
            render: None,
            colorize: Default::default(),
            paint: paint::PaintSettings::default(),
            timeline: Default::default(),
        }
    }

    /// Takes a screenshot to `path` once the window has drawn a few frames, then closes.
    pub fn screenshot_then_quit(&mut self, path: PathBuf) {
        self.screenshot = Some((path, 0));
    }

    /// Whether a rig build is running.
    pub fn computing(&self) -> bool {
        self.worker.is_some()
    }

    /// Applies a command, reporting a refusal as the message (the document stays as it was).
    pub fn apply(&mut self, command: Command) -> bool {
        match self.doc.apply(command) {
            Ok(()) => true,
            Err(e) => {
                self.message = Some(e.to_string());
                false
            }
        }
    }

    /// Starts computing the weights for the current handles (a no-op while one runs).
    pub fn compute_weights(&mut self, ctx: &egui::Context) {
        if self.worker.is_some() {
            return;
        }
        if self.doc.state().layers.is_empty() {
            self.message = Some("add a layer first (drop a PNG on the window)".into());
            return;
        }
        let dir = self
            .doc
            .path
            .as_deref()
            .and_then(Path::parent)
            .map(Path::to_path_buf)
            .unwrap_or_else(std::env::temp_dir);
        let ctx = ctx.clone();
        self.worker = Some(Worker::start(self.doc.rig_inputs(), dir, move || {
            ctx.request_repaint()
        }));
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
            animation: self.animation.clone(),
            time_s: self.time_s,
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
        self.rename_to = self.selected.clone().unwrap_or_default();
        self.animation = state.animation;
        self.time_s = if state.time_s.is_finite() {
            state.time_s.max(0.0)
        } else {
            0.0
        };
        self.timeline.looping = state.looping;
        self.timeline.onion = timeline::OnionOptions {
            frames: state.onion.frames.clamp(1, timeline::MAX_ONION_FRAMES),
            opacity: if state.onion.opacity.is_finite() {
                state.onion.opacity.clamp(0.05, 1.0)
            } else {
                timeline::OnionOptions::default().opacity
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
    fn save_view(&self, path: &Path) -> String {
        let view = serde_json::to_vec_pretty(&self.view_state()).unwrap_or_default();
        match crate::io::atomic::write_atomic(&view_path(path), &view) {
            Ok(()) => format!("saved {}", path.display()),
            Err(e) => format!("saved {}, but not the view: {e}", path.display()),
        }
    }

    /// Picks up a save finished on another thread: the document takes its path (and is clean
    /// if unchanged since), the view is written beside it. A save of a document since closed
    /// is only reported.
    fn poll_saving(&mut self) {
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
                self.doc
                    .export_spine(dir, &name, &options)
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
            self.animation.clone(),
            self.render_settings.clone(),
            PathBuf::from(&self.render_path),
        );
        let ctx = ctx.clone();
        std::thread::spawn(move || {
            let (doc, images) = job;
            let message =
                match crate::document::render_animation(doc, &images, &name, &settings, &output) {
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

    fn poll_render(&mut self) {
        if let Some(message) = self.render.as_ref().and_then(|r| r.try_recv().ok()) {
            self.message = Some(message);
            self.render = None;
        }
    }

    /// Where Save writes: the document's file, or else the File menu's path when it names a
    /// `.json` file (the field also takes the PNGs to import, which must never be written
    /// over).
    fn save_target(&self) -> Option<PathBuf> {
        self.doc.path.clone().or_else(|| {
            let typed = PathBuf::from(self.open_path.trim());
            typed
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("json"))
                .then_some(typed)
        })
    }

    fn save(&mut self) {
        let Some(path) = self.save_target() else {
            self.message = Some("type a .json file name in the File menu first".into());
            return;
        };
        self.message = Some(self.save_to(&path));
    }

    /// One frame of the whole editor.
    pub fn frame(&mut self, ui: &mut egui::Ui) {
        let started = Instant::now();
        let ctx = ui.ctx().clone();
        self.repaint = Some(ctx.clone());
        self.dialog_takes_input(&ctx);
        self.poll_worker();
        self.poll_render();
        self.poll_rig_tools(&ctx);
        self.warm_ik();
        self.colorize_frame_start(&ctx);
        self.dropped_files(&ctx);
        self.timeline_shortcuts(&ctx);
        self.shortcuts(&ctx);
        self.autosave(&ctx);
        self.guard_close(&ctx);
        egui::Panel::top("menu").show(ui, |ui| self.menu_bar(ui));
        self.advance_playback(&ctx);
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        if self.mode == Mode::Animate {
            egui::Panel::bottom("timeline").show(ui, |ui| self.animate_panel(ui));
        }
        egui::Panel::left("side")
            .default_size(230.0)
            .show(ui, |ui| self.side_panel(ui));
        egui::CentralPanel::default().show(ui, |ui| self.canvas(ui));
        if self.show_help {
            help_window(&ctx, &mut self.show_help);
        }
        self.close_dialog(&ctx);
        self.take_screenshot(&ctx);
        self.last_frame_ms = started.elapsed().as_secs_f64() * 1e3;
    }

    /// Starts the skinning-IK precomputation of a newly posable rig on another thread, so the
    /// first drag in pose mode does not wait for it (the scene caches the result).
    fn warm_ik(&mut self) {
        let Some(scene) = self.doc.posable() else {
            return;
        };
        if self.ik_warmed.as_ref().is_some_and(|k| k.is(scene)) {
            return;
        }
        self.ik_warmed = Some(Identity::of(scene));
        let scene = scene.clone();
        std::thread::spawn(move || {
            // Errors show up again, with a message, when the editor asks for the solver.
            let _ = scene.rig_ik();
        });
    }

    fn poll_worker(&mut self) {
        let Some(worker) = &self.worker else { return };
        if let Some(result) = worker.poll() {
            let key = worker.key.clone();
            self.worker = None;
            match result {
                Ok(scene) => {
                    if self.apply(Command::SetRig(Arc::new(scene), key)) {
                        self.message = Some("weights computed".into());
                    }
                }
                Err(DocumentError::Cancelled) => self.message = Some("cancelled".into()),
                Err(e) => self.message = Some(e.to_string()),
            }
        }
    }

    fn dropped_files(&mut self, ctx: &egui::Context) {
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        });
        for path in dropped {
            if path.extension().is_some_and(|e| e == "json") {
                self.open(&path);
            } else {
                self.import_layer(&path);
            }
        }
    }

    fn shortcuts(&mut self, ctx: &egui::Context) {
        let typing = ctx.text_edit_focused();
        let (animate, space) = ctx.input(|i| {
            (
                !typing && i.key_pressed(Key::Num3),
                !typing && i.key_pressed(Key::Space),
            )
        });
        if animate {
            self.mode = Mode::Animate;
        }
        if space && self.mode == Mode::Animate {
            self.playing = !self.playing;
        }
        let (undo, redo, delete, rig, pose, help, escape) = ctx.input_mut(|i| {
            let redo = i.consume_key(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
            let undo = i.consume_key(Modifiers::COMMAND, Key::Z);
            (
                undo,
                redo,
                !typing && i.key_pressed(Key::Delete),
                !typing && i.key_pressed(Key::Num1),
                !typing && i.key_pressed(Key::Num2),
                i.key_pressed(Key::F1) || (!typing && i.key_pressed(Key::Questionmark)),
                i.key_pressed(Key::Escape),
            )
        });
        if undo && self.gesture.is_none() {
            self.doc.undo();
        }
        if redo && self.gesture.is_none() {
            self.doc.redo();
        }
        // Pose mode selects handles to pose them; deleting one is a rig edit.
        if delete && self.mode == Mode::Rig {
            if let Some(name) = self.selected.take() {
                self.apply(Command::Delete { name });
            }
        }
        if rig {
            self.mode = Mode::Rig;
        }
        if pose {
            self.mode = Mode::Pose;
        }
        if help {
            self.show_help = !self.show_help;
        }
        if !typing && ctx.input(|i| i.key_pressed(Key::Enter)) {
            self.close_polygon();
        }
        if escape {
            self.gesture = None;
            self.show_help = false;
        }
    }

    fn autosave(&mut self, ctx: &egui::Context) {
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
    fn poll_autosave(&mut self) {
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

    fn menu_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.menu_button("File", |ui| {
                ui.label("Rig or PNG path:");
                ui.text_edit_singleline(&mut self.open_path);
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
            });
            if ui
                .add_enabled(self.can_undo_in_mode(), egui::Button::new("Undo"))
                .clicked()
            {
                self.undo_in_mode();
            }
            if ui
                .add_enabled(self.can_redo_in_mode(), egui::Button::new("Redo"))
                .clicked()
            {
                self.redo_in_mode();
            }
            ui.separator();
            ui.selectable_value(&mut self.mode, Mode::Rig, "Rig mode");
            ui.selectable_value(&mut self.mode, Mode::Pose, "Pose mode");
            ui.selectable_value(&mut self.mode, Mode::Animate, "Animate mode");
            ui.selectable_value(&mut self.mode, Mode::Colorize, "Colorize mode");
            ui.separator();
            if ui.button("Help").clicked() {
                self.show_help = !self.show_help;
            }
        });
    }

    fn status_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let state = self.doc.state();
            ui.label(format!(
                "{} layers, {} handles{}",
                state.layers.len(),
                state.handles.names().count(),
                if self.doc.dirty { ", modified" } else { "" }
            ));
            ui.separator();
            ui.label(format!("frame {:.1} ms", self.last_frame_ms));
            if let Some(message) = &self.message {
                ui.separator();
                ui.label(message);
            }
        });
    }

    fn side_panel(&mut self, ui: &mut egui::Ui) {
        // Rig mode's tools outgrow a short window: the panel scrolls.
        egui::ScrollArea::vertical().show(ui, |ui| match self.mode {
            Mode::Rig => self.rig_panel(ui),
            Mode::Pose | Mode::Animate => self.pose_panel(ui),
            Mode::Colorize => self.colorize_panel(ui),
        });
    }

    fn rig_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Tools");
        ui.horizontal(|ui| {
            ui.selectable_value(&mut self.tool, Tool::Select, "Select");
            ui.selectable_value(&mut self.tool, Tool::Bone, "Bone");
            ui.selectable_value(&mut self.tool, Tool::Point, "Point");
            ui.selectable_value(&mut self.tool, Tool::Cage, "Cage");
            ui.selectable_value(&mut self.tool, Tool::Region, "Region");
            ui.selectable_value(&mut self.tool, Tool::Paint, "Paint");
        });
        if self.tool == Tool::Paint {
            self.paint_panel(ui);
        }
        ui.separator();
        ui.heading("Handles");
        let names: Vec<String> = self.doc.state().handles.names().map(String::from).collect();
        egui::ScrollArea::vertical()
            .max_height(180.0)
            .show(ui, |ui| {
                for name in names {
                    let selected = self.selected.as_deref() == Some(name.as_str());
                    ui.horizontal(|ui| {
                        self.lock_box(ui, &name);
                        if ui.selectable_label(selected, &name).clicked() {
                            self.rename_to = name.clone();
                            self.selected = Some(name);
                        }
                    });
                }
            });
        if let Some(name) = self.selected.clone() {
            ui.separator();
            ui.label(format!("Selected: {name}"));
            ui.horizontal(|ui| {
                ui.text_edit_singleline(&mut self.rename_to);
                if ui.button("Rename").clicked() && self.rename_to != name {
                    let to = self.rename_to.clone();
                    if self.apply(Command::Rename {
                        from: name.clone(),
                        to: to.clone(),
                    }) {
                        self.selected = Some(to);
                    }
                }
            });
            let bones: Vec<String> = self
                .doc
                .state()
                .handles
                .bones
                .iter()
                .map(|b| b.name.clone())
                .collect();
            if let Some(bone) = self
                .doc
                .state()
                .handles
                .bones
                .iter()
                .find(|b| b.name == name)
            {
                let mut parent = bone.parent.clone();
                let before = parent.clone();
                egui::ComboBox::from_label("Parent")
                    .selected_text(parent.clone().unwrap_or_else(|| "(none)".into()))
                    .show_ui(ui, |ui| {
                        ui.selectable_value(&mut parent, None, "(none)");
                        for b in bones.iter().filter(|b| **b != name) {
                            ui.selectable_value(&mut parent, Some(b.clone()), b);
                        }
                    });
                if parent != before {
                    self.apply(Command::Reparent {
                        bone: name.clone(),
                        parent,
                    });
                }
            }
            if ui.button("Delete").clicked() {
                self.apply(Command::Delete { name });
                self.selected = None;
            }
        }
        ui.separator();
        ui.heading("Weights");
        let mut options = self.doc.state().options.clone();
        let before = options.clone();
        use crate::weights::WeightMethod;
        egui::ComboBox::from_label("Method")
            .selected_text(format!("{:?}", options.weights.method))
            .show_ui(ui, |ui| {
                for m in [
                    WeightMethod::Bbw,
                    WeightMethod::Harmonic,
                    WeightMethod::Biharmonic,
                    WeightMethod::Rigid,
                ] {
                    ui.selectable_value(&mut options.weights.method, m, format!("{m:?}"));
                }
            });
        if options != before {
            self.apply(Command::SetOptions(options));
        }
        match &self.worker {
            Some(worker) => {
                let (done, total) = worker.progress();
                ui.add(
                    egui::ProgressBar::new(done as f32 / total.max(1) as f32)
                        .text(format!("computing weights: part {done} of {total}")),
                );
                if ui.button("Cancel").clicked() {
                    worker.cancel();
                }
            }
            None => {
                let current = self.doc.posable().is_some();
                let label = if current {
                    "Weights are up to date"
                } else {
                    "Weights need computing"
                };
                ui.label(label);
                if ui.button("Compute weights").clicked() {
                    let ctx = ui.ctx().clone();
                    self.compute_weights(&ctx);
                }
            }
        }
        self.vertex_weights_panel(ui);
        self.rig_tools_panel(ui);
    }

    fn pose_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Pose");
        if self.doc.posable().is_none() {
            ui.label("Compute the weights in rig mode to pose.");
            return;
        }
        ui.label("Drag any point of the drawing; shift-click pins a point.");
        let pins = self.doc.state().pose.ik.len();
        ui.label(format!("{pins} pins and drags"));
        if ui.button("Clear pins").clicked() {
            let mut pose = self.doc.state().pose.clone();
            pose.ik.clear();
            self.apply(Command::SetPose(pose));
        }
        if ui.button("Rest pose").clicked() {
            self.apply(Command::SetPose(Pose::default()));
        }
    }

    /// The texture of each layer, uploaded once per layer image.
    fn textures(&mut self, ctx: &egui::Context) -> Vec<TextureHandle> {
        let layers = self.doc.state().layers.clone();
        let mut out = Vec::with_capacity(layers.len());
        for layer in &layers {
            if let Some((_, t)) = self.textures.iter().find(|(k, _)| k.is(layer)) {
                out.push(t.clone());
                continue;
            }
            let image = egui::ColorImage::from_rgba_unmultiplied(
                [layer.image.width() as usize, layer.image.height() as usize],
                layer.image.as_raw(),
            );
            let texture = ctx.load_texture(&layer.name, image, egui::TextureOptions::LINEAR);
            self.textures.push((Identity::of(layer), texture.clone()));
            out.push(texture);
        }
        self.textures
            .retain(|(k, _)| layers.iter().any(|l| k.is(l)));
        out
    }

    /// Posed positions of `scene` for `pose`, solved with the kept IK solver when it has drags.
    fn posed(&mut self, scene: &Arc<Scene>, pose: &Pose) -> Result<(), String> {
        if self
            .posed
            .as_ref()
            .is_some_and(|p| p.scene.is(scene) && p.pose == *pose)
        {
            return Ok(());
        }
        let (transforms, positions) =
            timeline::transforms_and_positions(scene, pose, &mut self.ik)?;
        let map = |t: &crate::rig::pose::Affine, p: [f64; 2]| {
            let q = t.apply(Point::new(p[0], p[1]));
            [q.x, q.y]
        };
        let mut handles = scene.doc.handles.clone();
        let bone_count = handles.bones.len();
        for (b, t) in handles.bones.iter_mut().zip(&transforms) {
            (b.head, b.tail) = (map(t, b.head), map(t, b.tail));
        }
        for (p, t) in handles
            .points
            .iter_mut()
            .zip(transforms.iter().skip(bone_count))
        {
            p.at = map(t, p.at);
        }
        // Cage vertices follow the points in column order, one column each.
        let mut cage_columns = transforms.iter().skip(bone_count + handles.points.len());
        for cage in &mut handles.cages {
            for (v, t) in cage.polygon.iter_mut().zip(cage_columns.by_ref()) {
                *v = map(t, *v);
            }
        }
        self.posed = Some(Posed {
            scene: Identity::of(scene),
            pose: pose.clone(),
            positions,
            transforms,
            handles,
        });
        Ok(())
    }

    fn canvas(&mut self, ui: &mut egui::Ui) {
        if self.mode == Mode::Colorize {
            return self.colorize_canvas(ui);
        }
        let ctx = ui.ctx().clone();
        let textures = self.textures(&ctx);
        let (response, painter) = ui.allocate_painter(ui.available_size(), Sense::click_and_drag());
        let rect = response.rect;
        painter.rect_filled(rect, 0.0, Color32::from_gray(40));
        let canvas_px = self
            .doc
            .state()
            .layers
            .first()
            .map(|l| [l.image.width(), l.image.height()])
            .unwrap_or([512, 512]);
        let placed = self.place_canvas(&ctx, &response, canvas_px);
        let posable = self.doc.posable().cloned();
        let live_pose = match &self.gesture {
            Some(Gesture::PoseDrag { pose, .. }) => Some(pose.clone()),
            Some(Gesture::Fk(g)) => Some(g.preview.clone()),
            _ => None,
        };
        let mut shapes = Vec::new();
        let mut posed_handles = None;
        match (self.mode, &posable) {
            (Mode::Pose | Mode::Animate, Some(scene)) => {
                let pose = live_pose.unwrap_or_else(|| self.edited_pose());
                shapes.extend(self.onion_shapes(scene, &placed));
                if let Err(e) = self.posed(scene, &pose) {
                    self.message = Some(e);
                }
                if let Some(posed) = &self.posed {
                    for (k, part) in scene.doc.parts.iter().enumerate() {
                        if let (Some(texture), Some(positions)) =
                            (textures.get(k), posed.positions.get(k))
                        {
                            shapes.push(canvas::textured_mesh(
                                &placed,
                                texture,
                                canvas_px,
                                &part.mesh.vertices,
                                positions,
                                &part.mesh.triangles,
                            ));
                        }
                    }
                    posed_handles = Some(posed.handles.clone());
                    for drag in &pose.ik {
                        let s = placed.screen_from_canvas(drag.to);
                        shapes.push(egui::Shape::circle_filled(s, 4.0, Color32::RED));
                    }
                }
            }
            _ => {
                for texture in &textures {
                    shapes.push(canvas::image_quad(&placed, texture, canvas_px));
                }
                if let (Some(scene), Some(name)) = (&self.doc.state().rig, &self.selected) {
                    for (k, part) in scene.doc.parts.iter().enumerate() {
                        let rest: Vec<Point> = part
                            .mesh
                            .vertices
                            .iter()
                            .map(|p| Point::new(p[0], p[1]))
                            .collect();
                        shapes.extend(canvas::wireframe(&placed, &rest, &part.mesh.triangles));
                        if let (Some(weights), true) = (&part.weights, posable.is_some()) {
                            shapes.extend(match self.shown_rows(k) {
                                Some(rows) => paint::heat_map_rows(
                                    &placed,
                                    weights,
                                    rows,
                                    name,
                                    &rest,
                                    &part.mesh.triangles,
                                ),
                                None => canvas::heat_map(
                                    &placed,
                                    weights,
                                    name,
                                    &rest,
                                    &part.mesh.triangles,
                                ),
                            });
                        }
                    }
                }
            }
        }
        let mut handles = posed_handles.unwrap_or_else(|| self.doc.state().handles.clone());
        match &self.gesture {
            Some(Gesture::NewBone { head, parent, tail }) => handles.bones.push(Bone {
                name: String::new(),
                parent: parent.clone(),
                head: *head,
                tail: *tail,
            }),
            Some(Gesture::MoveHandle { name, from, to }) => {
                move_handle(&mut handles, name, [to[0] - from[0], to[1] - from[1]])
            }
            _ => {}
        }
        shapes.extend(self.mesh_shapes(&placed));
        shapes.extend(canvas::handles(&placed, &handles, self.selected.as_deref()));
        shapes.extend(self.polygon_shapes(&placed, response.hover_pos()));
        if let (Mode::Pose | Mode::Animate, Some(scene)) = (self.mode, &posable) {
            if let Some(target) = self.fk_target(scene) {
                let active = match &self.gesture {
                    Some(Gesture::Fk(g)) => Some(g.kind),
                    _ => None,
                };
                shapes.extend(gizmo::shapes(&placed, &target, active));
            }
        }
        self.track_hover(&response, &placed);
        if self.mode == Mode::Rig && self.tool == Tool::Paint {
            shapes.extend(self.brush_shape(&placed));
        }
        painter.extend(shapes);
        match self.mode {
            Mode::Rig => self.rig_gestures(&ctx, &response, placed),
            Mode::Pose | Mode::Animate => {
                if let Some(scene) = posable {
                    self.pose_gestures(&ctx, &response, placed, &scene)
                }
            }
            Mode::Colorize => {}
        }
    }

    /// Places an image of `size_px` on the canvas `response` covers (fitted the first time,
    /// then as zoomed and panned), remembers it for picking and applies this frame's zoom and
    /// pan.
    fn place_canvas(
        &mut self,
        ctx: &egui::Context,
        response: &egui::Response,
        size_px: [u32; 2],
    ) -> Placed {
        let rect = response.rect;
        let view = *self
            .view
            .get_or_insert_with(|| canvas::fit(size_px, rect.size()));
        let placed = Placed {
            view,
            origin: rect.min,
        };
        self.placed = Some(placed);
        self.zoom_and_pan(ctx, response, placed);
        placed
    }

    fn zoom_and_pan(&mut self, ctx: &egui::Context, response: &egui::Response, placed: Placed) {
        if !response.hovered() {
            return;
        }
        let (scroll, pointer) = ctx.input(|i| (i.smooth_scroll_delta().y, i.pointer.hover_pos()));
        if scroll != 0.0 {
            if let (Some(view), Some(at)) = (self.view.as_mut(), pointer) {
                let anchor = placed.canvas_from_screen(at);
                view.zoom = (view.zoom * (scroll / 200.0).exp()).clamp(0.05, 32.0);
                // Keep the canvas point under the pointer where it was.
                let moved = Placed {
                    view: *view,
                    origin: placed.origin,
                }
                .screen_from_canvas(anchor);
                view.pan += at - moved;
            }
        }
        if response.dragged_by(egui::PointerButton::Middle) {
            if let Some(view) = self.view.as_mut() {
                view.pan += response.drag_delta();
            }
        }
    }

    fn rig_gestures(&mut self, ctx: &egui::Context, response: &egui::Response, placed: Placed) {
        if self.tool == Tool::Paint {
            self.paint_gestures(ctx, response, placed);
            return;
        }
        let pointer = response.interact_pointer_pos();
        if response.drag_started_by(egui::PointerButton::Primary) {
            // Where the button went down, not where the drag was recognized.
            let origin = ctx.input(|i| i.pointer.press_origin()).or(pointer);
            if let Some(at) = origin {
                let c = placed.canvas_from_screen(at);
                let handles = &self.doc.state().handles;
                self.gesture = match self.tool {
                    Tool::Bone => {
                        // Starting on a bone's tail continues that skeleton.
                        let parent = handles.bones.iter().find(|b| {
                            placed.screen_from_canvas(b.tail).distance(at) <= canvas::PICK_RADIUS_PT
                        });
                        Some(Gesture::NewBone {
                            head: parent.map_or(c, |b| b.tail),
                            parent: parent.map(|b| b.name.clone()),
                            tail: c,
                        })
                    }
                    Tool::Select => match canvas::pick(&placed, handles, at) {
                        Some(name) => {
                            self.rename_to = name.clone();
                            self.selected = Some(name.clone());
                            Some(Gesture::MoveHandle {
                                name,
                                from: c,
                                to: c,
                            })
                        }
                        None => Some(Gesture::Pan),
                    },
                    Tool::Point | Tool::Cage | Tool::Region | Tool::Paint => None,
                };
            }
        }
        if let (Some(at), true) = (pointer, response.dragged()) {
            let c = placed.canvas_from_screen(at);
            match &mut self.gesture {
                Some(Gesture::NewBone { tail, .. }) => *tail = c,
                Some(Gesture::MoveHandle { to, .. }) => *to = c,
                Some(Gesture::Pan) => {
                    if let Some(view) = self.view.as_mut() {
                        view.pan += response.drag_delta();
                    }
                }
                _ => {}
            }
        }
        if response.drag_stopped() {
            match self.gesture.take() {
                Some(Gesture::NewBone { head, parent, tail })
                    if distance(head, tail) >= CLICK_SLOP_PX =>
                {
                    let name = self.unique_name("bone");
                    if self.apply(Command::AddBone(Bone {
                        name: name.clone(),
                        parent,
                        head,
                        tail,
                    })) {
                        self.selected = Some(name);
                    }
                }
                Some(Gesture::MoveHandle { name, from, to }) if distance(from, to) > 0.0 => {
                    let mut handles = self.doc.state().handles.clone();
                    move_handle(&mut handles, &name, [to[0] - from[0], to[1] - from[1]]);
                    if let Some(b) = handles.bones.iter().find(|b| b.name == name) {
                        self.apply(Command::MoveBone {
                            name,
                            head: b.head,
                            tail: b.tail,
                        });
                    } else if let Some(p) = handles.points.iter().find(|p| p.name == name) {
                        self.apply(Command::MovePoint { name, at: p.at });
                    } else if let Some(polygon) = handles
                        .cages
                        .iter()
                        .map(|c| (&c.name, &c.polygon))
                        .chain(handles.regions.iter().map(|r| (&r.name, &r.polygon)))
                        .find(|(n, _)| **n == name)
                        .map(|(_, p)| p.clone())
                    {
                        self.apply(Command::SetPolygon { name, polygon });
                    }
                }
                _ => {}
            }
        }
        if response.clicked() {
            if let Some(at) = pointer {
                let c = placed.canvas_from_screen(at);
                match self.tool {
                    Tool::Cage => self.polygon_click(rig_tools::PolygonKind::Cage, c, &placed),
                    Tool::Region => self.polygon_click(rig_tools::PolygonKind::Region, c, &placed),
                    Tool::Point => {
                        let name = self.unique_name("point");
                        if self.apply(Command::AddPoint(PointHandle {
                            name: name.clone(),
                            at: c,
                        })) {
                            self.selected = Some(name);
                        }
                    }
                    _ => {
                        self.selected = canvas::pick(&placed, &self.doc.state().handles, at);
                        if let Some(name) = &self.selected {
                            self.rename_to = name.clone();
                        }
                    }
                }
            }
        }
    }

    fn pose_gestures(
        &mut self,
        ctx: &egui::Context,
        response: &egui::Response,
        placed: Placed,
        scene: &Arc<Scene>,
    ) {
        if self.fk_gestures(ctx, response, placed, scene) {
            return;
        }
        let pointer = response.interact_pointer_pos();
        let shift = ctx.input(|i| i.modifiers.shift);
        let grab = |app: &EditorApp, at: Pos2| -> Option<[f64; 2]> {
            let posed = app.posed.as_ref()?;
            rest_point_under(scene, &posed.positions, placed.canvas_from_screen(at))
        };
        if response.drag_started_by(egui::PointerButton::Primary) {
            // Where the button went down, not where the drag was recognized.
            let origin = ctx.input(|i| i.pointer.press_origin()).or(pointer);
            if let Some(at) = origin {
                let c = placed.canvas_from_screen(at);
                let mut pose = self.edited_pose();
                // Grabbing an existing pin moves it; anywhere else on the drawing adds a drag.
                let existing = pose.ik.iter().position(|d| {
                    placed.screen_from_canvas(d.to).distance(at) <= canvas::PICK_RADIUS_PT
                });
                let index = match existing {
                    Some(i) => Some(i),
                    None => grab(self, at).map(|rest| {
                        pose.ik.push(IkDrag {
                            at: rest,
                            to: c,
                            weight: None,
                        });
                        pose.ik.len() - 1
                    }),
                };
                if let Some(index) = index {
                    self.gesture = Some(Gesture::PoseDrag { index, pose });
                }
            }
        }
        if let (Some(at), true) = (pointer, response.dragged()) {
            if let Some(Gesture::PoseDrag { index, pose }) = &mut self.gesture {
                pose.ik[*index].to = placed.canvas_from_screen(at);
            }
        }
        if response.drag_stopped() {
            if let Some(Gesture::PoseDrag { pose, .. }) = self.gesture.take() {
                self.commit_pose(pose);
            }
        }
        if response.clicked() && !shift {
            // A click selects the handle under it (for the gizmo and G/R/S), or nothing.
            if let (Some(at), Some(posed)) = (pointer, &self.posed) {
                self.selected = canvas::pick(&placed, &posed.handles, at);
            }
        }
        if response.clicked() && shift {
            if let Some(at) = pointer {
                if let Some(rest) = grab(self, at) {
                    let mut pose = self.edited_pose();
                    pose.ik.push(IkDrag {
                        at: rest,
                        to: placed.canvas_from_screen(at),
                        weight: None,
                    });
                    self.commit_pose(pose);
                }
            }
        }
    }

    /// Where the selected bone or point is shown, for its gizmo; `None` when nothing posable
    /// is selected.
    fn fk_target(&self, scene: &Arc<Scene>) -> Option<crate::rig::fk_edit::FkTarget> {
        let (name, posed) = (self.selected.as_deref()?, self.posed.as_ref()?);
        crate::rig::fk_edit::target(&scene.doc.handles, &posed.transforms, name).ok()
    }

    /// The FK gizmo and the G/R/S keys. Returns whether they took the pointer this frame.
    fn fk_gestures(
        &mut self,
        ctx: &egui::Context,
        response: &egui::Response,
        placed: Placed,
        scene: &Arc<Scene>,
    ) -> bool {
        let handles = &scene.doc.handles;
        let hover = ctx.input(|i| i.pointer.hover_pos());
        if let Some(Gesture::Fk(g)) = &mut self.gesture {
            let pointer = if g.modal {
                hover
            } else {
                response.interact_pointer_pos()
            };
            if let Some(at) = pointer {
                if let Err(e) = g.update(handles, placed.canvas_from_screen(at)) {
                    self.message = Some(e.to_string());
                }
            }
            let (confirm, cancel) = if g.modal {
                (response.clicked(), response.secondary_clicked())
            } else {
                (response.drag_stopped(), false)
            };
            if confirm {
                if let Some(Gesture::Fk(g)) = self.gesture.take() {
                    self.commit_pose(g.preview);
                }
            } else if cancel {
                self.gesture = None;
            }
            return true;
        }
        if self.gesture.is_some() {
            return false;
        }
        let (Some(name), Some(target)) = (self.selected.clone(), self.fk_target(scene)) else {
            return false;
        };
        let typing = ctx.text_edit_focused();
        let key = ctx.input(|i| {
            [
                (Key::G, gizmo::FkKind::Grab),
                (Key::R, gizmo::FkKind::Rotate),
                (Key::S, gizmo::FkKind::Scale),
            ]
            .into_iter()
            .find(|(k, _)| !typing && i.modifiers.is_none() && i.key_pressed(*k))
            .map(|(_, kind)| kind)
        });
        let pressed = if response.drag_started_by(egui::PointerButton::Primary) {
            ctx.input(|i| i.pointer.press_origin())
                .and_then(|at| Some((gizmo::hit(&placed, &target, at)?, at)))
        } else {
            None
        };
        let (kind, at, modal) = match (key, hover, pressed) {
            (Some(kind), Some(at), _) => (kind, at, true),
            (_, _, Some((kind, at))) => (kind, at, false),
            _ => return false,
        };
        let Some(shown) = self.posed.as_ref().map(|p| p.transforms.clone()) else {
            return false;
        };
        match gizmo::FkGesture::start(
            handles,
            &self.edited_pose(),
            &shown,
            &name,
            kind,
            placed.canvas_from_screen(at),
            modal,
        ) {
            Ok(g) => self.gesture = Some(Gesture::Fk(Box::new(g))),
            Err(e) => self.message = Some(e.to_string()),
        }
        true
    }

    /// The pose the canvas edits: the document's in pose mode; in animate mode the pose being
    /// prepared for a key (the animation sampled at the current time until it is edited).
    pub fn edited_pose(&self) -> Pose {
        match self.mode {
            Mode::Animate => self.shown.clone().unwrap_or_else(|| self.sampled_pose()),
            _ => self.doc.state().pose.clone(),
        }
    }

    /// The current animation at the current time (clamped to its keys).
    pub fn sampled_pose(&self) -> Pose {
        crate::document::animation_named(self.doc.state(), &self.animation)
            .sample(self.time_s, false)
    }

    fn commit_pose(&mut self, pose: Pose) {
        match self.mode {
            Mode::Animate => self.shown = Some(pose),
            _ => {
                self.apply(Command::SetPose(pose));
            }
        }
    }

    fn unique_name(&self, stem: &str) -> String {
        let handles = &self.doc.state().handles;
        (1..)
            .map(|k| format!("{stem}{k}"))
            .find(|n| !handles.names().any(|m| m == n))
            .unwrap_or_else(|| stem.to_string())
    }

    fn take_screenshot(&mut self, ctx: &egui::Context) {
        // Background work first: the picture shows its result.
        if self.computing() || self.colorize.solving() || self.rig_tools.proposing() {
            return;
        }
        let Some((path, frames)) = &mut self.screenshot else {
            return;
        };
        *frames += 1;
        if *frames == SCREENSHOT_AFTER_FRAMES {
            ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(Default::default()));
        }
        let shot = ctx.input(|i| {
            i.raw.events.iter().find_map(|e| match e {
                egui::Event::Screenshot { image, .. } => Some(image.clone()),
                _ => None,
            })
        });
        if let Some(image) = shot {
            let [w, h] = image.size;
            let bytes: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
            let saved = image::RgbaImage::from_raw(w as u32, h as u32, bytes)
                .ok_or_else(|| "screenshot size mismatch".to_string())
                .and_then(|img| {
                    let mut png = Vec::new();
                    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
                        .map_err(|e| e.to_string())?;
                    crate::io::atomic::write_atomic(path, &png).map_err(|e| e.to_string())
                });
            if let Err(e) = saved {
                eprintln!("sinew edit: screenshot: {e}");
            }
            self.close(ctx);
        } else {
            ctx.request_repaint();
        }
    }
}

/// Frames drawn before `--screenshot` takes its picture (fonts and textures settle).
const SCREENSHOT_AFTER_FRAMES: u32 = 5;

impl eframe::App for EditorApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.frame(ui);
    }

    fn logic(&mut self, ctx: &egui::Context, _frame: &mut eframe::Frame) {
        self.close_requests(ctx);
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        self.finish_writes();
    }
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Moves handle `name` by `delta_px`.
fn move_handle(handles: &mut crate::rig::Handles, name: &str, delta_px: [f64; 2]) {
    let shift = |p: &mut [f64; 2]| {
        p[0] += delta_px[0];
        p[1] += delta_px[1];
    };
    if let Some(b) = handles.bones.iter_mut().find(|b| b.name == name) {
        shift(&mut b.head);
        shift(&mut b.tail);
    }
    if let Some(p) = handles.points.iter_mut().find(|p| p.name == name) {
        shift(&mut p.at);
    }
    let polygons = handles
        .cages
        .iter_mut()
        .map(|c| (&c.name, &mut c.polygon))
        .chain(
            handles
                .regions
                .iter_mut()
                .map(|r| (&r.name, &mut r.polygon)),
        );
    for (_, polygon) in polygons.filter(|(n, _)| *n == name) {
        polygon.iter_mut().for_each(shift);
    }
}

/// The rest position of the drawing's point shown at `at_px` (canvas px) in the posed
/// `positions`: the frontmost part whose posed triangle contains it, barycentrically.
pub fn rest_point_under(
    scene: &Scene,
    positions: &[Vec<Point>],
    at_px: [f64; 2],
) -> Option<[f64; 2]> {
    let p = Point::new(at_px[0], at_px[1]);
    for (part, posed) in scene.doc.parts.iter().zip(positions).rev() {
        for t in &part.mesh.triangles {
            let [a, b, c] = t.map(|i| posed[i as usize]);
            let Some([wa, wb, wc]) = crate::geom::barycentric(p, a, b, c) else {
                continue;
            };
            if wa >= 0.0 && wb >= 0.0 && wc >= 0.0 {
                let rest = t.map(|i| part.mesh.vertices[i as usize]);
                return Some([
                    wa * rest[0][0] + wb * rest[1][0] + wc * rest[2][0],
                    wa * rest[0][1] + wb * rest[1][1] + wc * rest[2][1],
                ]);
            }
        }
    }
    None
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

fn help_window(ctx: &egui::Context, open: &mut bool) {
    egui::Window::new("Keyboard shortcuts")
        .open(open)
        .collapsible(false)
        .show(ctx, |ui| {
            egui::Grid::new("shortcuts").show(ui, |ui| {
                for (keys, what) in SHORTCUTS {
                    ui.label(*keys);
                    ui.label(*what);
                    ui.end_row();
                }
            });
        });
}

/// The shortcuts the help overlay lists (every one of them works).
pub const SHORTCUTS: &[(&str, &str)] = &[
    (
        "1 / 2 / 3 / 4",
        "rig mode / pose mode / animate mode / colorize mode",
    ),
    ("Space", "play or pause (animate mode)"),
    ("Ctrl+Z", "undo"),
    ("Ctrl+Shift+Z", "redo"),
    (
        "Delete",
        "delete the selected handle (rig mode), the selected keys (animate mode)",
    ),
    ("Shift+click", "pin a point (pose mode)"),
    ("Click", "select the handle under the pointer (pose mode)"),
    (
        "Enter",
        "close the cage or region being drawn (or click its first vertex)",
    ),
    (
        "G / R / S",
        "grab / rotate / scale the selected bone or point (pose mode; click confirms, \
         Esc or right click cancels); or drag its gizmo's centre / ring / square",
    ),
    ("Mouse wheel", "zoom about the pointer"),
    ("Middle drag", "pan"),
    ("Esc", "cancel the gesture, close this help"),
    ("F1 or ?", "this help"),
    (
        "B / E / V",
        "colorize mode: brush / eraser / result or scribbles only",
    ),
    (
        "Ctrl+C / Ctrl+V",
        "copy the selected keys / paste them at the playhead",
    ),
];

/// What `sinew edit` starts with.
#[derive(Clone, Debug)]
pub struct Start {
    /// The rig to open; none: an empty document.
    pub rig: Option<PathBuf>,
    /// The mode to start in; none: the saved view's (or rig mode).
    pub mode: Option<Mode>,
    /// A pose to start with.
    pub pose: Option<Pose>,
    /// A handle to select (rig mode shows its weights).
    pub select: Option<String>,
    /// Take a picture of the first frames to this PNG, then quit.
    pub screenshot: Option<PathBuf>,
    /// Line art to open in colorize mode.
    pub line_art: Option<PathBuf>,
    /// Scribbles (the JSON file of `sinew colorize --scribbles`) to draw on the line art.
    pub scribbles: Option<PathBuf>,
}

/// Opens the editor window.
pub fn run(start: Start) -> anyhow::Result<()> {
    let doc = match &start.rig {
        Some(p) => Document::open(p)?,
        None => Document::new(),
    };
    let mut app = EditorApp::new(doc);
    if let Some(view) = start.rig.as_deref().and_then(load_view) {
        app.restore_view(view);
    }
    if let Some(mode) = start.mode {
        app.mode = mode;
    }
    if let Some(pose) = start.pose {
        app.doc.apply(Command::SetPose(pose))?;
    }
    if let Some(name) = start.select {
        if !app.doc.state().handles.names().any(|n| n == name) {
            anyhow::bail!("the rig has no handle named '{name}'");
        }
        app.rename_to = name.clone();
        app.selected = Some(name);
    }
    if let Some(path) = &start.line_art {
        app.open_lineart(path);
        if app.colorize.session.is_none() {
            anyhow::bail!(
                "{}",
                app.message
                    .clone()
                    .unwrap_or_else(|| format!("{}: cannot open", path.display()))
            );
        }
    }
    if let Some(path) = &start.scribbles {
        if app.colorize.session.is_none() {
            anyhow::bail!("--scribbles needs --line-art to draw on");
        }
        if !app.load_scribbles(path) {
            anyhow::bail!("{}", app.message.clone().unwrap_or_default());
        }
    }
    if let Some(shot) = start.screenshot {
        app.screenshot_then_quit(shot);
    }
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([1280.0, 800.0])
            .with_title("sinew")
            .with_drag_and_drop(true),
        ..Default::default()
    };
    eframe::run_native("sinew", options, Box::new(|_| Ok(Box::new(app))))
        .map_err(|e| anyhow::anyhow!("the editor window failed: {e}"))
}
