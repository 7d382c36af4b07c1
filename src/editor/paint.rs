//! Rig mode's Paint tool, handle locks and the per-vertex weights readout.
//!
//! In: the pointer over the canvas, the selected handle, the brush settings of the side panel.
//! Out: one [`Command::PaintWeights`] per stroke (press to release), [`Command::SetLocked`]
//! from the lock boxes of the handle list, and what the canvas and panel show meanwhile.
//!
//! A stroke is previewed on a copy of the painted part's weights, dab by dab with the
//! library's [`crate::weights::paint_dab`] as the pointer moves, and committed once at release
//! with all its samples: the document paints the same dabs ([`crate::weights::dab_centres`] is
//! prefix-stable), so the preview is what the command produces, and the stroke is one undo step.

use super::canvas::{self, Placed};
use super::number_field::number_field;
use super::{EditorApp, Gesture};
use crate::document::{part_weights_for_painting, Command};
use crate::geom::Point;
use crate::pipeline::Scene;
use crate::weights::{dab_centres, BrushMode, BrushOptions, PaintMesh};
use eframe::egui::{self, Color32, Shape, Stroke as Pen};

/// The brush settings and what the pointer is over.
#[derive(Clone, Debug, Default)]
pub struct PaintSettings {
    pub mode: BrushMode,
    pub options: BrushOptions,
    /// The canvas point under the pointer last frame, px; `None` off the canvas.
    pub hover_px: Option<Point>,
    /// The last canvas point the pointer was over, px: the side panel reads out the weights of
    /// the vertex there (it stays while the pointer goes to the panel).
    pub readout_px: Option<Point>,
}

/// A stroke under way: its samples and the painted part's weights with the dabs so far.
pub struct PaintStroke {
    pub part: String,
    part_index: usize,
    pub handle: String,
    column: usize,
    locked: Vec<bool>,
    /// The document's influence limit, as the committed stroke will apply it.
    max_influences: Option<usize>,
    mesh: PaintMesh,
    pub samples_px: Vec<Point>,
    dabs_done: usize,
    /// The part's weight rows as the stroke leaves them so far.
    pub rows: Vec<Vec<(u32, f64)>>,
}

/// The part and vertex under `at_px` at rest: the frontmost part `drawn` accepts (by name)
/// with a triangle containing it, and that triangle's corner nearest to it.
pub fn vertex_under(
    scene: &Scene,
    p: Point,
    drawn: impl Fn(&str) -> bool,
) -> Option<(usize, usize)> {
    use crate::geom::barycentric;
    for (k, part) in scene.doc.parts.iter().enumerate().rev() {
        if !drawn(&part.name) {
            continue;
        }
        let v = &part.mesh.vertices;
        let pt = |i: u32| Point::new(v[i as usize][0], v[i as usize][1]);
        for t in &part.mesh.triangles {
            let Some(w) = barycentric(p, pt(t[0]), pt(t[1]), pt(t[2])) else {
                continue;
            };
            if w.iter().all(|&x| x >= 0.0) {
                let corner = (0..3).max_by(|&a, &b| w[a].total_cmp(&w[b])).unwrap_or(0);
                return Some((k, t[corner] as usize));
            }
        }
    }
    None
}

impl EditorApp {
    /// Starts a stroke at `at_px` on the frontmost part there, with the selected handle.
    fn start_stroke(&mut self, at_px: Point) -> Option<PaintStroke> {
        let Some(handle) = self.selected.clone() else {
            self.message = Some("select the handle to paint first".into());
            return None;
        };
        let Some(scene) = self.doc.posable().cloned() else {
            self.message = Some(crate::document::DocumentError::NoWeights.to_string());
            return None;
        };
        let Some((part_index, _)) = vertex_under(&scene, at_px, |name| self.rig_shows_part(name))
        else {
            self.message = Some("paint on the drawing: no part is there".into());
            return None;
        };
        let part = scene.doc.parts[part_index].name.clone();
        let (_, _, locked) = match part_weights_for_painting(self.doc.state(), &part) {
            Ok(found) => found,
            Err(e) => {
                self.fail(e.to_string());
                return None;
            }
        };
        let part_doc = &scene.doc.parts[part_index];
        let weights = part_doc.weights.as_ref()?;
        let Some(column) = weights.handles.iter().position(|h| *h == handle) else {
            self.message = Some(format!(
                "'{handle}' has no weights (a cage paints per vertex)"
            ));
            return None;
        };
        if locked[column] {
            self.message = Some(crate::document::DocumentError::LockedHandle(handle).to_string());
            return None;
        }
        let mesh = match PaintMesh::new(&part_doc.mesh.vertices, &part_doc.mesh.triangles) {
            Ok(mesh) => mesh,
            Err(e) => {
                self.fail(e.to_string());
                return None;
            }
        };
        let mut stroke = PaintStroke {
            part,
            part_index,
            handle,
            column,
            locked,
            max_influences: scene.doc.options.weights.max_influences,
            mesh,
            samples_px: Vec::new(),
            dabs_done: 0,
            rows: weights.rows.clone(),
        };
        self.extend_stroke(&mut stroke, at_px);
        Some(stroke)
    }

    /// Adds a sample to the stroke and paints the dabs it completes on the preview.
    fn extend_stroke(&mut self, stroke: &mut PaintStroke, at_px: Point) {
        stroke.samples_px.push(at_px);
        let dabs = match dab_centres(&stroke.samples_px, &self.paint.options) {
            Ok(dabs) => dabs,
            Err(e) => {
                self.fail(e.to_string());
                return;
            }
        };
        for &centre in &dabs[stroke.dabs_done.min(dabs.len())..] {
            if let Err(e) = crate::weights::paint_dab(
                &stroke.mesh,
                &mut stroke.rows,
                &crate::weights::PaintTarget {
                    column: stroke.column,
                    locked: &stroke.locked,
                    max_influences: stroke.max_influences,
                },
                self.paint.mode,
                centre,
                &self.paint.options,
            ) {
                self.fail(e.to_string());
                return;
            }
        }
        stroke.dabs_done = dabs.len();
    }

    /// Commits a finished stroke as one command.
    fn finish_stroke(&mut self, stroke: PaintStroke) {
        if self.apply(Command::PaintWeights {
            part: stroke.part,
            handle: stroke.handle,
            mode: self.paint.mode,
            samples_px: stroke.samples_px,
            options: self.paint.options,
        }) {
            self.message = None;
        }
    }

    /// The Paint tool's pointer handling: press starts a stroke, dragging extends it, release
    /// commits it; a click paints one dab.
    pub(super) fn paint_gestures(
        &mut self,
        ctx: &egui::Context,
        response: &egui::Response,
        placed: Placed,
    ) {
        let pointer = response.interact_pointer_pos();
        if response.drag_started_by(egui::PointerButton::Primary) {
            // Where the button went down, not where the drag was recognized.
            if let Some(at) = ctx.input(|i| i.pointer.press_origin()).or(pointer) {
                let c = placed.canvas_from_screen(at);
                self.gesture = self.start_stroke(c).map(Gesture::Paint);
            }
        }
        if let (Some(at), true) = (pointer, response.dragged()) {
            // Taken out while it grows: extending reports errors on `self`.
            match self.gesture.take() {
                Some(Gesture::Paint(mut stroke)) => {
                    let c = placed.canvas_from_screen(at);
                    if stroke.samples_px.last() != Some(&c) {
                        self.extend_stroke(&mut stroke, c);
                    }
                    self.gesture = Some(Gesture::Paint(stroke));
                }
                other => self.gesture = other,
            }
        }
        if response.drag_stopped() {
            if let Some(Gesture::Paint(stroke)) = self.gesture.take() {
                self.finish_stroke(stroke);
            }
        }
        if let (true, Some(at)) = (response.clicked(), pointer) {
            if let Some(stroke) = self.start_stroke(placed.canvas_from_screen(at)) {
                self.finish_stroke(stroke);
            }
        }
    }

    /// The weights the canvas shows for part `index`: the stroke's preview while painting it.
    pub(super) fn shown_rows(&self, index: usize) -> Option<&[Vec<(u32, f64)>]> {
        match &self.gesture {
            Some(Gesture::Paint(stroke)) if stroke.part_index == index => {
                Some(stroke.rows.as_slice())
            }
            _ => None,
        }
    }

    /// The brush circle at the pointer (Paint tool only).
    pub(super) fn brush_shape(&self, placed: &Placed) -> Option<Shape> {
        let at = self.paint.hover_px?;
        Some(Shape::circle_stroke(
            placed.screen_from_canvas(at),
            (self.paint.options.radius_px as f32 * placed.view.zoom).max(1.0),
            Pen::new(1.5, Color32::from_rgb(255, 255, 255)),
        ))
    }

    /// Brush mode, radius and strength.
    pub(super) fn paint_panel(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.selectable_value(&mut self.paint.mode, BrushMode::Add, "Add");
            ui.selectable_value(&mut self.paint.mode, BrushMode::Subtract, "Subtract");
            ui.selectable_value(&mut self.paint.mode, BrushMode::Smooth, "Smooth");
        });
        // Labelled number fields (typed or dragged), as the numbers panel's.
        let options = &mut self.paint.options;
        for (text, value, range, speed) in [
            ("Brush radius px:", &mut options.radius_px, 2.0..=200.0, 0.5),
            ("Brush strength:", &mut options.strength, 0.01..=1.0, 0.01),
        ] {
            ui.horizontal(|ui| {
                let label = ui.label(text);
                ui.add(number_field(value).range(range).speed(speed))
                    .labelled_by(label.id);
            });
        }
        match &self.selected {
            Some(name) => ui.label(format!("Painting {name}'s weights")),
            None => ui.label("Select a handle to paint its weights"),
        };
    }

    /// The lock box in front of a handle's row in the handle list.
    pub(super) fn lock_box(&mut self, ui: &mut egui::Ui, name: &str) {
        let mut locked = self.doc.state().locked.contains(name);
        let response = ui
            .checkbox(&mut locked, "")
            .on_hover_text("Lock: painting and recomputing keep this handle's weights");
        // The box has no text; name it for screen readers (and UI tests).
        let label = format!("lock {name}");
        response.widget_info(|| {
            egui::WidgetInfo::selected(egui::WidgetType::Checkbox, true, locked, &label)
        });
        if response.changed() {
            self.apply(Command::SetLocked {
                handle: name.to_string(),
                locked,
            });
        }
    }

    /// The weights of the vertex last under the pointer (rig mode, current weights).
    pub(super) fn vertex_weights_panel(&mut self, ui: &mut egui::Ui) {
        let (Some(scene), Some(at)) = (self.doc.posable().cloned(), self.paint.readout_px) else {
            return;
        };
        let Some((part_index, vertex)) = vertex_under(&scene, at, |name| self.rig_shows_part(name))
        else {
            return;
        };
        let part = &scene.doc.parts[part_index];
        let Some(weights) = &part.weights else {
            return;
        };
        let row = self
            .shown_rows(part_index)
            .and_then(|rows| rows.get(vertex))
            .or_else(|| weights.rows.get(vertex));
        let Some(row) = row else { return };
        ui.label(format!("{} vertex {vertex}", part.name));
        let state = self.doc.state();
        let locked =
            crate::pipeline::locked_columns(&state.handles, &state.locked, &weights.handles);
        egui::Grid::new("vertex weights").show(ui, |ui| {
            for &(c, w) in row {
                let name = weights.handles.get(c as usize).map_or("?", String::as_str);
                let mark = if locked.get(c as usize).copied().unwrap_or(false) {
                    " (locked)"
                } else {
                    ""
                };
                ui.label(format!("{name}{mark}"));
                ui.label(format!("{w:.4}"));
                ui.end_row();
            }
        });
    }

    /// Remembers the canvas point under the pointer.
    pub(super) fn track_hover(&mut self, response: &egui::Response, placed: &Placed) {
        self.paint.hover_px = response
            .hover_pos()
            .or(response.interact_pointer_pos())
            .map(|p| placed.canvas_from_screen(p));
        if self.paint.hover_px.is_some() {
            self.paint.readout_px = self.paint.hover_px;
        }
    }
}

/// The heat map of `handle` drawn from `rows` (a stroke's preview) instead of `weights.rows`.
pub fn heat_map_rows(
    placed: &Placed,
    weights: &crate::io::WeightsDoc,
    rows: &[Vec<(u32, f64)>],
    handle: &str,
    positions: &[crate::geom::Point],
    triangles: &[[u32; 3]],
) -> Option<Shape> {
    let preview = crate::io::WeightsDoc {
        handles: weights.handles.clone(),
        rows: rows.to_vec(),
    };
    canvas::heat_map(placed, &preview, handle, positions, triangles)
}
