//! Rig mode: layers and handles. Draw bones, points, cages and regions, select, move, rename,
//! reparent and delete handles, compute the weights (with progress and cancel) and see a
//! handle's weights as a heat map. The polygon tools, the mesh preview and the automatic rig are
//! [`super::rig_tools`]'s; the Paint tool, the locks and the weights readout [`super::paint`]'s.
//!
//! In: pointer and keys on the canvas at rest. Out: document commands (`AddBone`, `MoveBone`,
//! `AddPoint`, `Rename`, `Reparent`, `SetBind` (the parts a handle weighs), `Delete`,
//! `SetOptions`, `SetRig` once a build is done).

use super::canvas::{self, Placed};
use super::worker::Worker;
use super::{rig_tools, EditorApp, Gesture, CLICK_SLOP_PX};
use crate::document::{Command, DocumentError};
use crate::geom::Point;
use crate::rig::{Bone, PointHandle};
use eframe::egui::{self, Shape, TextureHandle};
use std::path::Path;
use std::sync::Arc;

/// What a press on the canvas does in rig mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tool {
    /// Pick a handle; drag it to move it.
    Select,
    /// Press at the head, release at the tail. Starting on a bone's tail makes it the parent.
    Bone,
    /// Click to place a point handle: carried by the selected bone (or by the selected point's
    /// bone), loose when none is selected.
    Point,
    /// Click vertices of a cage; click the first one again (or press Enter) to close it.
    Cage,
    /// Click vertices of a region (its inside moves rigidly); close as a cage.
    Region,
    /// Paint the selected handle's weights (see [`super::paint`]).
    Paint,
}

/// Rig mode's own state: the tool, the rename field, the weight build running.
pub struct RigMode {
    pub tool: Tool,
    /// The side panel's name field for the selected handle.
    pub(super) rename_to: String,
    /// The weight build running on another thread.
    pub(super) worker: Option<Worker>,
}

impl Default for RigMode {
    fn default() -> Self {
        RigMode {
            tool: Tool::Select,
            rename_to: String::new(),
            worker: None,
        }
    }
}

impl EditorApp {
    /// The layers at rest and, with a handle selected, the parts' meshes and its weights as a
    /// heat map (`weighted`: the weights are current).
    pub(super) fn rest_shapes(
        &self,
        placed: &Placed,
        textures: &[TextureHandle],
        weighted: bool,
    ) -> Vec<Shape> {
        let mut shapes = Vec::new();
        let hidden = &self.tree.hidden_parts;
        for (texture, layer) in textures.iter().zip(&self.doc.state().layers) {
            if !hidden.contains(&layer.name) && self.rig_shows_part(&layer.name) {
                let size_px = [layer.image.width(), layer.image.height()];
                shapes.push(canvas::image_quad(
                    placed,
                    texture,
                    layer.offset_px,
                    size_px,
                ));
            }
        }
        let (Some(scene), Some(name)) = (&self.doc.state().rig, &self.selected) else {
            return shapes;
        };
        for (k, part) in scene.doc.parts.iter().enumerate() {
            if !self.rig_shows_part(&part.name) {
                continue;
            }
            let rest = &part.mesh.vertices;
            let Some(weights) = part.weights.as_ref().filter(|_| weighted) else {
                shapes.extend(canvas::wireframe(placed, rest, &part.mesh.triangles));
                continue;
            };
            // The heat map alone: a white wireframe under translucent colour showed as bright
            // starbursts where the outline's small triangles fan out.
            shapes.extend(match self.shown_rows(k) {
                Some(rows) => super::paint::heat_map_rows(
                    placed,
                    weights,
                    rows,
                    name,
                    rest,
                    &part.mesh.triangles,
                ),
                None => canvas::heat_map(placed, weights, name, rest, &part.mesh.triangles),
            });
        }
        shapes
    }

    /// The heat map's legend in the canvas' lower left corner (`canvas`, screen points): whose
    /// weights are shown and the colours of 0, ½ and 1. Shown while the selected handle's current
    /// weights are drawn.
    fn heat_legend(&self, ctx: &egui::Context, canvas: egui::Rect) {
        let (Some(scene), Some(name)) = (self.doc.posable(), &self.selected) else {
            return;
        };
        let weighs = scene.doc.parts.iter().any(|p| {
            p.weights
                .as_ref()
                .is_some_and(|w| w.handles.iter().any(|h| h == name))
        });
        if !weighs {
            return;
        }
        egui::Area::new(egui::Id::new("heat map legend"))
            .fixed_pos(canvas.left_bottom() + egui::vec2(8.0, -LEGEND_HEIGHT_PT))
            .interactable(false)
            .show(ctx, |ui| {
                egui::Frame::popup(ui.style()).show(ui, |ui| {
                    ui.label(format!("weights of {name}"));
                    ui.horizontal(|ui| {
                        ui.label("0");
                        let (rect, _) = ui.allocate_exact_size(
                            egui::vec2(LEGEND_BAR_PT, 10.0),
                            egui::Sense::hover(),
                        );
                        let mut bar = egui::Mesh::default();
                        let steps = 16;
                        for k in 0..=steps {
                            let w = k as f64 / steps as f64;
                            let x = rect.left() + rect.width() * w as f32;
                            // Opaque: the legend shows the hue, the canvas shows the drawing.
                            let [r, g, b, _] = canvas::heat_color(w).to_srgba_unmultiplied();
                            let color = egui::Color32::from_rgb(r, g, b);
                            bar.colored_vertex(egui::pos2(x, rect.top()), color);
                            bar.colored_vertex(egui::pos2(x, rect.bottom()), color);
                            if k > 0 {
                                let i = 2 * k as u32;
                                bar.add_triangle(i - 2, i - 1, i);
                                bar.add_triangle(i - 1, i + 1, i);
                            }
                        }
                        ui.painter().add(Shape::mesh(bar));
                        ui.label("1");
                    });
                });
            });
    }

    /// Starts computing the weights for the current handles (a no-op while one runs).
    pub fn compute_weights(&mut self, ctx: &egui::Context) {
        if self.rig_mode.worker.is_some() {
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
        self.rig_mode.worker = Some(Worker::start(self.doc.rig_inputs(), dir, move || {
            ctx.request_repaint()
        }));
    }

    pub(super) fn poll_worker(&mut self) {
        let Some(worker) = &self.rig_mode.worker else {
            return;
        };
        if let Some(result) = worker.poll() {
            let key = worker.key.clone();
            self.rig_mode.worker = None;
            match result {
                Ok(scene) => {
                    if self.apply(Command::SetRig(Arc::new(scene), Box::new(key))) {
                        self.message = Some("weights computed".into());
                    }
                }
                Err(DocumentError::Cancelled) => self.message = Some("cancelled".into()),
                Err(e) => self.fail(e.to_string()),
            }
        }
    }

    pub(super) fn rig_panel(&mut self, ui: &mut egui::Ui) {
        ui.heading("Tools");
        ui.horizontal(|ui| {
            ui.selectable_value(&mut self.rig_mode.tool, Tool::Select, "Select");
            ui.selectable_value(&mut self.rig_mode.tool, Tool::Bone, "Bone");
            ui.selectable_value(&mut self.rig_mode.tool, Tool::Point, "Point");
            ui.selectable_value(&mut self.rig_mode.tool, Tool::Cage, "Cage");
            ui.selectable_value(&mut self.rig_mode.tool, Tool::Region, "Region");
            ui.selectable_value(&mut self.rig_mode.tool, Tool::Paint, "Paint");
        });
        if self.rig_mode.tool == Tool::Paint {
            self.paint_panel(ui);
        }
        ui.separator();
        ui.heading("Tree");
        self.tree_area(ui);
        if let Some(name) = self.selected.clone() {
            ui.separator();
            ui.label(format!("Selected: {name}"));
            ui.horizontal(|ui| {
                ui.text_edit_singleline(&mut self.rig_mode.rename_to);
                if ui.button("Rename").clicked() && self.rig_mode.rename_to != name {
                    let to = self.rig_mode.rename_to.clone();
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
            // A bone's parent, or the bone that carries a point.
            let now = self.doc.state().handles.parent_of(&name);
            if let Some(before) = now.map(|p| p.map(str::to_string)) {
                let mut parent = before.clone();
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
                        handle: name.clone(),
                        parent,
                    });
                }
            }
            self.bind_boxes(ui, &name);
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
        match &self.rig_mode.worker {
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

    pub(super) fn rig_gestures(
        &mut self,
        ctx: &egui::Context,
        response: &egui::Response,
        placed: Placed,
    ) {
        self.heat_legend(ctx, response.rect);
        if self.rig_mode.tool == Tool::Paint {
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
                self.gesture = match self.rig_mode.tool {
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
                            self.rig_mode.rename_to = name.clone();
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
                    move_handle(&mut handles, &name, to - from);
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
                match self.rig_mode.tool {
                    Tool::Cage => self.polygon_click(rig_tools::PolygonKind::Cage, c, &placed),
                    Tool::Region => self.polygon_click(rig_tools::PolygonKind::Region, c, &placed),
                    Tool::Point => {
                        let name = self.unique_name("point");
                        let parent = self.new_point_parent();
                        if self.apply(Command::AddPoint(PointHandle {
                            name: name.clone(),
                            at: c,
                            parent,
                        })) {
                            self.selected = Some(name);
                        }
                    }
                    _ => {
                        self.selected = canvas::pick(&placed, &self.doc.state().handles, at);
                        if let Some(name) = &self.selected {
                            self.rig_mode.rename_to = name.clone();
                        }
                    }
                }
            }
        }
    }

    /// The parts handle `name` may weigh (the handles' `bind`): a box per part, front to back
    /// as the tree lists them. None ticked, the handle weighs every part it touches; ticking
    /// one binds it to the ticked parts only. Each tick is one undoable `SetBind`, and the
    /// weights need computing again.
    fn bind_boxes(&mut self, ui: &mut egui::Ui, name: &str) {
        let state = self.doc.state();
        if state.layers.is_empty() {
            return;
        }
        let bound = state.handles.bind.get(name).cloned();
        let parts: Vec<String> = state.layers.iter().rev().map(|l| l.name.clone()).collect();
        // Folded, one line: what the handle weighs; unfolded (kept so from one selection to
        // the next), the boxes.
        let header = match &bound {
            None => "Weighs: all parts".to_string(),
            Some(bound) => format!("Weighs only: {}", bound.join(", ")),
        };
        let mut toggled = None;
        egui::CollapsingHeader::new(header)
            .id_salt("weighs")
            .show(ui, |ui| {
                ui.label("None ticked: every part. Ticked: only those.");
                let ticked = bound.as_deref().unwrap_or(&[]);
                ui.horizontal_wrapped(|ui| toggled = part_boxes(ui, name, &parts, ticked));
            });
        let Some((part, on)) = toggled else {
            return;
        };
        let mut parts = bound.unwrap_or_default();
        parts.retain(|p| *p != part);
        if on {
            parts.push(part);
        }
        let message = match parts.as_slice() {
            [] => format!("'{name}' weighs every part again"),
            bound => format!("'{name}' weighs only {}", bound.join(", ")),
        };
        if self.apply(Command::SetBind {
            handle: name.to_string(),
            parts,
        }) {
            self.message = Some(message);
        }
    }

    /// The bone a new point is carried by: the selected bone, or the one carrying the
    /// selected point (so points placed one after another share it); none otherwise.
    fn new_point_parent(&self) -> Option<String> {
        let handles = &self.doc.state().handles;
        let selected = self.selected.as_deref()?;
        if handles.bones.iter().any(|b| b.name == selected) {
            return Some(selected.to_string());
        }
        let point = handles.points.iter().find(|p| p.name == selected)?;
        point.parent.clone()
    }

    pub(super) fn unique_name(&self, stem: &str) -> String {
        let handles = &self.doc.state().handles;
        (1..)
            .map(|k| format!("{stem}{k}"))
            .find(|n| !handles.names().any(|m| m == n))
            .unwrap_or_else(|| stem.to_string())
    }
}

/// A box per part in `parts` for handle `name`, ticked when `ticked` lists it. Returns the
/// part toggled this frame, if any, and whether it is ticked now.
fn part_boxes(
    ui: &mut egui::Ui,
    name: &str,
    parts: &[String],
    ticked: &[String],
) -> Option<(String, bool)> {
    let mut toggled = None;
    for part in parts {
        let mut on = ticked.contains(part);
        let response = ui
            .checkbox(&mut on, part.as_str())
            .on_hover_text(format!("whether '{name}' may weigh part '{part}'"));
        // Parts and bones often share names: the box is "weighs PART" to screen readers (and
        // UI tests).
        let label = format!("weighs {part}");
        response.widget_info(|| {
            egui::WidgetInfo::selected(egui::WidgetType::Checkbox, true, on, &label)
        });
        if response.changed() {
            toggled = Some((part.clone(), on));
        }
    }
    toggled
}

/// Height of the heat map legend above the canvas' bottom edge, screen points.
const LEGEND_HEIGHT_PT: f32 = 64.0;
/// Length of the legend's colour bar, screen points.
const LEGEND_BAR_PT: f32 = 120.0;

pub(super) fn distance(a: Point, b: impl Into<Point>) -> f64 {
    (a - b.into()).norm()
}

/// Moves handle `name` by `delta_px`.
pub(super) fn move_handle(
    handles: &mut crate::rig::Handles,
    name: &str,
    delta_px: crate::geom::Vec2,
) {
    let shift = |p: &mut Point| *p += delta_px;
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
