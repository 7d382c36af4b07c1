//! Animate mode's deform tool: drag mesh vertices with a soft radius; the offsets are keyed at
//! the playhead as the part's deform key.
//!
//! In: a press on the canvas (the part drawn with a vertex nearest it, within the radius, is the
//! one deformed: the attachment its slot shows), the drag, the radius (canvas px). Out: one
//! `KeyDeform` command on release (undoable): each vertex within the radius of the press, at
//! distance d, follows the pointer's motion by the falloff `(1 − (d/r)²)²` (1 at the press, 0
//! at the radius, smooth at both ends). Deform offsets live in the rest frame, before
//! skinning: the motion on screen is taken back through the skinning's local map at each
//! vertex, measured by posing the offsets through the scene itself (one path; skinning is
//! linear in an offset under LBS, so the map is exact there). While dragging, the canvas shows
//! the circle of the radius and the motion.

use super::{canvas, EditorApp, Gesture};
use crate::document::Command;
use crate::geom::{Point, Vec2};
use crate::pipeline::Scene;
use eframe::egui::{self, Color32, Pos2, Stroke};
use nalgebra::Matrix2;
use std::sync::Arc;

/// Default radius of the deform tool, canvas px.
pub const DEFAULT_RADIUS_PX: f64 = 30.0;

/// The deform tool's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct DeformTool {
    /// Whether a drag on the canvas deforms (instead of posing). Default off.
    pub enabled: bool,
    /// Vertices within this distance of the press move (canvas px). Default
    /// [`DEFAULT_RADIUS_PX`].
    pub radius_px: f64,
}

impl Default for DeformTool {
    fn default() -> Self {
        DeformTool {
            enabled: false,
            radius_px: DEFAULT_RADIUS_PX,
        }
    }
}

/// A deform drag in progress: the part, the press and the pointer (canvas px).
pub(super) struct DeformDrag {
    part: usize,
    from: Point,
    to: Point,
}

/// How much a vertex at `distance_px` from the press follows the pointer: `(1 − (d/r)²)²`
/// inside the radius, 0 outside.
pub fn falloff(distance_px: f64, radius_px: f64) -> f64 {
    if radius_px <= 0.0 || distance_px >= radius_px {
        return 0.0;
    }
    let f = 1.0 - (distance_px / radius_px).powi(2);
    f * f
}

impl EditorApp {
    /// The tool's switch and radius (animate mode's side panel).
    pub(super) fn deform_tool_row(&mut self, ui: &mut egui::Ui) {
        ui.checkbox(&mut self.deform.enabled, "Deform tool")
            .on_hover_text("drag mesh vertices; the offsets are keyed at the playhead");
        let label = ui.label("Deform radius");
        ui.add(
            egui::DragValue::new(&mut self.deform.radius_px)
                .range(1.0..=2000.0)
                .suffix(" px"),
        )
        .labelled_by(label.id);
    }

    /// The part drawn (visible, front first) with a posed vertex nearest `at_px`, within the
    /// radius.
    fn part_to_deform(&self, at: Point) -> Option<usize> {
        let posed = self.pose_mode.posed.as_ref()?;
        let picture = self.drawing.picture.as_ref()?;
        picture
            .draws
            .iter()
            .rev()
            .filter(|d| d.visible)
            .filter_map(|d| {
                let nearest = posed
                    .positions
                    .get(d.part)?
                    .iter()
                    .map(|p| (p - at).norm())
                    .fold(f64::INFINITY, f64::min);
                Some((d.part, nearest))
            })
            .filter(|(_, d)| *d < self.deform.radius_px)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(part, _)| part)
    }

    /// The deform tool's pointer gestures on the canvas (instead of posing while it is on).
    pub(super) fn deform_gestures(
        &mut self,
        ctx: &egui::Context,
        response: &egui::Response,
        placed: canvas::Placed,
        scene: &Arc<Scene>,
    ) {
        if response.drag_started_by(egui::PointerButton::Primary) {
            let origin = ctx.input(|i| i.pointer.press_origin());
            if let Some(from) = origin.map(|p| placed.canvas_from_screen(p)) {
                match self.part_to_deform(from) {
                    Some(part) => {
                        self.gesture = Some(Gesture::Deform(DeformDrag {
                            part,
                            from,
                            to: from,
                        }))
                    }
                    None => self.fail("no mesh vertex of a shown part within the deform radius"),
                }
            }
        }
        if let (Some(Gesture::Deform(drag)), Some(at)) =
            (&mut self.gesture, response.interact_pointer_pos())
        {
            drag.to = placed.canvas_from_screen(at);
        }
        if response.drag_stopped() {
            if let Some(Gesture::Deform(drag)) = self.gesture.take() {
                if let Err(e) = self.key_deform(scene, &drag) {
                    self.fail(e);
                }
            }
        }
    }

    /// Keys the drag's offsets at the playhead.
    fn key_deform(&mut self, scene: &Arc<Scene>, drag: &DeformDrag) -> Result<(), String> {
        let delta = drag.to - drag.from;
        if delta.norm() < super::CLICK_SLOP_PX {
            return Ok(());
        }
        let posed = self
            .pose_mode
            .posed
            .as_ref()
            .filter(|p| p.scene.is(scene))
            .ok_or("the pose is not drawn yet")?;
        let part = &scene.doc.parts[drag.part];
        let n = part.mesh.vertices.len();
        let base = posed.pose.deform.get(&part.name).cloned();
        let base = base.unwrap_or_else(|| vec![Vec2::zeros(); n]);
        // Each vertex's posed position as a function of its offset, measured through the one
        // pose path: with every offset moved by a unit along x, then y.
        let blend = self.render_settings.blend;
        let posed_with = |shift: Vec2| -> Result<Vec<Point>, String> {
            let mut pose = posed.pose.clone();
            let offsets = base.iter().map(|o| o + shift).collect();
            pose.deform.insert(part.name.clone(), offsets);
            let mut all = scene
                .positions_from_transforms(&posed.transforms, &pose, blend)
                .map_err(|e| e.to_string())?;
            Ok(std::mem::take(&mut all[drag.part]))
        };
        let (at, along_x, along_y) = (
            posed_with(Vec2::zeros())?,
            posed_with(Vec2::x())?,
            posed_with(Vec2::y())?,
        );
        let from = drag.from;
        let mut offsets = base.clone();
        for (v, offset) in offsets.iter_mut().enumerate() {
            let w = falloff((at[v] - from).norm(), self.deform.radius_px);
            if w == 0.0 {
                continue;
            }
            // Solve J · d = w · delta for the offset's change d, J = [jx jy] the skinning's
            // local map (a vertex it collapses keeps its offset).
            let jacobian = Matrix2::from_columns(&[along_x[v] - at[v], along_y[v] - at[v]]);
            if jacobian.determinant().abs() < 1e-9 {
                continue;
            }
            if let Some(inverse) = jacobian.try_inverse() {
                *offset += inverse * (w * delta);
            }
        }
        let (name, time_s) = (part.name.clone(), self.animate.time_s);
        if self.apply(Command::KeyDeform {
            animation: self.animate.animation.clone(),
            part: name.clone(),
            time_s,
            offsets: offsets.clone(),
        }) {
            if let Some(shown) = &mut self.animate.shown {
                shown.deform.insert(name.clone(), offsets);
            }
            self.message = Some(format!("keyed the deform of '{name}' at {time_s:.3} s"));
        }
        Ok(())
    }

    /// The tool's circle at the pointer (or the press) and the drag's motion.
    pub(super) fn deform_shapes(
        &self,
        placed: &canvas::Placed,
        hover: Option<Pos2>,
    ) -> Vec<egui::Shape> {
        if !self.deform.enabled || self.mode != super::Mode::Animate {
            return Vec::new();
        }
        let radius_pt = (self.deform.radius_px * f64::from(placed.view.zoom)) as f32;
        let stroke = Stroke::new(1.5, Color32::from_rgb(120, 200, 255));
        match &self.gesture {
            Some(Gesture::Deform(drag)) => {
                let (from, to) = (
                    placed.screen_from_canvas(drag.from),
                    placed.screen_from_canvas(drag.to),
                );
                vec![
                    egui::Shape::circle_stroke(from, radius_pt, stroke),
                    egui::Shape::line_segment([from, to], stroke),
                    egui::Shape::circle_filled(to, 3.0, stroke.color),
                ]
            }
            _ => hover
                .map(|at| egui::Shape::circle_stroke(at, radius_pt, stroke))
                .into_iter()
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::falloff;

    #[test]
    fn the_falloff_is_one_at_the_press_and_fades_to_zero_at_the_radius() {
        assert_eq!(falloff(0.0, 10.0), 1.0);
        assert_eq!(falloff(5.0, 10.0), 0.5625);
        assert_eq!(falloff(10.0, 10.0), 0.0);
        assert_eq!(falloff(12.0, 10.0), 0.0);
        assert_eq!(falloff(1.0, 0.0), 0.0);
    }
}
