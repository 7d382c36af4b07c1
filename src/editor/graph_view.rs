//! Animate mode's graph view: a resizable window drawing every curve channel of the selected
//! handle over the whole animation at once (rotate; translate, scale and shear x and y), each
//! in its colour, with a legend that shows or hides each curve. The Bézier handles of every
//! segment drawn can be dragged, as in the one-segment curve editor ([`super::curves`]).
//!
//! In: the animation edited, the selected handle, pointer input. Out: `SetCurve` commands
//! (undoable, checked by [`crate::anim::edit::set_curve`]) and the picture.
//!
//! Channels have different units (degrees, px, factors), so by default each curve is drawn
//! over its own value range, scaled to the plot's height, and the legend gives each range;
//! the value axis is labelled when one curve is shown. "Same scale" draws every shown curve
//! over one range with a labelled value axis. The time axis is labelled in seconds.

use super::EditorApp;
use crate::anim::edit::{self, KeyRef, TimelineId};
use crate::anim::{Animation, Curve};
use crate::document::Command;
use eframe::egui::{self, Color32, Pos2, Rect, Sense, Shape, Stroke};
use std::collections::BTreeSet;

/// The window's size when it first opens, points.
pub const GRAPH_DEFAULT_PT: [f32; 2] = [640.0, 380.0];
/// Screen distance within which a press grabs a Bézier handle, points.
const HANDLE_PICK_PT: f32 = 9.0;
/// Margins of the plot inside its frame, points: room for the value labels on the left and
/// the time labels below.
const PLOT_MARGIN_LEFT_PT: f32 = 44.0;
const PLOT_MARGIN_BOTTOM_PT: f32 = 18.0;
const PLOT_MARGIN_PT: f32 = 12.0;
/// Screen distance wanted between value ticks and between time ticks, points.
const VALUE_TICK_SPACING_PT: f32 = 36.0;
const TIME_TICK_SPACING_PT: f32 = 70.0;
/// Points sampled per segment when drawing a curve.
const SAMPLES_PER_SEGMENT: usize = 48;
/// Curve colours, one per channel in legend order (cycled).
const PALETTE: [Color32; 7] = [
    Color32::from_rgb(230, 190, 60),
    Color32::from_rgb(235, 90, 80),
    Color32::from_rgb(110, 200, 90),
    Color32::from_rgb(90, 150, 245),
    Color32::from_rgb(200, 120, 230),
    Color32::from_rgb(80, 210, 210),
    Color32::from_rgb(240, 150, 70),
];

/// One curve drawn: a value channel of one timeline.
#[derive(Clone, Debug)]
pub struct GraphCurve {
    /// As the legend names it: `head rotate`, `head translate x`, ….
    pub name: String,
    pub timeline: TimelineId,
    pub channel: usize,
    /// Value range drawn, bottom to top of the plot.
    pub low: f64,
    pub high: f64,
    /// Each Bézier handle drawn: its segment's start key, the index of its time in the
    /// curve numbers (its value follows), and where it is on screen.
    pub handles: Vec<(KeyRef, usize, Pos2)>,
}

/// Where last frame's graph was drawn.
#[derive(Clone, Debug)]
pub struct GraphLayout {
    pub rect: Rect,
    pub start_s: f64,
    pub end_s: f64,
    pub curves: Vec<GraphCurve>,
    /// The value axis' labelled ticks (value, screen y), when it is labelled.
    pub value_ticks: Vec<(f64, f32)>,
    /// The time axis' labelled ticks (seconds, screen x).
    pub time_ticks: Vec<(f64, f32)>,
}

impl GraphLayout {
    fn x_of(&self, time_s: f64) -> f32 {
        let f = ((time_s - self.start_s) / (self.end_s - self.start_s)) as f32;
        self.rect.left() + f * self.rect.width()
    }

    fn time_at(&self, x: f32) -> f64 {
        let f = f64::from((x - self.rect.left()) / self.rect.width());
        self.start_s + f * (self.end_s - self.start_s)
    }
}

fn y_of(rect: Rect, low: f64, high: f64, value: f64) -> f32 {
    let f = ((value - low) / (high - low)) as f32;
    rect.bottom() - f * rect.height()
}

fn value_at(rect: Rect, low: f64, high: f64, y: f32) -> f64 {
    low + f64::from((rect.bottom() - y) / rect.height()) * (high - low)
}

/// A handle being dragged: the numbers as dragged so far, and the value range it is drawn in
/// (kept for the drag, so the curve does not rescale under the pointer).
#[derive(Clone, Debug)]
struct HandleDrag {
    key: KeyRef,
    at: usize,
    numbers: Vec<f64>,
    low: f64,
    high: f64,
}

/// The graph view's state.
#[derive(Default)]
pub struct GraphView {
    /// The window is open.
    pub open: bool,
    /// Curves hidden from the legend, by name.
    pub hidden: BTreeSet<String>,
    /// Every shown curve drawn over one value range (off: each over its own).
    pub same_scale: bool,
    /// Where the graph was drawn last frame (tests find handles by it).
    pub layout: Option<GraphLayout>,
    drag: Option<HandleDrag>,
}

/// The value channels' names of a timeline: `x` and `y` for two, none for one.
fn channel_suffix(channels: usize, c: usize) -> &'static str {
    match (channels, c) {
        (1, _) => "",
        (2, 0) => " x",
        (2, 1) => " y",
        (4, k) => [" red", " green", " blue", " alpha"][k.min(3)],
        _ => " ?",
    }
}

/// The timelines with curves that belong to `handle` (a bone's or point's transform channels).
fn handle_timelines(animation: &Animation, handle: &str) -> Vec<(TimelineId, Vec<f64>)> {
    edit::timelines(animation)
        .into_iter()
        .filter(|(t, _)| match t {
            TimelineId::Bone { bone, .. } => bone == handle,
            TimelineId::Point { point, .. } => point == handle,
            _ => false,
        })
        .collect()
}

impl EditorApp {
    /// The button that opens the graph view.
    pub(super) fn graph_view_button(&mut self, ui: &mut egui::Ui) {
        if ui
            .button("Graph view")
            .on_hover_text("every curve of the selected handle in a resizable window")
            .clicked()
        {
            self.timeline.graph.open = !self.timeline.graph.open;
        }
    }

    /// The graph view window (animate mode, while open).
    pub(super) fn graph_view_window(&mut self, ctx: &egui::Context) {
        let mut open = self.timeline.graph.open;
        if !open {
            self.timeline.graph.layout = None;
            return;
        }
        // Over the canvas's right side, not over the side panel.
        let right_top = ctx.content_rect().right_top() + egui::vec2(-16.0, 48.0);
        egui::Window::new("Graph view")
            .open(&mut open)
            .resizable(true)
            .pivot(egui::Align2::RIGHT_TOP)
            .default_pos(right_top)
            .default_size(GRAPH_DEFAULT_PT)
            .show(ctx, |ui| self.graph_view(ui));
        self.timeline.graph.open = open;
    }

    fn graph_view(&mut self, ui: &mut egui::Ui) {
        self.timeline.graph.layout = None;
        let Some(handle) = self.selected.clone() else {
            ui.label("Select a bone or point to see its curves.");
            return;
        };
        let animation = crate::document::animation_named(self.doc.state(), &self.animate.animation);
        let timelines = handle_timelines(&animation, &handle);
        if timelines.is_empty() {
            ui.label(format!("'{handle}' has no keys in this animation."));
            return;
        }
        // Every value channel of every timeline, with its segments.
        let mut curves = Vec::new();
        for (timeline, times) in &timelines {
            let segments: Vec<(KeyRef, edit::Segment)> = times
                .iter()
                .filter_map(|&time_s| {
                    let key = KeyRef {
                        timeline: timeline.clone(),
                        time_s,
                    };
                    edit::segment(&animation, &key).ok().map(|s| (key, s))
                })
                .collect();
            let channels = segments.first().map_or(0, |(_, s)| s.channels());
            for c in 0..channels {
                let name = format!("{}{}", timeline.label(), channel_suffix(channels, c));
                curves.push((name, timeline.clone(), c, segments.clone()));
            }
        }
        let length_s = self.timeline_length_s();
        // The legend: a box per curve, in its colour, with the range it is drawn over.
        let mut ranges = Vec::new();
        ui.horizontal_wrapped(|ui| {
            for (i, (name, _, c, segments)) in curves.iter().enumerate() {
                let (low, high) = curve_range(segments, *c, self.timeline.graph.drag.as_ref());
                ranges.push((low, high));
                let colour = PALETTE[i % PALETTE.len()];
                let mut shown = !self.timeline.graph.hidden.contains(name);
                let (swatch, painter) = ui.allocate_painter(egui::vec2(12.0, 12.0), Sense::hover());
                painter.rect_filled(swatch.rect, 2.0, colour);
                if ui
                    .checkbox(&mut shown, name.as_str())
                    .on_hover_text(format!("drawn from {low:.2} (bottom) to {high:.2} (top)"))
                    .changed()
                {
                    if shown {
                        self.timeline.graph.hidden.remove(name);
                    } else {
                        self.timeline.graph.hidden.insert(name.clone());
                    }
                }
            }
        });
        ui.checkbox(&mut self.timeline.graph.same_scale, "Same scale")
            .on_hover_text("every shown curve over one value range, with its values on the axis");
        let shown: Vec<usize> = (0..curves.len())
            .filter(|&i| !self.timeline.graph.hidden.contains(&curves[i].0))
            .collect();
        if self.timeline.graph.same_scale {
            // While a handle is dragged, the range the drag began with: no rescaling under
            // the pointer.
            let shared = match &self.timeline.graph.drag {
                Some(drag) => (drag.low, drag.high),
                None => shown
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |r, &i| {
                        (r.0.min(ranges[i].0), r.1.max(ranges[i].1))
                    }),
            };
            if shared.0 < shared.1 {
                ranges.iter_mut().for_each(|r| *r = shared);
            }
        }
        // The plot takes what the window has left: resizing the window resizes it.
        let size = ui.available_size().max(egui::vec2(160.0, 100.0));
        let (response, painter) = ui.allocate_painter(size, Sense::drag());
        painter.rect_filled(response.rect, 2.0, Color32::from_gray(28));
        let frame = response.rect;
        let mut layout = GraphLayout {
            rect: Rect::from_min_max(
                frame.min + egui::vec2(PLOT_MARGIN_LEFT_PT, PLOT_MARGIN_PT),
                frame.max - egui::vec2(PLOT_MARGIN_PT, PLOT_MARGIN_BOTTOM_PT),
            ),
            start_s: 0.0,
            end_s: length_s,
            curves: Vec::new(),
            value_ticks: Vec::new(),
            time_ticks: Vec::new(),
        };
        // The value axis is labelled when its numbers mean one thing: one curve shown, or
        // every shown curve on the same scale.
        let labelled = match shown.as_slice() {
            [one] => Some(ranges[*one]),
            [first, ..] if self.timeline.graph.same_scale => Some(ranges[*first]),
            _ => None,
        };
        draw_axes(&painter, &mut layout, labelled);
        // The playhead.
        let x = layout.x_of(self.animate.time_s);
        painter.line_segment(
            [
                egui::pos2(x, response.rect.top()),
                egui::pos2(x, response.rect.bottom()),
            ],
            Stroke::new(1.0, Color32::from_rgb(200, 60, 60)),
        );
        for (i, ((name, timeline, c, mut segments), (low, high))) in
            curves.into_iter().zip(ranges).enumerate()
        {
            if self.timeline.graph.hidden.contains(&name) {
                continue;
            }
            let colour = PALETTE[i % PALETTE.len()];
            let rect = layout.rect;
            let mut handles = Vec::new();
            for (key, segment) in &mut segments {
                // A handle being dragged shows where it is, not where the document has it.
                if let Some(drag) = &self.timeline.graph.drag {
                    if drag.key == *key {
                        segment.curve = Curve::Bezier(drag.numbers.clone());
                    }
                }
                let points: Vec<Pos2> = (0..=SAMPLES_PER_SEGMENT)
                    .map(|k| {
                        let t = segment.start_s
                            + (segment.end_s - segment.start_s) * k as f64
                                / SAMPLES_PER_SEGMENT as f64;
                        egui::pos2(
                            layout.x_of(t),
                            y_of(rect, low, high, segment.value_at(c, t)),
                        )
                    })
                    .collect();
                painter.add(Shape::line(points, Stroke::new(2.0, colour)));
                let ends = [
                    (segment.start_s, segment.start[c]),
                    (segment.end_s, segment.end[c]),
                ]
                .map(|(t, v)| egui::pos2(layout.x_of(t), y_of(rect, low, high, v)));
                for end in ends {
                    painter.circle_filled(end, 3.5, colour);
                }
                if let Curve::Bezier(n) = &segment.curve {
                    let k = crate::anim::curve::BEZIER_NUMBERS_PER_CHANNEL * c;
                    for (h, end) in ends.iter().enumerate() {
                        let Some(pair) = n.get(k + 2 * h..k + 2 * h + 2) else {
                            continue;
                        };
                        let at = egui::pos2(layout.x_of(pair[0]), y_of(rect, low, high, pair[1]));
                        painter.line_segment([*end, at], Stroke::new(1.0, Color32::from_gray(160)));
                        painter.circle_stroke(at, 4.5, Stroke::new(2.0, colour));
                        handles.push((key.clone(), k + 2 * h, at));
                    }
                }
            }
            layout.curves.push(GraphCurve {
                name,
                timeline,
                channel: c,
                low,
                high,
                handles,
            });
        }
        self.graph_input(ui, &response, &layout, &animation);
        self.timeline.graph.layout = Some(layout);
    }

    fn graph_input(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        layout: &GraphLayout,
        animation: &Animation,
    ) {
        if response.drag_started_by(egui::PointerButton::Primary) {
            let origin = ui
                .input(|i| i.pointer.press_origin())
                .or(response.interact_pointer_pos());
            let nearest = origin.and_then(|at| {
                layout
                    .curves
                    .iter()
                    .flat_map(|c| c.handles.iter().map(move |h| (c, h)))
                    .filter(|(_, h)| h.2.distance(at) <= HANDLE_PICK_PT)
                    .min_by(|a, b| a.1 .2.distance(at).total_cmp(&b.1 .2.distance(at)))
            });
            if let Some((curve, (key, at, _))) = nearest {
                if let Ok(edit::Segment {
                    curve: Curve::Bezier(numbers),
                    ..
                }) = edit::segment(animation, key)
                {
                    self.timeline.graph.drag = Some(HandleDrag {
                        key: key.clone(),
                        at: *at,
                        numbers,
                        low: curve.low,
                        high: curve.high,
                    });
                }
            }
        }
        if let (Some(p), true) = (response.interact_pointer_pos(), response.dragged()) {
            if let Some(drag) = &mut self.timeline.graph.drag {
                let t = layout.time_at(p.x);
                let v = value_at(layout.rect, drag.low, drag.high, p.y);
                if let Ok(segment) = edit::segment(animation, &drag.key) {
                    if let Some(pair) = drag.numbers.get_mut(drag.at..drag.at + 2) {
                        // Handle times stay in the segment: time must keep running forward.
                        pair[0] = t.clamp(segment.start_s, segment.end_s);
                        pair[1] = v;
                    }
                }
            }
        }
        if response.drag_stopped() {
            if let Some(drag) = self.timeline.graph.drag.take() {
                self.apply(Command::SetCurve {
                    animation: self.animate.animation.clone(),
                    key: drag.key,
                    curve: Curve::Bezier(drag.numbers),
                });
            }
        }
    }
}

/// The grid and labels of both axes: time in seconds below the plot, values (when
/// `value_range` is given) on its left. Records the ticks in `layout`.
fn draw_axes(painter: &egui::Painter, layout: &mut GraphLayout, value_range: Option<(f64, f64)>) {
    use super::ticks::{nice_ticks, tick_label};
    let rect = layout.rect;
    let font = egui::FontId::proportional(11.0);
    let grid = Stroke::new(1.0, Color32::from_gray(48));
    let text = Color32::from_gray(170);
    let count = (rect.width() / TIME_TICK_SPACING_PT).floor().max(1.0) as usize;
    let (step, times) = nice_ticks(layout.start_s, layout.end_s, count);
    for t in times {
        let x = layout.x_of(t);
        painter.line_segment(
            [egui::pos2(x, rect.top()), egui::pos2(x, rect.bottom())],
            grid,
        );
        painter.text(
            egui::pos2(x, rect.bottom() + 3.0),
            egui::Align2::CENTER_TOP,
            format!("{} s", tick_label(t, step)),
            font.clone(),
            text,
        );
        layout.time_ticks.push((t, x));
    }
    let Some((low, high)) = value_range else {
        return;
    };
    let count = (rect.height() / VALUE_TICK_SPACING_PT).floor().max(1.0) as usize;
    let (step, values) = nice_ticks(low, high, count);
    for v in values {
        let y = y_of(rect, low, high, v);
        painter.line_segment(
            [egui::pos2(rect.left(), y), egui::pos2(rect.right(), y)],
            grid,
        );
        painter.text(
            egui::pos2(rect.left() - 4.0, y),
            egui::Align2::RIGHT_CENTER,
            tick_label(v, step),
            font.clone(),
            text,
        );
        layout.value_ticks.push((v, y));
    }
}

/// The value range a curve is drawn over: its keys, samples and handles, padded; while one
/// of its handles is dragged, the range it had when the drag began.
fn curve_range(
    segments: &[(KeyRef, edit::Segment)],
    c: usize,
    drag: Option<&HandleDrag>,
) -> (f64, f64) {
    if let Some(drag) = drag {
        let k = crate::anim::curve::BEZIER_NUMBERS_PER_CHANNEL * c;
        if segments.iter().any(|(key, _)| *key == drag.key) && (k..k + 4).contains(&drag.at) {
            return (drag.low, drag.high);
        }
    }
    let mut values = Vec::new();
    for (_, s) in segments {
        values.extend((0..=SAMPLES_PER_SEGMENT).map(|k| {
            s.value_at(
                c,
                s.start_s + (s.end_s - s.start_s) * k as f64 / SAMPLES_PER_SEGMENT as f64,
            )
        }));
        if let Curve::Bezier(n) = &s.curve {
            let k = crate::anim::curve::BEZIER_NUMBERS_PER_CHANNEL * c;
            values.extend(n.get(k..k + 4).iter().flat_map(|p| [p[1], p[3]]));
        }
    }
    let (mut low, mut high) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    if !low.is_finite() || !high.is_finite() {
        return (-1.0, 1.0);
    }
    if high - low < 1e-9 {
        (low, high) = (low - 1.0, high + 1.0);
    }
    let pad = 0.08 * (high - low);
    (low - pad, high + pad)
}
