//! The editor (`sinew edit`): an egui/eframe view over [`crate::document::Document`].
//!
//! In: a rig file (or nothing), pointer and keyboard input. Out: document commands (every edit
//! goes through [`Document::apply`], so undo, checking and saving live in the library) and a
//! picture of the document. Rig builds run on a background thread ([`worker`]).
//!
//! This module is the app: its state, the menu bar, the shortcuts and the dispatch to the
//! modes, each with its own state and UI: **Rig** ([`rig_mode`], with [`rig_tools`] and
//! [`paint`]), **Pose** ([`pose_mode`], with the FK [`gizmo`]), **Animate** ([`animate_mode`]:
//! playhead, playback, onion skins; [`timeline`]: dopesheet and curves; [`apply_motion`]: a
//! capture retargeted as an animation) and **Colorize**
//! ([`colorize`]). The canvas ([`drawing`], helpers in [`canvas`]) draws a pose as `sinew
//! render` does: posed through [`pose_mode::pose_frame`] (or [`crate::scene::Playhead`] at the
//! playhead), drawn from the library's draw list
//! ([`crate::playback::pose_draws`]) by its renderer. Files are [`file`]'s; the File menu, its
//! windows and its shortcuts [`file_menu`]'s; the status bar's messages and their log
//! [`messages`]'.

pub mod animate_mode;
pub mod animation_list;
pub mod apply_motion;
pub mod canvas;
pub mod closing;
pub mod colorize;
pub mod curves;
pub mod deform_tool;
pub mod drawing;
pub mod events;
pub mod file;
pub mod file_menu;
pub mod gizmo;
pub mod graph_view;
mod identity;
pub mod key_menu;
pub mod messages;
pub mod native_dialog;
pub mod number_field;
pub mod numbers;
pub mod paint;
pub mod physics_fields;
pub mod pose_mode;
pub mod rig_mode;
pub mod rig_tools;
pub mod ticks;
pub mod timeline;
pub mod tree;
pub mod view;
pub mod worker;

#[cfg(test)]
mod tests;

pub use file::{load_view, view_path, ViewState, AUTOSAVE_INTERVAL_S};
pub use pose_mode::rest_point_under;
pub use rig_mode::Tool;

use crate::document::{Command, Document};
use crate::geom::Point;
use crate::rig::Pose;
use canvas::{Placed, View};
use eframe::egui::{self, Key, Modifiers};
use std::path::PathBuf;
use std::time::Instant;

/// The timeline shows at least this many seconds.
pub const MIN_TIMELINE_S: f64 = 2.0;
/// A press and release closer than this (canvas px) is a click, not a drag.
pub const CLICK_SLOP_PX: f64 = 2.0;

/// What the canvas edits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    Rig,
    Pose,
    Animate,
    Colorize,
}

/// A pointer gesture in progress.
enum Gesture {
    NewBone {
        head: Point,
        parent: Option<String>,
        tail: Point,
    },
    MoveHandle {
        name: String,
        from: Point,
        to: Point,
    },
    PoseDrag {
        /// Index of the drag in the live pose's `ik` list.
        index: usize,
        pose: Pose,
        /// From the pointer to the drag's target, canvas px (the target starts where the
        /// gripped point is shown, then follows the pointer's motion).
        offset: crate::geom::Vec2,
    },
    /// Grab, rotate or scale the selected handle by forward kinematics.
    Fk(Box<gizmo::FkGesture>),
    /// A cage or region being drawn, vertex by vertex (canvas px).
    NewPolygon {
        kind: rig_tools::PolygonKind,
        points: Vec<Point>,
    },
    Pan,
    Paint(paint::PaintStroke),
    /// A field of the numbers panel being dragged: the pose it shows ([`numbers`]).
    Numbers(Pose),
    /// Mesh vertices dragged by animate mode's deform tool ([`deform_tool`]).
    Deform(deform_tool::DeformDrag),
}

/// The editor's state: the document plus what only the view needs.
pub struct EditorApp {
    pub doc: Document,
    pub mode: Mode,
    /// The handle selected (rig mode edits it, pose mode poses it).
    pub selected: Option<String>,
    /// `None` fits the canvas into the window on the next frame.
    pub view: Option<View>,
    /// A change of the view (View menu, Home, F, Ctrl+0) for the next frame.
    pub view_request: Option<view::ViewRequest>,
    /// The view the editor fitted last: while [`Self::view`] is still it, a change of the
    /// canvas area's size fits it again ([`EditorApp::place_view`]).
    pub fitted: Option<view::Fitted>,
    /// Where the canvas was drawn last frame (tests convert canvas px to screen with it).
    pub placed: Option<Placed>,
    /// The last message for the user (errors, saves).
    pub message: Option<String>,
    /// Time spent in the editor's own code for the last frame (solve, skin, draw), ms.
    pub last_frame_ms: f64,
    /// The whole previous frame as eframe measures it (the GL draw included), ms; `None`
    /// outside a window (tests).
    pub whole_frame_ms: Option<f64>,
    /// Where frame times are logged (`sinew edit --frame-log`).
    pub frame_log: Option<FrameLog>,
    pub show_help: bool,
    gesture: Option<Gesture>,
    /// Rig mode: tool, rename field, weight build.
    pub rig_mode: rig_mode::RigMode,
    /// Pose mode: the pose shown, posed.
    pub pose_mode: pose_mode::PoseMode,
    /// Animate mode: the animation edited, the playhead, playback, onion skins.
    pub animate: animate_mode::AnimateMode,
    /// Animate mode's list of animations.
    pub animations: animation_list::AnimationList,
    /// Animate mode's *Apply motion* window.
    pub motion: apply_motion::ApplyMotionWindow,
    /// The canvas: layer textures and the picture of the posed drawing.
    pub drawing: drawing::Drawing,
    /// The File menu's path field (rigs to open, PNGs to import, where to save).
    open_path: String,
    /// The File menu's windows (typed paths, Export Spine, Render, New's question).
    pub files: file_menu::FileWindows,
    /// Recently opened or saved documents, newest first.
    pub recent: Vec<PathBuf>,
    /// Where the recent files are kept between runs (none: only in memory).
    recent_file: Option<PathBuf>,
    /// Every message so far, and when the latest appeared.
    pub log: messages::MessageLog,
    /// The message set this frame is an error (see [`EditorApp::fail`]).
    message_is_error: bool,
    last_autosave_s: f64,
    /// The autosave being written on another thread (a document never rigged is traced and
    /// meshed to be saved, too slow for the UI thread on large images).
    autosaving: Option<file::Writing>,
    /// A save being written on another thread.
    saving: Option<file::Saving>,
    /// Where File → Export writes.
    pub export_dir: String,
    /// File → Export Spine's options (those of `sinew export spine`).
    pub spine_options: crate::export::spine::SpineOptions,
    /// Where File → Render writes.
    pub render_path: String,
    /// A render under way on another thread: its message when done.
    render: Option<std::sync::mpsc::Receiver<String>>,
    /// Where a request to close the window stands.
    closing: closing::Closing,
    /// The UI's context, for threads started outside a frame's call chain to wake it.
    repaint: Option<egui::Context>,
    /// Screenshot to take after a few frames, then quit (for `--screenshot`).
    screenshot: Option<(PathBuf, u32)>,
    /// File → Render's options (those of `sinew render`); the canvas draws and the timeline
    /// plays as they say.
    pub render_settings: crate::playback::RenderSettings,
    /// Rig mode's polygon tools, mesh preview and automatic rig.
    pub rig_tools: rig_tools::RigTools,
    /// Colorize mode: line art, scribbles, the background solve.
    pub colorize: colorize::ColorizeEditor,
    /// Rig mode's brush settings.
    pub paint: paint::PaintSettings,
    /// Animate mode: key selection, clipboard, loop, onion skins, curve editor.
    pub timeline: timeline::TimelineState,
    /// The tree view: renaming in place, the parts hidden on the canvas.
    pub tree: tree::TreeState,
    /// Animate mode's events: the selected event key's payload, adding and defining events.
    pub events: events::EventsPanel,
    /// Animate mode's deform tool: on or off, its radius.
    pub deform: deform_tool::DeformTool,
    /// Native file dialogs, where a portal answers ([`native_dialog`]).
    pub dialogs: native_dialog::NativeDialogs,
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
        let rig_tools = rig_tools::RigTools::for_document(doc.state().autorig);
        EditorApp {
            doc,
            mode: Mode::Rig,
            selected: None,
            view: None,
            view_request: None,
            fitted: None,
            placed: None,
            message: None,
            last_frame_ms: 0.0,
            whole_frame_ms: None,
            frame_log: None,
            show_help: false,
            gesture: None,
            rig_mode: Default::default(),
            pose_mode: Default::default(),
            animate: animate_mode::AnimateMode::new(first_animation),
            animations: Default::default(),
            motion: Default::default(),
            drawing: Default::default(),
            open_path,
            files: Default::default(),
            recent: Vec::new(),
            recent_file: None,
            log: Default::default(),
            message_is_error: false,
            last_autosave_s: 0.0,
            autosaving: None,
            saving: None,
            export_dir: "export".into(),
            spine_options: Default::default(),
            render_path: "render.gif".into(),
            render: None,
            closing: Default::default(),
            repaint: None,
            screenshot: None,
            render_settings: Default::default(),
            rig_tools,
            colorize: Default::default(),
            paint: paint::PaintSettings::default(),
            timeline: Default::default(),
            tree: Default::default(),
            events: Default::default(),
            deform: Default::default(),
            dialogs: Default::default(),
        }
    }

    /// Takes a screenshot to `path` once the window has drawn a few frames, then closes.
    pub fn screenshot_then_quit(&mut self, path: PathBuf) {
        self.screenshot = Some((path, 0));
    }

    /// Whether a rig build is running.
    pub fn computing(&self) -> bool {
        self.rig_mode.worker.is_some()
    }

    /// Applies a command, reporting a refusal as the message (the document stays as it was).
    pub fn apply(&mut self, command: Command) -> bool {
        match self.doc.apply(command) {
            Ok(()) => true,
            Err(e) => {
                self.fail(e.to_string());
                false
            }
        }
    }

    /// One frame of the whole editor.
    pub fn frame(&mut self, ui: &mut egui::Ui) {
        let started = Instant::now();
        let ctx = ui.ctx().clone();
        self.repaint = Some(ctx.clone());
        let now_s = ctx.input(|i| i.time);
        self.log_message(now_s);
        self.dialog_takes_input(&ctx);
        self.poll_worker();
        self.poll_render();
        self.poll_dialogs(&ctx);
        self.poll_rig_tools(&ctx);
        self.warm_ik();
        self.colorize_frame_start(&ctx);
        self.dropped_files(&ctx);
        // Ctrl+N/O/S first: they take their key events, which no other shortcut then sees.
        self.file_shortcuts(&ctx);
        self.view_shortcuts(&ctx);
        self.timeline_shortcuts(&ctx);
        self.shortcuts(&ctx);
        self.keep_selection();
        self.autosave(&ctx);
        self.guard_close(&ctx);
        egui::Panel::top("menu").show(ui, |ui| self.menu_bar(ui));
        self.advance_playback(&ctx);
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        // The side panel first, from the menu bar down to the status bar: animate mode's
        // timeline goes under the canvas only and leaves the tree its height (as in Spine).
        egui::Panel::left("side")
            .default_size(230.0)
            .show(ui, |ui| self.side_panel(ui));
        if self.mode == Mode::Animate {
            egui::Panel::bottom("timeline").show(ui, |ui| self.animate_panel(ui));
        }
        egui::CentralPanel::default().show(ui, |ui| self.canvas(ui));
        if self.show_help {
            help_window(&ctx, &mut self.show_help);
        }
        self.file_windows(&ctx);
        if self.mode == Mode::Animate {
            self.graph_view_window(&ctx);
            self.define_event_window(&ctx);
            self.apply_motion_window(&ctx);
        }
        self.log_window(&ctx);
        self.close_dialog(&ctx);
        self.take_screenshot(&ctx);
        self.log_message(now_s);
        self.last_frame_ms = started.elapsed().as_secs_f64() * 1e3;
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
        // Each key event with its own modifiers: Ctrl+3 is not 3.
        let plain = |key: Key| !typing && ctx.input(|i| file_menu::plain_key(i, key));
        if plain(Key::Num3) {
            self.mode = Mode::Animate;
        }
        if plain(Key::Space) && self.mode == Mode::Animate {
            self.toggle_playback();
        }
        if plain(Key::K) && self.mode == Mode::Animate && self.gesture.is_none() {
            self.set_key();
        }
        let (delete, rig, pose) = (plain(Key::Delete), plain(Key::Num1), plain(Key::Num2));
        let (undo, redo, help, escape) = ctx.input_mut(|i| {
            let redo = i.consume_key(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
            let undo = i.consume_key(Modifiers::COMMAND, Key::Z);
            (
                undo,
                redo,
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

    /// The selection across modes and edits: kept while its handle exists (the tree shows it
    /// in view again after a mode switch), dropped when an undo, a delete or another edit took
    /// the handle away, so no mode shows or edits a handle that is not there.
    fn keep_selection(&mut self) {
        if let Some(name) = &self.selected {
            if !self.doc.state().handles.names().any(|n| n == name) {
                self.selected = None;
            }
        }
        if self.tree.mode_shown != Some(self.mode) {
            self.tree.mode_shown = Some(self.mode);
            self.tree.reveal_after_switch();
        }
    }

    fn menu_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            self.file_menu_button(ui);
            self.view_menu_button(ui);
            if ui
                .add_enabled(self.can_undo_in_mode(), egui::Button::new("Undo"))
                .on_hover_text("Ctrl+Z")
                .clicked()
            {
                self.undo_in_mode();
            }
            if ui
                .add_enabled(self.can_redo_in_mode(), egui::Button::new("Redo"))
                .on_hover_text("Ctrl+Shift+Z")
                .clicked()
            {
                self.redo_in_mode();
            }
            ui.separator();
            for (mode, label, key) in [
                (Mode::Rig, "Rig mode", "1"),
                (Mode::Pose, "Pose mode", "2"),
                (Mode::Animate, "Animate mode", "3"),
                (Mode::Colorize, "Colorize mode", "4"),
            ] {
                ui.selectable_value(&mut self.mode, mode, label)
                    .on_hover_text(format!("key {key}"));
            }
            ui.separator();
            if ui.button("Help").on_hover_text("F1 or ?").clicked() {
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
                if self.doc.dirty() { ", modified" } else { "" }
            ));
            ui.separator();
            // The whole frame (GL draw included) where a window measures it.
            let ms = self.whole_frame_ms.unwrap_or(self.last_frame_ms);
            ui.label(format!("frame {ms:.1} ms")).on_hover_text(format!(
                "the editor's own code: {:.1} ms",
                self.last_frame_ms
            ));
            ui.separator();
            self.message_ui(ui);
        });
    }

    fn side_panel(&mut self, ui: &mut egui::Ui) {
        // Rig mode's tools outgrow a short window: the panel scrolls, each mode's panel on its
        // own (they hold different things: one mode's scrolling does not hide another's top).
        self.tree.panel_height_pt = ui.available_height();
        let scroll = egui::ScrollArea::vertical().id_salt(("side panel", self.mode as u8));
        scroll.show(ui, |ui| match self.mode {
            Mode::Rig => self.rig_panel(ui),
            Mode::Pose => {
                self.pose_panel(ui);
                self.numbers_panel(ui);
                self.pose_tree(ui);
            }
            Mode::Animate => {
                self.animation_list(ui);
                ui.separator();
                // Beside the list, not under the dopesheet: the canvas keeps its height.
                ui.horizontal_wrapped(|ui| self.add_event_row(ui));
                ui.horizontal(|ui| self.deform_tool_row(ui));
                ui.separator();
                self.pose_panel(ui);
                self.numbers_panel(ui);
                self.pose_tree(ui);
            }
            Mode::Colorize => self.colorize_panel(ui),
        });
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
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        self.whole_frame_ms = frame.info().cpu_usage.map(|s| f64::from(s) * 1e3);
        if let Some(log) = &mut self.frame_log {
            log.log(Instant::now(), self.last_frame_ms, self.whole_frame_ms);
        }
        self.frame(ui);
    }

    fn logic(&mut self, ctx: &egui::Context, _frame: &mut eframe::Frame) {
        self.close_requests(ctx);
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        self.finish_writes();
    }
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
    ("K", "set a key at the playhead (animate mode)"),
    ("Ctrl+N", "new document"),
    ("Ctrl+O", "open a rig"),
    ("Ctrl+S", "save"),
    ("Ctrl+Shift+S", "save as"),
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
    (
        "Home",
        "zoom to fit the canvas (kept fitted as the window or mode changes, until you zoom or pan)",
    ),
    ("F", "frame the selected handle"),
    ("Ctrl+0", "actual size (100 %)"),
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
    /// Open the graph view window ([`graph_view`]) at start.
    pub graph_view: bool,
    /// Line art to open in colorize mode.
    pub line_art: Option<PathBuf>,
    /// Scribbles (the JSON file of `sinew colorize --scribbles`) to draw on the line art.
    pub scribbles: Option<PathBuf>,
    /// Where each frame's times are appended ([`FrameLog`]).
    pub frame_log: Option<PathBuf>,
}

/// Each frame's times, appended to a file for benchmarks: one tab-separated line per frame
/// after a header, ms: `app_ms` (the editor's own code), `whole_ms` (eframe's measure of the
/// whole frame: the editor, tessellation and the GL draw, without waiting for the swap),
/// `interval_ms` (since the frame before started).
pub struct FrameLog {
    file: std::io::BufWriter<std::fs::File>,
    last_start: Option<Instant>,
}

impl FrameLog {
    pub fn create(path: &std::path::Path) -> std::io::Result<Self> {
        use std::io::Write;
        let mut file = std::io::BufWriter::new(std::fs::File::create(path)?);
        writeln!(file, "app_ms\twhole_ms\tinterval_ms")?;
        Ok(FrameLog {
            file,
            last_start: None,
        })
    }

    /// Logs the frame before this one (started at `now`): its own and whole times.
    fn log(&mut self, now: Instant, app_ms: f64, whole_ms: Option<f64>) {
        use std::io::Write;
        let interval_ms = self
            .last_start
            .map(|t| now.duration_since(t).as_secs_f64() * 1e3);
        self.last_start = Some(now);
        let (Some(whole), Some(interval)) = (whole_ms, interval_ms) else {
            return;
        };
        // A failed write only loses benchmark lines; flushed per line so a killed run keeps them.
        let _ = writeln!(self.file, "{app_ms:.3}\t{whole:.3}\t{interval:.3}");
        let _ = self.file.flush();
    }
}

/// Opens the editor window.
pub fn run(start: Start) -> anyhow::Result<()> {
    let doc = match &start.rig {
        Some(p) => Document::open(p)?,
        None => Document::new(),
    };
    let mut app = EditorApp::new(doc);
    app.use_native_dialogs_where_a_portal_answers();
    if let Some(path) = &start.frame_log {
        app.frame_log = Some(
            FrameLog::create(path)
                .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?,
        );
    }
    // Recent files live in the user's configuration folder (XDG), when there is one.
    let config = std::env::var_os("XDG_CONFIG_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".config")));
    if let Some(config) = config {
        app.keep_recent_in(config.join("sinew").join("recent.json"));
    }
    if let Some(path) = &start.rig {
        app.remember_recent(path);
    }
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
        app.rig_mode.rename_to = name.clone();
        app.selected = Some(name);
    }
    app.timeline.graph.open = start.graph_view;
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
