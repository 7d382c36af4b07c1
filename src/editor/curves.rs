//! Animate mode's curve editor: the outgoing segment of the one key selected in the dopesheet
//! ([`super::timeline`]), its kind (linear, stepped, Bézier) and, for a Bézier, the graph of one
//! value channel with the two handles to drag.
//!
//! In: the animation edited, the key selected, pointer input. Out: `SetCurve` commands (checked
//! by [`crate::anim::edit::set_curve`]) and the picture of the graph.

use super::timeline::{diamond, SheetGesture};
use super::EditorApp;
use crate::anim::edit::{self, KeyRef, Segment};
use crate::anim::{Animation, Curve};
use crate::document::Command;
use eframe::egui::{self, Color32, Pos2, Rect, Sense, Shape, Stroke};

/// Size of the curve editor's graph, points.
pub const CURVE_GRAPH_PT: [f32; 2] = [300.0, 150.0];
/// Screen distance within which a press grabs a Bézier handle, points.
const HANDLE_PICK_PT: f32 = 9.0;

/// Where last frame's curve editor graph was drawn.
#[derive(Clone, Debug)]
pub struct CurveLayout {
    pub rect: Rect,
    pub start_s: f64,
    pub end_s: f64,
    /// Value range shown, bottom to top.
    pub low: f64,
    pub high: f64,
    /// The two Bézier handles of the shown channel, when the curve is a Bézier.
    pub handles: Option<[Pos2; 2]>,
}

impl CurveLayout {
    pub fn screen(&self, time_s: f64, value: f64) -> Pos2 {
        let fx = ((time_s - self.start_s) / (self.end_s - self.start_s)) as f32;
        let fy = ((value - self.low) / (self.high - self.low)) as f32;
        Pos2::new(
            self.rect.left() + fx * self.rect.width(),
            self.rect.bottom() - fy * self.rect.height(),
        )
    }

    pub fn graph(&self, p: Pos2) -> (f64, f64) {
        let fx = f64::from((p.x - self.rect.left()) / self.rect.width());
        let fy = f64::from((self.rect.bottom() - p.y) / self.rect.height());
        (
            self.start_s + fx * (self.end_s - self.start_s),
            self.low + fy * (self.high - self.low),
        )
    }
}

fn channel_name(channels: usize, c: usize) -> String {
    match (channels, c) {
        (2, 0) => "x".into(),
        (2, 1) => "y".into(),
        (4, k) => ["red", "green", "blue", "alpha"][k.min(3)].into(),
        _ => format!("channel {c}"),
    }
}

impl EditorApp {
    /// The curve of the one selected key's outgoing segment: its kind, and for a Bézier the
    /// graph of one channel with its two handles to drag.
    pub(super) fn curve_editor(&mut self, ui: &mut egui::Ui, animation: &Animation) {
        self.timeline.curve = None;
        let [key] = self.timeline.selection.as_slice() else {
            ui.label("Select one key to edit the curve to the next key.");
            return;
        };
        let key = key.clone();
        let segment = match edit::segment(animation, &key) {
            Ok(s) => s,
            Err(e) => {
                ui.label(e.to_string());
                return;
            }
        };
        ui.label(format!(
            "{}: {:.3} s to {:.3} s",
            key.timeline.label(),
            segment.start_s,
            segment.end_s
        ));
        let channels = segment.channels();
        self.timeline.curve_channel = self.timeline.curve_channel.min(channels.saturating_sub(1));
        ui.horizontal(|ui| {
            let kind = match segment.curve {
                Curve::Linear => 0,
                Curve::Stepped => 1,
                Curve::Bezier(_) => 2,
            };
            let mut chosen = None;
            if ui.selectable_label(kind == 0, "Linear").clicked() && kind != 0 {
                chosen = Some(Curve::Linear);
            }
            if ui.selectable_label(kind == 1, "Stepped").clicked() && kind != 1 {
                chosen = Some(Curve::Stepped);
            }
            if ui.selectable_label(kind == 2, "Bézier").clicked() && kind != 2 {
                chosen = Some(Curve::Bezier(segment.linear_bezier()));
            }
            if let Some(curve) = chosen {
                self.apply(Command::SetCurve {
                    animation: self.animate.animation.clone(),
                    key: key.clone(),
                    curve,
                });
            }
            if channels > 1 {
                egui::ComboBox::from_id_salt("curve channel")
                    .selected_text(channel_name(channels, self.timeline.curve_channel))
                    .show_ui(ui, |ui| {
                        for c in 0..channels {
                            ui.selectable_value(
                                &mut self.timeline.curve_channel,
                                c,
                                channel_name(channels, c),
                            );
                        }
                    });
            }
        });
        self.curve_graph(ui, &key, segment);
    }

    fn curve_graph(&mut self, ui: &mut egui::Ui, key: &KeyRef, mut segment: Segment) {
        let c = self.timeline.curve_channel;
        // A handle being dragged shows where it is, not where the document has it.
        if let Some(SheetGesture::CurveHandle {
            key: k, numbers, ..
        }) = &self.timeline.gesture
        {
            if k == key {
                segment.curve = Curve::Bezier(numbers.clone());
            }
        }
        let (response, painter) = ui.allocate_painter(
            egui::vec2(CURVE_GRAPH_PT[0], CURVE_GRAPH_PT[1]),
            Sense::drag(),
        );
        let rect = response.rect.shrink(10.0);
        let (t0, t1) = (segment.start_s, segment.end_s);
        let samples: Vec<(f64, f64)> = (0..=64)
            .map(|i| {
                let t = t0 + (t1 - t0) * i as f64 / 64.0;
                (t, segment.value_at(c, t))
            })
            .collect();
        let handles: Option<[(f64, f64); 2]> = match &segment.curve {
            Curve::Bezier(n) if n.len() >= 4 * (c + 1) => {
                Some([(n[4 * c], n[4 * c + 1]), (n[4 * c + 2], n[4 * c + 3])])
            }
            _ => None,
        };
        let values = samples
            .iter()
            .map(|s| s.1)
            .chain(handles.iter().flatten().map(|h| h.1));
        let (mut low, mut high) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(v), h.max(v))
        });
        if high - low < 1e-9 {
            (low, high) = (low - 1.0, high + 1.0);
        }
        let pad = 0.08 * (high - low);
        let layout = CurveLayout {
            rect,
            start_s: t0,
            end_s: t1,
            low: low - pad,
            high: high + pad,
            handles: None,
        };
        painter.rect_filled(response.rect, 2.0, Color32::from_gray(30));
        let curve: Vec<Pos2> = samples.iter().map(|&(t, v)| layout.screen(t, v)).collect();
        painter.add(Shape::line(
            curve,
            Stroke::new(2.0, Color32::from_rgb(230, 190, 60)),
        ));
        let ends = [
            layout.screen(t0, segment.start.get(c).copied().unwrap_or(0.0)),
            layout.screen(t1, segment.end.get(c).copied().unwrap_or(0.0)),
        ];
        for end in ends {
            painter.add(diamond(
                end,
                5.0,
                Color32::from_rgb(255, 140, 40),
                Stroke::NONE,
            ));
        }
        // The value range shown, at the graph's top and bottom.
        let font = egui::FontId::proportional(10.0);
        for (value, y, align) in [
            (
                layout.high,
                response.rect.top() + 2.0,
                egui::Align2::LEFT_TOP,
            ),
            (
                layout.low,
                response.rect.bottom() - 2.0,
                egui::Align2::LEFT_BOTTOM,
            ),
        ] {
            painter.text(
                egui::pos2(response.rect.left() + 3.0, y),
                align,
                format!("{value:.2}"),
                font.clone(),
                Color32::from_gray(150),
            );
        }
        let handle_pos = handles.map(|h| h.map(|(t, v)| layout.screen(t, v)));
        if let Some(h) = handle_pos {
            for (end, handle) in ends.iter().zip(h) {
                painter.line_segment([*end, handle], Stroke::new(1.0, Color32::from_gray(170)));
                painter.circle_filled(handle, 4.5, Color32::from_rgb(120, 180, 255));
            }
        }
        let layout = CurveLayout {
            handles: handle_pos,
            ..layout
        };
        self.curve_input(ui, &response, &layout, key, &segment);
        self.timeline.curve = Some(layout);
    }

    fn curve_input(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        layout: &CurveLayout,
        key: &KeyRef,
        segment: &Segment,
    ) {
        let c = self.timeline.curve_channel;
        let pointer = response.interact_pointer_pos();
        if response.drag_started_by(egui::PointerButton::Primary) {
            let origin = ui.input(|i| i.pointer.press_origin()).or(pointer);
            if let (Some(at), Some(handles), Curve::Bezier(numbers)) =
                (origin, layout.handles, &segment.curve)
            {
                let grabbed = (0..2)
                    .filter(|&h| handles[h].distance(at) <= HANDLE_PICK_PT)
                    .min_by(|&a, &b| handles[a].distance(at).total_cmp(&handles[b].distance(at)));
                if let Some(h) = grabbed {
                    self.timeline.gesture = Some(SheetGesture::CurveHandle {
                        key: key.clone(),
                        at: 4 * c + 2 * h,
                        numbers: numbers.clone(),
                    });
                }
            }
        }
        if let (Some(p), true) = (pointer, response.dragged()) {
            if let Some(SheetGesture::CurveHandle { at, numbers, .. }) = &mut self.timeline.gesture
            {
                let (t, v) = layout.graph(p);
                if let Some(pair) = numbers.get_mut(*at..*at + 2) {
                    // Handle times stay in the segment: time must keep running forward.
                    pair[0] = t.clamp(layout.start_s, layout.end_s);
                    pair[1] = v;
                }
            }
        }
        if response.drag_stopped() {
            if let Some(SheetGesture::CurveHandle { key, numbers, .. }) =
                self.timeline.gesture.take()
            {
                self.apply(Command::SetCurve {
                    animation: self.animate.animation.clone(),
                    key,
                    curve: Curve::Bezier(numbers),
                });
            }
        }
    }
}
