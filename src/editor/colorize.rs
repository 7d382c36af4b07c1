//! Colorize mode (key 4): scribble colors on line art and see the colored result live.
//!
//! In: a line-art PNG (File menu or dropped on the window in this mode), pointer strokes with
//! the scribble brush or the eraser. Out: [`SessionCommand`]s on a [`ColorizeSession`] (so
//! undo, checking and the solve live in the library), a picture (the line art, the result
//! blended over it, the scribbles on top), and the colorized PNG saved atomically.
//!
//! Solves run on a background thread, one at a time: while the brush moves, the stroke being
//! drawn is solved too, so the result follows the pen at the solver's pace; a solve whose
//! committed strokes changed meanwhile (a new stroke, an erase, undo) is cancelled at its next
//! step, and a result is installed in the session only for the strokes it was solved for —
//! the newest strokes win.

use super::canvas::{self, Placed, View};
use super::number_field::{number_field, slider};
use super::{EditorApp, Mode};
use crate::colorize::session::{
    ColorizeSession, ScribbleStroke, SessionCommand, SessionError, SolveJob,
};
use crate::colorize::{ColorizeError, ColorizeOptions, Colorized};
use crate::geom::Point;
use eframe::egui::{self, Color32, Key, Modifiers, Pos2, Sense, TextureHandle};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::sync::Arc;

mod split_controls;

/// Brush diameter a new session starts with, image px.
pub const DEFAULT_BRUSH_PX: f32 = 6.0;
/// The brush color a new editor starts with.
pub const DEFAULT_COLOR: [u8; 3] = [230, 80, 70];
/// Ready-made brush colors.
pub const SWATCHES: [[u8; 3]; 10] = [
    [230, 80, 70],
    [240, 140, 40],
    [240, 200, 60],
    [90, 190, 90],
    [60, 200, 200],
    [70, 140, 230],
    [170, 90, 200],
    [240, 150, 190],
    [150, 110, 70],
    [250, 245, 225],
];
/// A new brush point is recorded once the pointer moved this far from the last, image px.
const BRUSH_STEP_PX: f64 = 0.75;

/// What a press on the canvas does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorizeTool {
    Brush,
    /// Removes whole strokes under the pointer.
    Eraser,
}

/// What the canvas shows under the scribbles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorizeView {
    /// The line art with the colorized result over it.
    Result,
    /// The line art alone.
    ScribblesOnly,
}

/// A solve under way on another thread.
struct Solve {
    job: SolveJob,
    /// The session's strokes when it started (the stroke being drawn comes on top of them).
    base: Arc<Vec<ScribbleStroke>>,
    cancel: Arc<AtomicBool>,
    result: Receiver<Result<Option<Colorized>, SessionError>>,
}

/// Colorize mode's state.
pub struct ColorizeEditor {
    pub session: Option<ColorizeSession>,
    /// Where the line art came from.
    pub path: Option<PathBuf>,
    /// The File menu's line-art path field.
    pub lineart_path: String,
    /// Where "Save colorized PNG" writes.
    pub save_path: String,
    /// Where "Save scribbles" writes and "Load scribbles" reads (a JSON scribble file).
    pub scribbles_path: String,
    /// The scribble file last saved or loaded (or the default beside the line art): its
    /// autosave side file is where the strokes are autosaved, whatever the field holds.
    scribbles_file: Option<PathBuf>,
    /// The strokes last saved or autosaved, to autosave only changes.
    saved_strokes: Option<Arc<Vec<ScribbleStroke>>>,
    pub tool: ColorizeTool,
    pub color: [u8; 3],
    /// The "Color hex:" field's text while it is edited (`#rrggbb`).
    color_hex: String,
    /// Brush diameter, image px.
    pub width_px: f32,
    pub view_mode: ColorizeView,
    /// What the solves use (the split picked in the panel); line art opened later takes them
    /// too.
    pub options: ColorizeOptions,
    /// Opacity of the result over the line art, 0..=1.
    pub opacity: f32,
    /// This mode's pan and zoom (the line art has its own size); `None` fits it.
    view: Option<View>,
    /// This canvas's [`EditorApp::fitted`].
    fitted: Option<super::view::Fitted>,
    /// The stroke being drawn, image px.
    drawing: Option<Vec<Point>>,
    solve: Option<Solve>,
    /// The newest finished solve: its strokes and result, shown until a newer one arrives.
    latest: Option<(Arc<Vec<ScribbleStroke>>, Arc<Colorized>)>,
    /// `latest` was solved with options changed since: shown, but solved again.
    latest_stale: bool,
    /// Strokes whose solve failed: not tried again until they change.
    failed: Option<Vec<ScribbleStroke>>,
    lineart_texture: Option<TextureHandle>,
    result_texture: Option<(Arc<Colorized>, TextureHandle)>,
}

impl Default for ColorizeEditor {
    fn default() -> Self {
        ColorizeEditor {
            session: None,
            path: None,
            lineart_path: String::new(),
            save_path: "colorized.png".into(),
            scribbles_path: "scribbles.json".into(),
            scribbles_file: None,
            saved_strokes: None,
            tool: ColorizeTool::Brush,
            color: DEFAULT_COLOR,
            color_hex: String::new(),
            width_px: DEFAULT_BRUSH_PX,
            view_mode: ColorizeView::Result,
            options: ColorizeOptions::default(),
            opacity: 1.0,
            view: None,
            fitted: None,
            drawing: None,
            solve: None,
            latest: None,
            latest_stale: false,
            failed: None,
            lineart_texture: None,
            result_texture: None,
        }
    }
}

impl ColorizeEditor {
    /// Whether a solve is running or due (the strokes shown have no result yet).
    pub fn solving(&self) -> bool {
        self.solve.is_some() || self.due().is_some()
    }

    /// The newest result shown: the session's for its strokes, else the last one solved.
    pub fn shown_result(&self) -> Option<&Arc<Colorized>> {
        let session = self.session.as_ref()?;
        if self.drawing.is_none() {
            if let Some(result) = session.result() {
                return Some(result);
            }
            if session.strokes().is_empty() {
                return None;
            }
        }
        self.latest.as_ref().map(|(_, r)| r)
    }

    /// The strokes the canvas shows: the session's and the one being drawn.
    fn wanted(&self) -> Option<Vec<ScribbleStroke>> {
        let session = self.session.as_ref()?;
        let mut strokes = session.strokes().to_vec();
        if let Some(points) = &self.drawing {
            strokes.push(self.stroke(points.clone()));
        }
        Some(strokes)
    }

    fn stroke(&self, points_px: Vec<Point>) -> ScribbleStroke {
        ScribbleStroke {
            color: self.color,
            width_px: self.width_px as f64,
            points_px,
        }
    }

    /// The strokes that need a solve now, if any.
    fn due(&self) -> Option<Vec<ScribbleStroke>> {
        let session = self.session.as_ref()?;
        if self.drawing.is_none() && session.result().is_some() {
            return None;
        }
        let wanted = self.wanted()?;
        let known = |s: &[ScribbleStroke]| s == wanted.as_slice();
        if wanted.is_empty()
            || (!self.latest_stale && self.latest.as_ref().is_some_and(|(s, _)| known(s)))
            || self.failed.as_deref().is_some_and(known)
        {
            return None;
        }
        Some(wanted)
    }

    fn undo(&mut self) {
        if self.drawing.is_none() {
            if let Some(s) = &mut self.session {
                s.undo();
            }
        }
    }

    fn redo(&mut self) {
        if self.drawing.is_none() {
            if let Some(s) = &mut self.session {
                s.redo();
            }
        }
    }

    fn stop_solve(&mut self) {
        if let Some(solve) = self.solve.take() {
            solve.cancel.store(true, Ordering::Relaxed);
        }
    }
}

impl EditorApp {
    /// Opens a line-art PNG for colorizing (and switches to colorize mode); on failure the
    /// current line art and strokes stay.
    pub fn open_lineart(&mut self, path: &Path) {
        let opened = crate::io::load_png(path)
            .map_err(SessionError::from)
            .and_then(|image| ColorizeSession::new(image, self.colorize.options.clone()));
        match opened {
            Ok(session) => {
                let c = &mut self.colorize;
                c.stop_solve();
                let [w, h] = session.size_px();
                *c = ColorizeEditor {
                    session: Some(session),
                    path: Some(path.to_path_buf()),
                    lineart_path: path.display().to_string(),
                    save_path: colorized_path(path).display().to_string(),
                    scribbles_path: scribbles_path(path).display().to_string(),
                    scribbles_file: Some(scribbles_path(path)),
                    tool: c.tool,
                    color: c.color,
                    width_px: c.width_px,
                    view_mode: c.view_mode,
                    options: c.options.clone(),
                    opacity: c.opacity,
                    ..Default::default()
                };
                self.mode = Mode::Colorize;
                self.message = Some(format!("opened line art {} ({w}×{h} px)", path.display()));
            }
            Err(e) => self.fail(format!("cannot open {}: {e}", path.display())),
        }
    }

    /// Saves the colorized image to `path`; returns the message for the status bar.
    pub fn save_colorized(&mut self, path: &Path) -> String {
        let Some(session) = &self.colorize.session else {
            return "open a line-art PNG first".into();
        };
        match session.save_result(path) {
            Ok(()) => format!("saved {}", path.display()),
            Err(e) => e.to_string(),
        }
    }

    /// Saves the strokes to `path` as a JSON scribble file; returns the status-bar message.
    pub fn save_scribbles(&mut self, path: &Path) -> String {
        let c = &mut self.colorize;
        let Some(session) = &c.session else {
            return "open a line-art PNG first".into();
        };
        match session.save_strokes(path) {
            Ok(()) => {
                c.saved_strokes = Some(session.state().strokes.clone());
                c.scribbles_file = Some(path.to_path_buf());
                format!(
                    "saved {} strokes to {}",
                    session.strokes().len(),
                    path.display()
                )
            }
            Err(e) => e.to_string(),
        }
    }

    /// Replaces the strokes with those of the JSON scribble file at `path` (one undo step);
    /// on failure the strokes stay. Sets the status-bar message; true when loaded.
    pub fn load_scribbles(&mut self, path: &Path) -> bool {
        let Some(session) = self.colorize.session.as_mut() else {
            self.message = Some("open a line-art PNG first".into());
            return false;
        };
        let (message, loaded) = match session.load_strokes(path) {
            Ok(count) => {
                self.colorize.scribbles_path = path.display().to_string();
                self.colorize.scribbles_file = Some(path.to_path_buf());
                self.colorize.saved_strokes = Some(session.state().strokes.clone());
                (
                    format!("loaded {count} strokes from {}", path.display()),
                    true,
                )
            }
            Err(e) => (format!("cannot load {}: {e}", path.display()), false),
        };
        self.message = Some(message);
        loaded
    }

    /// Writes the strokes beside the scribble file (`NAME.autosave.json`) when they changed
    /// since the last save, load or autosave (none at all included, once there were some); a
    /// failure goes to the status bar.
    pub(super) fn autosave_scribbles(&mut self) {
        let c = &mut self.colorize;
        let (Some(session), Some(file)) = (&c.session, &c.scribbles_file) else {
            return;
        };
        let strokes = &session.state().strokes;
        let unchanged = match &c.saved_strokes {
            Some(saved) => saved.as_slice() == strokes.as_slice(),
            None => strokes.is_empty(),
        };
        if unchanged {
            return;
        }
        let target = crate::document::autosave_path(file);
        match session.write_strokes(&target) {
            Ok(()) => c.saved_strokes = Some(strokes.clone()),
            Err(e) => self.fail(format!("autosave failed: {e}")),
        }
    }

    /// Colorize mode's part of every frame, before the rest: key 4, undo and redo (and the
    /// tool keys) in this mode, dropped PNGs as line art, the background solve.
    pub(super) fn colorize_frame_start(&mut self, ctx: &egui::Context) {
        let typing = ctx.text_edit_focused();
        if !typing && ctx.input(|i| i.key_pressed(Key::Num4)) {
            self.mode = Mode::Colorize;
        }
        if self.mode == Mode::Colorize {
            // Consumed here, so the document's undo does not also see them.
            let (undo, redo, brush, eraser, toggle) = ctx.input_mut(|i| {
                let redo = i.consume_key(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
                let undo = i.consume_key(Modifiers::COMMAND, Key::Z);
                (
                    undo,
                    redo,
                    !typing && i.key_pressed(Key::B),
                    !typing && i.key_pressed(Key::E),
                    !typing && i.key_pressed(Key::V),
                )
            });
            let c = &mut self.colorize;
            if undo {
                c.undo();
            }
            if redo {
                c.redo();
            }
            if brush {
                c.tool = ColorizeTool::Brush;
            }
            if eraser {
                c.tool = ColorizeTool::Eraser;
            }
            if toggle {
                c.view_mode = match c.view_mode {
                    ColorizeView::Result => ColorizeView::ScribblesOnly,
                    ColorizeView::ScribblesOnly => ColorizeView::Result,
                };
            }
            // Dropped PNGs are line art here, not rig layers: taken before the rig code sees them.
            let dropped: Vec<PathBuf> = ctx.input_mut(|i| {
                let (png, other): (Vec<_>, Vec<_>) = std::mem::take(&mut i.raw.dropped_files)
                    .into_iter()
                    .partition(|f| is_png(f.path()));
                i.raw.dropped_files = other;
                png.iter().map(|f| f.path().to_path_buf()).collect()
            });
            if let Some(path) = dropped.last() {
                self.open_lineart(path);
            }
        }
        self.poll_colorize();
        self.schedule_colorize(ctx);
    }

    fn poll_colorize(&mut self) {
        let c = &mut self.colorize;
        let Some(solve) = &c.solve else { return };
        let result = match solve.result.try_recv() {
            Ok(result) => result,
            Err(TryRecvError::Empty) => return,
            Err(TryRecvError::Disconnected) => Err(ColorizeError::Cancelled.into()),
        };
        let strokes = solve.job.strokes.clone();
        c.solve = None;
        match result {
            Ok(result) => {
                let result = result.map(Arc::new);
                if let Some(session) = &mut c.session {
                    // Refused when the strokes changed meanwhile: it is still the newest
                    // picture, so it is shown until the next solve ends.
                    let _ = session.set_result(&strokes, result.clone());
                }
                c.latest = result.map(|r| (strokes, r));
                c.latest_stale = false;
                c.failed = None;
            }
            Err(SessionError::Colorize(ColorizeError::Cancelled)) => {}
            Err(e) => {
                self.message = Some(e.to_string());
                self.message_is_error = true;
                c.failed = Some(strokes.as_ref().clone());
            }
        }
    }

    fn schedule_colorize(&mut self, ctx: &egui::Context) {
        let c = &mut self.colorize;
        let Some(session) = &c.session else { return };
        if let Some(solve) = &c.solve {
            // Committed strokes changed under it (not just the stroke being drawn): stale.
            if !Arc::ptr_eq(&solve.base, &session.state().strokes) {
                c.stop_solve();
            } else {
                return;
            }
        }
        if let (None, false, Some(session), Some((strokes, result))) =
            (&c.drawing, c.latest_stale, &mut c.session, &c.latest)
        {
            // The stroke just finished was already solved while it was drawn.
            if session.result().is_none() && session.strokes() == strokes.as_slice() {
                let _ = session.set_result(strokes, Some(result.clone()));
            }
        }
        let Some(strokes) = c.due() else { return };
        let Some(session) = &c.session else { return };
        let base = session.state().strokes.clone();
        let job = SolveJob {
            lineart: session.job().lineart,
            strokes: Arc::new(strokes),
        };
        let cancel = Arc::new(AtomicBool::new(false));
        let (send, result) = mpsc::channel();
        let (thread_job, thread_cancel, ctx) = (job.clone(), cancel.clone(), ctx.clone());
        std::thread::spawn(move || {
            // The editor may have moved on or closed meanwhile; then nobody wants it.
            let _ = send.send(thread_job.run(&thread_cancel));
            ctx.request_repaint();
        });
        c.solve = Some(Solve {
            job,
            base,
            cancel,
            result,
        });
    }

    /// The File menu's colorize entries; an action closes the menu, as the others do.
    pub(super) fn colorize_file_menu(&mut self, ui: &mut egui::Ui) {
        ui.separator();
        labelled_text_field(
            ui,
            "Line-art PNG to colorize:",
            &mut self.colorize.lineart_path,
        );
        if ui.button("Open line art").clicked() {
            ui.close();
            let path = PathBuf::from(&self.colorize.lineart_path);
            self.open_lineart(&path);
        }
        labelled_text_field(ui, "Colorized PNG:", &mut self.colorize.save_path);
        if ui.button("Save colorized PNG").clicked() {
            ui.close();
            let path = PathBuf::from(&self.colorize.save_path);
            self.message = Some(self.save_colorized(&path));
        }
        labelled_text_field(ui, "Scribbles JSON:", &mut self.colorize.scribbles_path);
        ui.horizontal(|ui| {
            if ui.button("Save scribbles").clicked() {
                ui.close();
                let path = PathBuf::from(&self.colorize.scribbles_path);
                self.message = Some(self.save_scribbles(&path));
            }
            if ui.button("Load scribbles").clicked() {
                ui.close();
                let path = PathBuf::from(&self.colorize.scribbles_path);
                self.load_scribbles(&path);
            }
        });
    }

    pub(super) fn colorize_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Colorize");
        let c = &mut self.colorize;
        let Some(session) = &c.session else {
            ui.label("Open a line-art PNG (File menu, or drop it on the window).");
            return;
        };
        let palette = session.palette();
        let strokes = session.strokes().len();
        ui.horizontal(|ui| {
            ui.selectable_value(&mut c.tool, ColorizeTool::Brush, "Brush");
            ui.selectable_value(&mut c.tool, ColorizeTool::Eraser, "Eraser");
        });
        ui.horizontal(|ui| {
            ui.label("Color");
            ui.color_edit_button_srgb(&mut c.color);
            // Typed as #rrggbb; taken once it parses, shown as the colour otherwise.
            let label = ui.label("Color hex:");
            let field = ui
                .add(egui::TextEdit::singleline(&mut c.color_hex).desired_width(70.0))
                .labelled_by(label.id);
            if field.changed() {
                if let Some(color) = crate::colorize::scribbles::parse_hex_color(c.color_hex.trim())
                {
                    c.color = color;
                    c.tool = ColorizeTool::Brush;
                }
            }
            if !field.has_focus() {
                c.color_hex = format!("#{}", crate::colorize::scribbles::hex(c.color));
            }
        });
        ui.horizontal_wrapped(|ui| {
            for swatch in SWATCHES {
                if swatch_button(ui, swatch, swatch == c.color).clicked() {
                    c.color = swatch;
                    c.tool = ColorizeTool::Brush;
                }
            }
        });
        ui.horizontal(|ui| {
            let label = ui.label("Brush px:");
            ui.add(number_field(&mut c.width_px).range(1.0..=64.0).speed(0.25))
                .labelled_by(label.id);
        });
        ui.separator();
        ui.horizontal(|ui| {
            ui.selectable_value(&mut c.view_mode, ColorizeView::Result, "Result");
            ui.selectable_value(
                &mut c.view_mode,
                ColorizeView::ScribblesOnly,
                "Scribbles only",
            );
        });
        ui.add(slider(&mut c.opacity, 0.0..=1.0).text("result opacity"));
        ui.separator();
        let split = c.split_controls(ui);
        ui.separator();
        ui.label(format!("{strokes} strokes, {} colors", palette.len()));
        let mut command = None;
        for color in &palette {
            ui.horizontal(|ui| {
                if swatch_button(ui, *color, *color == c.color).clicked() {
                    c.color = *color;
                    c.tool = ColorizeTool::Brush;
                }
                if ui
                    .add_enabled(*color != c.color, egui::Button::new("Recolor to brush"))
                    .clicked()
                {
                    command = Some(SessionCommand::Recolor {
                        from: *color,
                        to: c.color,
                    });
                }
            });
        }
        if ui
            .add_enabled(strokes > 0, egui::Button::new("Clear"))
            .clicked()
        {
            command = Some(SessionCommand::Clear);
        }
        // A label, not a spinner: a spinner repaints forever, the solve wakes the UI itself.
        if c.solving() {
            ui.label("colorizing…");
        } else if c.shown_result().is_some() {
            ui.label("colorized");
        }
        if ui.button("Save colorized PNG").clicked() {
            let path = PathBuf::from(&self.colorize.save_path);
            self.message = Some(self.save_colorized(&path));
        }
        if ui
            .add_enabled(strokes > 0, egui::Button::new("Save scribbles"))
            .on_hover_text(self.colorize.scribbles_path.clone())
            .clicked()
        {
            let path = PathBuf::from(&self.colorize.scribbles_path);
            self.message = Some(self.save_scribbles(&path));
        }
        if let Some(command) = command {
            self.apply_colorize(command);
        }
        if let Err(message) = split {
            self.fail(message);
        }
    }

    /// Whether the menu's Undo has a step: the colorize session's in colorize mode, the
    /// document's elsewhere.
    pub fn can_undo_in_mode(&self) -> bool {
        match (self.mode, &self.colorize.session) {
            (Mode::Colorize, Some(s)) => s.can_undo(),
            (Mode::Colorize, None) => false,
            _ => self.doc.can_undo(),
        }
    }

    pub fn can_redo_in_mode(&self) -> bool {
        match (self.mode, &self.colorize.session) {
            (Mode::Colorize, Some(s)) => s.can_redo(),
            (Mode::Colorize, None) => false,
            _ => self.doc.can_redo(),
        }
    }

    /// Undo in the current mode (the menu's button).
    pub fn undo_in_mode(&mut self) {
        match self.mode {
            Mode::Colorize => self.colorize.undo(),
            _ => {
                self.doc.undo();
            }
        }
    }

    pub fn redo_in_mode(&mut self) {
        match self.mode {
            Mode::Colorize => self.colorize.redo(),
            _ => {
                self.doc.redo();
            }
        }
    }

    /// Applies a session command, reporting a refusal as the message.
    pub fn apply_colorize(&mut self, command: SessionCommand) -> bool {
        let Some(session) = &mut self.colorize.session else {
            return false;
        };
        match session.apply(command) {
            Ok(()) => true,
            Err(e) => {
                self.fail(e.to_string());
                false
            }
        }
    }

    /// Colorize mode's canvas: line art, result, scribbles, brush and eraser gestures.
    pub(super) fn colorize_canvas(&mut self, ui: &mut egui::Ui) {
        // The shared pan/zoom code works on `self.view`: lend it this mode's view.
        std::mem::swap(&mut self.view, &mut self.colorize.view);
        std::mem::swap(&mut self.fitted, &mut self.colorize.fitted);
        self.colorize_canvas_with_view(ui);
        std::mem::swap(&mut self.view, &mut self.colorize.view);
        std::mem::swap(&mut self.fitted, &mut self.colorize.fitted);
    }

    fn colorize_canvas_with_view(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let (response, painter) = ui.allocate_painter(ui.available_size(), Sense::click_and_drag());
        let rect = response.rect;
        painter.rect_filled(rect, 0.0, Color32::from_gray(40));
        let Some(size_px) = self.colorize.session.as_ref().map(|s| s.size_px()) else {
            painter.text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "Open a line-art PNG to colorize (File menu, or drop it here)",
                egui::FontId::proportional(16.0),
                Color32::from_gray(200),
            );
            return;
        };
        let placed = self.place_canvas(&ctx, &response, size_px);
        let mut shapes = Vec::new();
        if let Some(texture) = self.colorize_textures(&ctx) {
            shapes.push(canvas::image_quad(&placed, &texture.0, [0, 0], size_px));
            if let (Some(result), ColorizeView::Result) = (texture.1, self.colorize.view_mode) {
                let alpha = (self.colorize.opacity.clamp(0.0, 1.0) * 255.0).round() as u8;
                let quad = egui::Rect::from_two_pos(
                    placed.screen_from_canvas(Point::origin()),
                    placed.screen_from_canvas(Point::new(size_px[0] as f64, size_px[1] as f64)),
                );
                let uv = egui::Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
                shapes.push(egui::Shape::image(
                    result.id(),
                    quad,
                    uv,
                    Color32::from_white_alpha(alpha),
                ));
            }
        }
        for stroke in self.colorize.wanted().unwrap_or_default() {
            shapes.extend(stroke_shapes(&placed, &stroke));
        }
        if let (ColorizeTool::Eraser, Some(at)) = (self.colorize.tool, response.hover_pos()) {
            let radius = self.eraser_radius_px(&placed) as f32 * placed.view.zoom;
            shapes.push(egui::Shape::circle_stroke(
                at,
                radius,
                egui::Stroke::new(1.5, Color32::WHITE),
            ));
        }
        painter.extend(shapes);
        self.colorize_gestures(&ctx, &response, placed);
    }

    /// The line art's texture and the shown result's, uploaded when they change.
    fn colorize_textures(
        &mut self,
        ctx: &egui::Context,
    ) -> Option<(TextureHandle, Option<TextureHandle>)> {
        let c = &mut self.colorize;
        let session = c.session.as_ref()?;
        let upload = |name: &str, image: &image::RgbaImage| {
            let pixels = egui::ColorImage::from_rgba_unmultiplied(
                [image.width() as usize, image.height() as usize],
                image.as_raw(),
            );
            ctx.load_texture(name, pixels, egui::TextureOptions::LINEAR)
        };
        let lineart = c
            .lineart_texture
            .get_or_insert_with(|| upload("lineart", session.lineart()))
            .clone();
        let shown = c.shown_result().cloned();
        let result = match shown {
            None => None,
            Some(r) => match &c.result_texture {
                Some((k, t)) if Arc::ptr_eq(k, &r) => Some(t.clone()),
                _ => {
                    let t = upload("colorized", &r.image);
                    c.result_texture = Some((r, t.clone()));
                    Some(t)
                }
            },
        };
        Some((lineart, result))
    }

    /// The eraser's reach, image px: the brush radius, at least a few screen points.
    fn eraser_radius_px(&self, placed: &Placed) -> f64 {
        (self.colorize.width_px as f64 / 2.0)
            .max(canvas::PICK_RADIUS_PT as f64 / placed.view.zoom as f64)
    }

    fn colorize_gestures(
        &mut self,
        ctx: &egui::Context,
        response: &egui::Response,
        placed: Placed,
    ) {
        let pointer = response.interact_pointer_pos();
        let primary = ctx.input(|i| i.pointer.primary_down());
        match self.colorize.tool {
            ColorizeTool::Brush => {
                if response.drag_started_by(egui::PointerButton::Primary) {
                    // Where the button went down, not where the drag was recognized.
                    let origin = ctx.input(|i| i.pointer.press_origin()).or(pointer);
                    self.colorize.drawing = origin.map(|at| vec![placed.canvas_from_screen(at)]);
                }
                if let (Some(at), true, Some(points)) =
                    (pointer, response.dragged(), &mut self.colorize.drawing)
                {
                    let p = placed.canvas_from_screen(at);
                    if points
                        .last()
                        .is_none_or(|q| super::rig_mode::distance(*q, p) >= BRUSH_STEP_PX)
                    {
                        points.push(p);
                    }
                }
                if response.drag_stopped() {
                    if let Some(points) = self.colorize.drawing.take() {
                        let stroke = self.colorize.stroke(points);
                        self.apply_colorize(SessionCommand::AddStroke(stroke));
                    }
                }
                if response.clicked() {
                    if let Some(at) = pointer {
                        let stroke = self.colorize.stroke(vec![placed.canvas_from_screen(at)]);
                        self.apply_colorize(SessionCommand::AddStroke(stroke));
                    }
                }
            }
            ColorizeTool::Eraser => {
                self.colorize.drawing = None;
                let erasing = response.clicked() || (response.dragged() && primary);
                if let (Some(at), true) = (pointer, erasing) {
                    let command = SessionCommand::EraseNear {
                        at_px: placed.canvas_from_screen(at),
                        radius_px: self.eraser_radius_px(&placed),
                    };
                    if let Some(session) = &mut self.colorize.session {
                        match session.apply(command) {
                            // Passing over paper erases nothing: no message for that.
                            Ok(()) | Err(SessionError::NothingToErase { .. }) => {}
                            Err(e) => self.fail(e.to_string()),
                        }
                    }
                }
            }
        }
    }
}

/// `NAME.colorized.png` beside the line art `NAME.png`.
pub fn colorized_path(lineart: &Path) -> PathBuf {
    let stem = lineart
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "lineart".into());
    lineart.with_file_name(format!("{stem}.colorized.png"))
}

/// `NAME.scribbles.json` beside the line art `NAME.png`.
pub fn scribbles_path(lineart: &Path) -> PathBuf {
    crate::document::side_file(lineart, "scribbles")
}

fn is_png(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
}

/// A label and a one-line text field it names (found by the label's text).
fn labelled_text_field(ui: &mut egui::Ui, text: &str, value: &mut String) {
    let label = ui.label(text);
    ui.text_edit_singleline(value).labelled_by(label.id);
}

/// A small square of `color` (framed when `selected`) that picks it; named "Swatch #rrggbb"
/// for screen readers and tests.
fn swatch_button(ui: &mut egui::Ui, color: [u8; 3], selected: bool) -> egui::Response {
    let fill = Color32::from_rgb(color[0], color[1], color[2]);
    let frame = if selected {
        egui::Stroke::new(2.0, Color32::WHITE)
    } else {
        egui::Stroke::new(1.0, Color32::from_gray(90))
    };
    let response = ui.add(
        egui::Button::new("")
            .fill(fill)
            .stroke(frame)
            .min_size(egui::vec2(18.0, 18.0)),
    );
    let name = format!("Swatch #{}", crate::colorize::scribbles::hex(color));
    response.widget_info(|| {
        egui::WidgetInfo::selected(egui::WidgetType::Button, true, selected, name.clone())
    });
    response.on_hover_text(&name[7..])
}

/// A scribble as the brush painted it: its path at its width, round joins and caps.
fn stroke_shapes(placed: &Placed, stroke: &ScribbleStroke) -> Vec<egui::Shape> {
    let [r, g, b] = stroke.color;
    let color = Color32::from_rgb(r, g, b);
    let width = stroke.width_px as f32 * placed.view.zoom;
    let points: Vec<Pos2> = stroke
        .points_px
        .iter()
        .map(|p| placed.screen_from_canvas(*p))
        .collect();
    // A dark rim first: a scribble stays visible over the region it colored.
    let rim = Color32::from_black_alpha(150);
    let mut shapes = Vec::new();
    for (w, c) in [(width + 2.0, rim), (width, color)] {
        shapes.extend(
            points
                .iter()
                .map(|p| egui::Shape::circle_filled(*p, w / 2.0, c)),
        );
        if points.len() > 1 {
            shapes.push(egui::Shape::line(points.clone(), egui::Stroke::new(w, c)));
        }
    }
    shapes
}
