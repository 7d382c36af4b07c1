//! Animate mode's panel: the transport, the dopesheet and the curve editor (the playhead,
//! playback and onion skins are [`super::animate_mode`]'s).
//!
//! In: the document's animation being edited, the playhead, pointer and keys. Out: document
//! commands — `SetKey` and `DeleteKeys` at the playhead, `MoveKeys`, `PasteKeys`,
//! `DeleteTimelineKeys` and `SetCurve` for the keys selected in the dopesheet (the logic and the
//! checks are [`crate::anim::edit`]'s) — and pictures: the transport (play, pause, loop at the
//! frame rate, frame steps), the dopesheet (a row per timeline, one per handle and channel:
//! click, shift-click and box-select keys, drag them in time snapped to frames, copy, paste at
//! the playhead, delete; rows for attachment swaps, deform keys and events too); beside it the
//! curve editor ([`super::curves`]), or for a time of the events row its payload
//! ([`super::events`]).

use super::animate_mode::{OnionOptions, MAX_ONION_FRAMES};
use super::curves::{CurveLayout, CURVE_GRAPH_PT};
use super::number_field::{number_field, slider};
use super::{EditorApp, Mode};
use crate::anim::edit::{self, CopiedKey, KeyRef, TimelineId, KEY_TIME_TOLERANCE_S};
use crate::document::Command;
use crate::geom::Point;
use eframe::egui::{self, Color32, Key, Modifiers, Pos2, Rect, Sense, Shape, Stroke};

/// Height of a dopesheet row (the ruler, the summary and each timeline), points.
pub const ROW_HEIGHT_PT: f32 = 18.0;
/// Width of the dopesheet's name column, points.
pub const LABEL_WIDTH_PT: f32 = 150.0;
/// Horizontal distance within which a click picks a key, points.
pub const KEY_PICK_PT: f32 = 6.0;

/// Where last frame's dopesheet was drawn (tests convert key times to screen with it).
#[derive(Clone, Debug)]
pub struct SheetLayout {
    pub rect: Rect,
    /// x of time 0, points.
    pub zero_x: f32,
    pub px_per_s: f32,
    pub ruler: Rect,
    /// Centre line of the row of all keys.
    pub summary_y: f32,
    /// Each timeline's row, centre line.
    pub rows: Vec<(TimelineId, f32)>,
    /// Each row's name, as drawn ([`row_names`]).
    pub names: Vec<String>,
}

impl SheetLayout {
    pub fn x_of(&self, time_s: f64) -> f32 {
        self.zero_x + self.px_per_s * time_s as f32
    }

    pub fn time_at(&self, x: f32) -> f64 {
        f64::from((x - self.zero_x) / self.px_per_s).max(0.0)
    }

    /// Where the key at `time_s` of `timeline` is drawn.
    pub fn key_pos(&self, timeline: &TimelineId, time_s: f64) -> Option<Pos2> {
        let (_, y) = self.rows.iter().find(|(t, _)| t == timeline)?;
        Some(Pos2::new(self.x_of(time_s), *y))
    }

    fn row_at(&self, y: f32) -> Option<&TimelineId> {
        self.rows
            .iter()
            .find(|(_, cy)| (y - cy).abs() <= ROW_HEIGHT_PT / 2.0)
            .map(|(t, _)| t)
    }
}

/// What a press in the dopesheet landed on.
pub(super) enum Hit {
    Ruler,
    Key(KeyRef),
    /// A key of the row of all keys: every key at that time.
    Summary(f64),
    /// A timeline's name: all its keys.
    Row(TimelineId),
    Empty,
}

pub(super) enum SheetGesture {
    Scrub,
    Move {
        anchor_s: f64,
        origin_x: f32,
        delta_s: f64,
    },
    Box {
        from: Pos2,
        to: Pos2,
        add: bool,
    },
    CurveHandle {
        key: KeyRef,
        /// Index of the handle's time in the curve numbers (its value follows).
        at: usize,
        numbers: Vec<f64>,
    },
}

/// Animate mode's state beside the document.
pub struct TimelineState {
    /// Keys selected in the dopesheet.
    pub selection: Vec<KeyRef>,
    /// The keys last copied.
    pub clipboard: Vec<CopiedKey>,
    /// Whether playback starts again at the end (default) or stops there.
    pub looping: bool,
    pub onion: OnionOptions,
    /// Auto-key: every pose edit in animate mode keys the channels it changed at the
    /// playhead (default off: edits wait for *Set key*).
    pub auto_key: bool,
    /// Which value channel (x, y; r, g, b, a) the curve editor shows.
    pub curve_channel: usize,
    pub sheet: Option<SheetLayout>,
    pub curve: Option<CurveLayout>,
    /// The graph view window: every curve of the selected handle ([`super::graph_view`]).
    pub graph: super::graph_view::GraphView,
    pub(super) gesture: Option<SheetGesture>,
    /// The animation the selection belongs to.
    selection_of: String,
}

impl Default for TimelineState {
    fn default() -> Self {
        TimelineState {
            selection: Vec::new(),
            clipboard: Vec::new(),
            looping: true,
            onion: OnionOptions::default(),
            auto_key: false,
            curve_channel: 0,
            sheet: None,
            curve: None,
            graph: Default::default(),
            gesture: None,
            selection_of: String::new(),
        }
    }
}

/// The dopesheet's row names: a transform channel's `arm rotate`; an IK drag named after the
/// handle nearest its rest point at rest (`hand drag`, numbered when several drags share one:
/// `hand drag 2`), not by its index.
pub fn row_names(
    timelines: &[(TimelineId, Vec<f64>)],
    animation: &crate::anim::Animation,
    handles: &crate::rig::Handles,
) -> Vec<String> {
    let mut per_handle: std::collections::BTreeMap<String, usize> = Default::default();
    timelines
        .iter()
        .map(|(t, _)| match t {
            TimelineId::Ik { index } => {
                let Some(at) = animation.ik.get(*index).map(|d| d.at) else {
                    return t.label();
                };
                let Some(handle) = nearest_handle(handles, at) else {
                    return t.label();
                };
                let n = per_handle.entry(handle.clone()).or_default();
                *n += 1;
                if *n == 1 {
                    format!("{handle} drag")
                } else {
                    format!("{handle} drag {n}")
                }
            }
            _ => t.label(),
        })
        .collect()
}

/// The bone (its segment) or point nearest `at_px` at rest.
fn nearest_handle(handles: &crate::rig::Handles, at_px: Point) -> Option<String> {
    let distance = |a: Point, b: Point| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len2 = dx * dx + dy * dy;
        let f = if len2 > 0.0 {
            (((at_px[0] - a[0]) * dx + (at_px[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (at_px[0] - a[0] - f * dx).hypot(at_px[1] - a[1] - f * dy)
    };
    let bones = handles
        .bones
        .iter()
        .map(|b| (distance(b.head, b.tail), &b.name));
    let points = handles
        .points
        .iter()
        .map(|p| (distance(p.at, p.at), &p.name));
    bones
        .chain(points)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, name)| name.clone())
}

pub(super) fn diamond(center: Pos2, radius: f32, fill: Color32, stroke: Stroke) -> Shape {
    Shape::convex_polygon(
        vec![
            center + egui::vec2(0.0, -radius),
            center + egui::vec2(radius, 0.0),
            center + egui::vec2(0.0, radius),
            center + egui::vec2(-radius, 0.0),
        ],
        fill,
        stroke,
    )
}

impl EditorApp {
    /// Animate mode's keyboard: copy, paste, and delete of the selected keys (run before the
    /// editor's shortcuts, so Delete deletes keys rather than the selected handle).
    pub(super) fn timeline_shortcuts(&mut self, ctx: &egui::Context) {
        if self.mode != Mode::Animate || ctx.text_edit_focused() {
            return;
        }
        let selected = !self.timeline.selection.is_empty();
        let (copy, paste, delete) = ctx.input_mut(|i| {
            // Native windows turn Ctrl+C / Ctrl+V into Copy and Paste events.
            let copy = i.consume_key(Modifiers::COMMAND, Key::C)
                || i.events.iter().any(|e| matches!(e, egui::Event::Copy));
            let pasted = i.events.iter().find_map(|e| match e {
                egui::Event::Paste(text) => Some(text.clone()),
                _ => None,
            });
            let paste = match (i.consume_key(Modifiers::COMMAND, Key::V), pasted) {
                (_, Some(text)) => Some(Some(text)),
                (true, None) => Some(None),
                (false, None) => None,
            };
            let delete = selected
                && (i.consume_key(Modifiers::NONE, Key::Delete)
                    || i.consume_key(Modifiers::NONE, Key::Backspace));
            (copy, paste, delete)
        });
        if copy && selected {
            self.copy_keys();
            // The system clipboard gets them too, so the window's Ctrl+V comes back as a paste.
            if let Ok(text) = serde_json::to_string(&self.timeline.clipboard) {
                ctx.copy_text(text);
            }
        }
        if let Some(text) = paste {
            if let Some(keys) = text.and_then(|t| serde_json::from_str::<Vec<CopiedKey>>(&t).ok()) {
                self.timeline.clipboard = keys;
            }
            self.paste_keys();
        }
        if delete {
            self.delete_selected_keys();
        }
    }

    /// Copies the selected keys to the editor's clipboard.
    pub fn copy_keys(&mut self) {
        let animation = crate::document::animation_named(self.doc.state(), &self.animate.animation);
        match edit::copy_keys(&animation, &self.timeline.selection) {
            Ok(keys) => self.timeline.clipboard = keys,
            Err(e) => self.fail(e.to_string()),
        }
    }

    /// Pastes the clipboard at the playhead (on its frame); the pasted keys become the
    /// selection.
    pub fn paste_keys(&mut self) {
        if self.timeline.clipboard.is_empty() {
            return;
        }
        let at_s = self.snap_to_frame(self.animate.time_s).max(0.0);
        let keys = self.timeline.clipboard.clone();
        if self.apply(Command::PasteKeys {
            animation: self.animate.animation.clone(),
            at_s,
            keys: keys.clone(),
        }) {
            self.timeline.selection = keys
                .into_iter()
                .map(|k| KeyRef {
                    timeline: k.timeline,
                    time_s: at_s + k.offset_s,
                })
                .collect();
        }
    }

    pub fn delete_selected_keys(&mut self) {
        if self.timeline.selection.is_empty() {
            return;
        }
        if self.apply(Command::DeleteTimelineKeys {
            animation: self.animate.animation.clone(),
            keys: self.timeline.selection.clone(),
        }) {
            self.timeline.selection.clear();
        }
    }

    /// The bottom panel of animate mode.
    pub(super) fn animate_panel(&mut self, ui: &mut egui::Ui) {
        let frame_s = self.frame_s();
        ui.horizontal(|ui| {
            // Picked, created and renamed in the side panel's list of animations.
            ui.label(format!("Animation '{}'", self.animate.animation));
            let play = if self.animate.playing {
                "Pause"
            } else {
                "Play"
            };
            if ui.button(play).clicked() {
                self.toggle_playback();
            }
            ui.checkbox(&mut self.timeline.looping, "Loop");
            if ui.button("Previous frame").clicked() {
                let t = ((self.animate.time_s / frame_s).round() - 1.0).max(0.0) * frame_s;
                self.set_time(t);
            }
            if ui.button("Next frame").clicked() {
                let t = ((self.animate.time_s / frame_s).round() + 1.0) * frame_s;
                self.set_time(t);
            }
            ui.add(
                number_field(&mut self.render_settings.fps)
                    .range(1.0..=crate::playback::MAX_FPS)
                    .speed(0.1)
                    .suffix(" fps"),
            );
            let mut t = self.animate.time_s;
            let length = self.timeline_length_s();
            if ui.add(slider(&mut t, 0.0..=length).text("s")).changed() {
                self.set_time(t);
            }
            if ui
                .button("Set key")
                .on_hover_text("key the pose shown at the playhead (K)")
                .clicked()
            {
                self.set_key();
            }
            ui.checkbox(&mut self.timeline.auto_key, "Auto-key")
                .on_hover_text("key every pose edit at the playhead as it is made");
            if ui.button("Delete key").clicked() {
                let animation = self.animate.animation.clone();
                self.apply(Command::DeleteKeys {
                    animation,
                    time_s: self.animate.time_s,
                });
            }
        });
        if let Some(target) = self.doc.state().target {
            // What the preview plays (`sinew target` sets the rig's runtime).
            ui.label(super::pose_mode::target_label(target));
        }
        ui.horizontal(|ui| {
            let selected = !self.timeline.selection.is_empty();
            if ui
                .add_enabled(selected, egui::Button::new("Copy keys"))
                .clicked()
            {
                self.copy_keys();
            }
            let pastable = !self.timeline.clipboard.is_empty();
            if ui
                .add_enabled(pastable, egui::Button::new("Paste keys"))
                .clicked()
            {
                self.paste_keys();
            }
            if ui
                .add_enabled(selected, egui::Button::new("Delete selected keys"))
                .clicked()
            {
                self.delete_selected_keys();
            }
            ui.separator();
            let onion = &mut self.timeline.onion;
            ui.checkbox(&mut onion.enabled, "Onion skin");
            ui.add(
                number_field(&mut onion.frames)
                    .range(1..=MAX_ONION_FRAMES)
                    .suffix(" frames"),
            );
            ui.add(slider(&mut onion.opacity, 0.05..=1.0).text("opacity"));
        });
        let animation = crate::document::animation_named(self.doc.state(), &self.animate.animation);
        let timelines = edit::timelines(&animation);
        // Another animation, undo, redo and other edits can take selected keys away.
        if self.timeline.selection_of != self.animate.animation {
            self.timeline.selection_of = self.animate.animation.clone();
            self.timeline.selection.clear();
        }
        self.timeline.selection.retain(|k| {
            timelines
                .iter()
                .any(|(t, times)| times.iter().any(|&s| k.is(t, s)))
        });
        ui.horizontal_top(|ui| {
            let width = (ui.available_width() - CURVE_GRAPH_PT[0] - 24.0).max(240.0);
            // Ask for the whole sheet (up to the cap), or the panel stays at its last height.
            let sheet_height = ROW_HEIGHT_PT * (timelines.len() as f32 + 2.0);
            egui::ScrollArea::vertical()
                .id_salt("dopesheet")
                .max_height(240.0)
                .min_scrolled_height(sheet_height.min(240.0))
                .max_width(width)
                .show(ui, |ui| self.dopesheet(ui, width, &timelines));
            ui.separator();
            ui.vertical(|ui| {
                self.graph_view_button(ui);
                if self.event_selected() {
                    self.timeline.curve = None;
                    self.event_key_panel(ui);
                } else {
                    self.curve_editor(ui, &animation);
                }
            });
        });
    }

    pub(super) fn hit(
        &self,
        layout: &SheetLayout,
        p: Pos2,
        timelines: &[(TimelineId, Vec<f64>)],
    ) -> Hit {
        if layout.ruler.contains(p) {
            return Hit::Ruler;
        }
        let near = |t: f64| (layout.x_of(t) - p.x).abs() <= KEY_PICK_PT;
        let nearest = |times: &[f64]| {
            times.iter().copied().filter(|&t| near(t)).min_by(|a, b| {
                (layout.x_of(*a) - p.x)
                    .abs()
                    .total_cmp(&(layout.x_of(*b) - p.x).abs())
            })
        };
        if (p.y - layout.summary_y).abs() <= ROW_HEIGHT_PT / 2.0 {
            let all: Vec<f64> = timelines.iter().flat_map(|(_, t)| t.clone()).collect();
            return nearest(&all).map_or(Hit::Empty, Hit::Summary);
        }
        let Some(row) = layout.row_at(p.y) else {
            return Hit::Empty;
        };
        if p.x < layout.zero_x - KEY_PICK_PT {
            return Hit::Row(row.clone());
        }
        timelines
            .iter()
            .find(|(t, _)| t == row)
            .and_then(|(t, times)| {
                nearest(times).map(|time_s| {
                    Hit::Key(KeyRef {
                        timeline: t.clone(),
                        time_s,
                    })
                })
            })
            .unwrap_or(Hit::Empty)
    }

    pub(super) fn is_selected(&self, timeline: &TimelineId, time_s: f64) -> bool {
        self.timeline
            .selection
            .iter()
            .any(|k| k.is(timeline, time_s))
    }

    fn select(&mut self, key: KeyRef) {
        if !self.is_selected(&key.timeline, key.time_s) {
            self.timeline.selection.push(key);
        }
    }

    fn dopesheet(&mut self, ui: &mut egui::Ui, width: f32, timelines: &[(TimelineId, Vec<f64>)]) {
        let height = ROW_HEIGHT_PT * (timelines.len() as f32 + 2.0);
        let (response, painter) =
            ui.allocate_painter(egui::vec2(width, height), Sense::click_and_drag());
        let rect = response.rect;
        let length = self.timeline_length_s();
        let zero_x = rect.left() + LABEL_WIDTH_PT;
        let px_per_s = ((rect.right() - 10.0 - zero_x) / length as f32).max(1.0);
        let ruler = Rect::from_min_max(
            rect.min,
            egui::pos2(rect.right(), rect.top() + ROW_HEIGHT_PT),
        );
        let layout = SheetLayout {
            rect,
            zero_x,
            px_per_s,
            ruler,
            summary_y: rect.top() + 1.5 * ROW_HEIGHT_PT,
            rows: timelines
                .iter()
                .enumerate()
                .map(|(i, (t, _))| (t.clone(), rect.top() + (i as f32 + 2.5) * ROW_HEIGHT_PT))
                .collect(),
            names: row_names(
                timelines,
                &crate::document::animation_named(self.doc.state(), &self.animate.animation),
                &self.doc.state().handles,
            ),
        };
        self.dopesheet_input(ui, &response, &layout, timelines);
        self.key_context_menu(&response, &layout, timelines);

        // Background, ruler with a tick per frame (when they are far enough apart) and seconds.
        painter.rect_filled(rect, 2.0, Color32::from_gray(30));
        painter.rect_filled(ruler, 0.0, Color32::from_gray(45));
        let font = egui::FontId::proportional(11.0);
        let frame_px = px_per_s * self.frame_s() as f32;
        let frames = (length / self.frame_s()).ceil() as usize;
        for f in 0..=frames {
            let t = f as f64 * self.frame_s();
            let x = layout.x_of(t);
            let whole = (t - t.round()).abs() < 1e-9;
            if whole || frame_px >= 5.0 {
                let top = if whole {
                    ruler.top()
                } else {
                    ruler.bottom() - 5.0
                };
                painter.line_segment(
                    [egui::pos2(x, top), egui::pos2(x, ruler.bottom())],
                    Stroke::new(1.0, Color32::from_gray(if whole { 160 } else { 90 })),
                );
            }
            if whole {
                painter.text(
                    egui::pos2(x + 2.0, ruler.top()),
                    egui::Align2::LEFT_TOP,
                    format!("{}", t.round()),
                    font.clone(),
                    Color32::from_gray(190),
                );
            }
        }
        let label = |y: f32, text: &str| {
            painter.text(
                egui::pos2(rect.left() + 4.0, y),
                egui::Align2::LEFT_CENTER,
                text,
                font.clone(),
                Color32::from_gray(200),
            )
        };
        label(layout.summary_y, "all keys");
        for ((_, y), name) in layout.rows.iter().zip(&layout.names) {
            label(*y, name);
            painter.line_segment(
                [
                    egui::pos2(zero_x, y + ROW_HEIGHT_PT / 2.0),
                    egui::pos2(rect.right(), y + ROW_HEIGHT_PT / 2.0),
                ],
                Stroke::new(1.0, Color32::from_gray(38)),
            );
        }

        // Keys; selected ones drawn where a move in progress takes them.
        let shift = match &self.timeline.gesture {
            Some(SheetGesture::Move { delta_s, .. }) => *delta_s,
            _ => 0.0,
        };
        let key_shape = |at: Pos2, selected: bool| {
            let (fill, stroke) = if selected {
                (
                    Color32::from_rgb(255, 140, 40),
                    Stroke::new(1.5, Color32::WHITE),
                )
            } else {
                (Color32::from_rgb(230, 190, 60), Stroke::NONE)
            };
            diamond(at, 5.5, fill, stroke)
        };
        let mut summary: Vec<(f64, bool)> = Vec::new();
        for ((timeline, times), (_, y)) in timelines.iter().zip(&layout.rows) {
            for &t in times {
                let selected = self.is_selected(timeline, t);
                let shown_t = if selected { t + shift } else { t };
                painter.add(key_shape(egui::pos2(layout.x_of(shown_t), *y), selected));
                match summary
                    .iter_mut()
                    .find(|(s, _)| (s - shown_t).abs() <= KEY_TIME_TOLERANCE_S)
                {
                    Some((_, all)) => *all &= selected,
                    None => summary.push((shown_t, selected)),
                }
            }
        }
        for (t, all_selected) in summary {
            painter.add(key_shape(
                egui::pos2(layout.x_of(t), layout.summary_y),
                all_selected,
            ));
        }
        if let Some(SheetGesture::Box { from, to, .. }) = &self.timeline.gesture {
            let r = Rect::from_two_pos(*from, *to);
            painter.rect_filled(r, 0.0, Color32::from_rgba_unmultiplied(120, 160, 255, 40));
            painter.rect_stroke(
                r,
                0.0,
                Stroke::new(1.0, Color32::from_rgb(120, 160, 255)),
                egui::StrokeKind::Inside,
            );
        }
        let x = layout.x_of(self.animate.time_s);
        painter.line_segment(
            [egui::pos2(x, rect.top()), egui::pos2(x, rect.bottom())],
            Stroke::new(2.0, Color32::RED),
        );
        self.timeline.sheet = Some(layout);
    }

    fn dopesheet_input(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        layout: &SheetLayout,
        timelines: &[(TimelineId, Vec<f64>)],
    ) {
        let shift = ui.input(|i| i.modifiers.shift);
        let pointer = response.interact_pointer_pos();
        if response.drag_started_by(egui::PointerButton::Primary) {
            let origin = ui.input(|i| i.pointer.press_origin()).or(pointer);
            if let Some(at) = origin {
                self.timeline.gesture = Some(match self.hit(layout, at, timelines) {
                    Hit::Ruler => SheetGesture::Scrub,
                    Hit::Key(key) => {
                        if !self.is_selected(&key.timeline, key.time_s) {
                            if !shift {
                                self.timeline.selection.clear();
                            }
                            self.select(key.clone());
                        }
                        SheetGesture::Move {
                            anchor_s: key.time_s,
                            origin_x: at.x,
                            delta_s: 0.0,
                        }
                    }
                    Hit::Summary(time_s) => {
                        if !shift {
                            self.timeline.selection.clear();
                        }
                        for key in crate::anim::edit::keys_at(timelines, time_s) {
                            self.select(key);
                        }
                        SheetGesture::Move {
                            anchor_s: time_s,
                            origin_x: at.x,
                            delta_s: 0.0,
                        }
                    }
                    Hit::Row(_) | Hit::Empty => SheetGesture::Box {
                        from: at,
                        to: at,
                        add: shift,
                    },
                });
            }
        }
        if let (Some(at), true) = (pointer, response.dragged()) {
            let earliest = self
                .timeline
                .selection
                .iter()
                .map(|k| k.time_s)
                .fold(f64::INFINITY, f64::min);
            let frame_s = self.frame_s();
            let snapped = move |t: f64| (t / frame_s).round() * frame_s;
            let mut scrub = None;
            match &mut self.timeline.gesture {
                Some(SheetGesture::Scrub) => scrub = Some(snapped(layout.time_at(at.x))),
                Some(SheetGesture::Move {
                    anchor_s,
                    origin_x,
                    delta_s,
                }) => {
                    let raw = *anchor_s + f64::from((at.x - *origin_x) / layout.px_per_s);
                    // The grabbed key lands on a frame; no key goes before 0.
                    *delta_s = (snapped(raw) - *anchor_s).max(-earliest);
                }
                Some(SheetGesture::Box { to, .. }) => *to = at,
                _ => {}
            }
            if let Some(t) = scrub {
                self.set_time(t);
            }
        }
        if response.drag_stopped() {
            match self.timeline.gesture.take() {
                Some(SheetGesture::Move { delta_s, .. })
                    if delta_s.abs() > KEY_TIME_TOLERANCE_S =>
                {
                    let keys = self.timeline.selection.clone();
                    if self.apply(Command::MoveKeys {
                        animation: self.animate.animation.clone(),
                        keys,
                        delta_s,
                    }) {
                        for k in &mut self.timeline.selection {
                            k.time_s += delta_s;
                        }
                    }
                }
                Some(SheetGesture::Box { from, to, add }) => {
                    let r = Rect::from_two_pos(from, to).expand(2.0);
                    if !add {
                        self.timeline.selection.clear();
                    }
                    for (timeline, times) in timelines {
                        for &t in times {
                            if layout.key_pos(timeline, t).is_some_and(|p| r.contains(p)) {
                                self.select(KeyRef {
                                    timeline: timeline.clone(),
                                    time_s: t,
                                });
                            }
                        }
                    }
                }
                other @ Some(SheetGesture::CurveHandle { .. }) => self.timeline.gesture = other,
                _ => {}
            }
        }
        if let (true, Some(at)) = (response.clicked(), pointer) {
            match self.hit(layout, at, timelines) {
                Hit::Ruler => self.set_time(self.snap_to_frame(layout.time_at(at.x))),
                Hit::Key(key) => {
                    if shift {
                        let before = self.timeline.selection.len();
                        self.timeline
                            .selection
                            .retain(|k| !k.is(&key.timeline, key.time_s));
                        if self.timeline.selection.len() == before {
                            self.timeline.selection.push(key);
                        }
                    } else {
                        self.set_time(key.time_s);
                        self.timeline.selection = vec![key];
                    }
                }
                Hit::Summary(time_s) => {
                    if !shift {
                        self.timeline.selection.clear();
                        self.set_time(time_s);
                    }
                    for key in crate::anim::edit::keys_at(timelines, time_s) {
                        self.select(key);
                    }
                }
                Hit::Row(timeline) => {
                    if !shift {
                        self.timeline.selection.clear();
                    }
                    if let Some((_, times)) = timelines.iter().find(|(t, _)| *t == timeline) {
                        for &time_s in times {
                            self.select(KeyRef {
                                timeline: timeline.clone(),
                                time_s,
                            });
                        }
                    }
                }
                Hit::Empty => {
                    if !shift {
                        self.timeline.selection.clear();
                    }
                }
            }
        }
    }
}
