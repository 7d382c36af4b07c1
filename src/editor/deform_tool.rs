//! Animate mode's deform tool: drag mesh vertices with a soft radius; the offsets are keyed at
//! the playhead as the part's deform key.
//!
//! In: a press on the canvas (the part drawn with a vertex nearest it, within the radius, is the
//! one deformed: the attachment its slot shows), the drag, the radius (canvas px). Out: one
//! `KeyDeform` command on release (undoable): each vertex within the radius of the press, at
//! distance d, follows the pointer's motion by the falloff `(1 − (d/r)²)²` (1 at the press, 0
//! at the radius, smooth at both ends). Deform offsets live in the rest frame, before
//! skinning: the motion on screen is taken back through the skinning's local map at each
//! vertex, measured by posing the offsets through the scene itself (one path), with Newton
//! steps where the skinning is not affine in the offset ([`offsets_reaching`]). While dragging, the canvas shows
//! the circle of the radius and the motion.

use super::number_field::number_field;
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

/// Newton steps at most when taking the pointer's motion back to rest-frame offsets.
pub const MAX_DEFORM_STEPS: usize = 6;
/// The steps stop when every moved vertex is this close to where it should be, canvas px.
pub const DEFORM_TOLERANCE_PX: f64 = 1e-6;
/// The shift of every offset that measures the skinning's local map, canvas px.
pub const DEFORM_PROBE_PX: f64 = 1e-3;

/// The rest-frame offsets that pose each vertex `v` at `targets[v]` (canvas px; `None`: the
/// vertex keeps `base[v]`), given `posed_with` (offsets → posed positions: the scene's
/// skinning, where a vertex's position depends on its own offset only). Newton's method per
/// vertex: its 2×2 local map is measured by shifting every offset [`DEFORM_PROBE_PX`] along x
/// and along y. One step is exact where skinning is affine in the offset (LBS, and DQS, whose
/// blended motion depends on the weights only); stretchable bones clamp along the bone, and
/// the further steps (at most [`MAX_DEFORM_STEPS`], until [`DEFORM_TOLERANCE_PX`]) cross the
/// kink. The best iterate is kept; a vertex whose map collapses (|det| < 1e-9) keeps its offset.
pub fn offsets_reaching(
    base: &[Vec2],
    targets: &[Option<Point>],
    posed_with: impl Fn(&[Vec2]) -> Result<Vec<Point>, String>,
) -> Result<Vec<Vec2>, String> {
    let worst_px = |now: &[Point]| {
        let misses = targets
            .iter()
            .zip(now)
            .filter_map(|(t, p)| t.map(|t| (t - p).norm()));
        misses.fold(0.0, f64::max)
    };
    let mut offsets = base.to_vec();
    let mut now = posed_with(&offsets)?;
    let mut best = (worst_px(&now), offsets.clone());
    for _ in 0..MAX_DEFORM_STEPS {
        if best.0 <= DEFORM_TOLERANCE_PX {
            break;
        }
        let probe = |shift: Vec2| {
            let shifted: Vec<Vec2> = offsets.iter().map(|o| o + shift).collect();
            posed_with(&shifted)
        };
        let along_x = probe(Vec2::new(DEFORM_PROBE_PX, 0.0))?;
        let along_y = probe(Vec2::new(0.0, DEFORM_PROBE_PX))?;
        for (v, target) in targets.iter().enumerate() {
            let Some(target) = target else {
                continue;
            };
            let jacobian = Matrix2::from_columns(&[
                (along_x[v] - now[v]) / DEFORM_PROBE_PX,
                (along_y[v] - now[v]) / DEFORM_PROBE_PX,
            ]);
            if jacobian.determinant().abs() < 1e-9 {
                continue;
            }
            if let Some(inverse) = jacobian.try_inverse() {
                offsets[v] += inverse * (target - now[v]);
            }
        }
        now = posed_with(&offsets)?;
        let worst = worst_px(&now);
        if worst < best.0 {
            best = (worst, offsets.clone());
        }
    }
    Ok(best.1)
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
            number_field(&mut self.deform.radius_px)
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
        // Each vertex's posed position as a function of the offsets, through the one pose path.
        let blend = self.render_settings.blend;
        let posed_with = |offsets: &[Vec2]| -> Result<Vec<Point>, String> {
            let mut pose = posed.pose.clone();
            pose.deform.insert(part.name.clone(), offsets.to_vec());
            let mut all = scene
                .positions_from_transforms(&posed.transforms, &pose, blend)
                .map_err(|e| e.to_string())?;
            Ok(std::mem::take(&mut all[drag.part]))
        };
        let now = posed_with(&base)?;
        let targets: Vec<Option<Point>> = now
            .iter()
            .map(|&at| {
                let w = falloff((at - drag.from).norm(), self.deform.radius_px);
                (w > 0.0).then(|| at + w * delta)
            })
            .collect();
        let offsets = offsets_reaching(&base, &targets, posed_with)?;
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
    use super::*;
    use std::cell::Cell;

    /// A part skinned by a rotation and a bone stretched along x that clamps past its tail at
    /// x = 10 (as stretchable bones do): not affine in the offset.
    fn clamped_stretch(p: Point) -> Point {
        let (sin, cos) = 0.3f64.sin_cos();
        let rotated = Point::new(cos * p.x - sin * p.y, sin * p.x + cos * p.y);
        rotated + Vec2::new(6.0 * (p.x / 10.0).clamp(0.0, 1.0), 0.0)
    }

    #[test]
    fn newton_steps_put_vertices_on_their_targets_past_a_clamp() {
        let rest = [
            Point::new(9.5, 1.0),
            Point::new(3.0, -2.0),
            Point::new(20.0, 0.0),
        ];
        let base = vec![Vec2::new(0.2, 0.0), Vec2::zeros(), Vec2::zeros()];
        let posed_with = |offsets: &[Vec2]| -> Result<Vec<Point>, String> {
            Ok(rest
                .iter()
                .zip(offsets)
                .map(|(p, o)| clamped_stretch(p + o))
                .collect())
        };
        let now = posed_with(&base).expect("posed");
        // The first vertex crosses the clamp at x = 10; the second stays inside; the third
        // keeps its offset.
        let targets = [
            Some(now[0] + Vec2::new(3.0, 1.0)),
            Some(now[1] + Vec2::new(-1.0, 2.0)),
            None,
        ];
        let offsets = offsets_reaching(&base, &targets, posed_with).expect("offsets");
        let reached = posed_with(&offsets).expect("posed");
        for v in 0..2 {
            let target = targets[v].expect("a target");
            assert!(
                (reached[v] - target).norm() < DEFORM_TOLERANCE_PX,
                "{v}: {:?}",
                reached[v]
            );
        }
        assert_eq!(offsets[2], base[2]);
        // One step with the map measured by unit shifts (the old way) misses: the kink.
        let jacobian_step = {
            let shifted: Vec<Vec2> = base.iter().map(|o| o + Vec2::x()).collect();
            let x = posed_with(&shifted).expect("posed")[0] - now[0];
            let shifted: Vec<Vec2> = base.iter().map(|o| o + Vec2::y()).collect();
            let y = posed_with(&shifted).expect("posed")[0] - now[0];
            Matrix2::from_columns(&[x, y])
                .try_inverse()
                .expect("invertible")
                * Vec2::new(3.0, 1.0)
        };
        let one_step = clamped_stretch(rest[0] + base[0] + jacobian_step);
        assert!(
            (one_step - targets[0].expect("a target")).norm() > 0.1,
            "{one_step:?}"
        );
    }

    #[test]
    fn an_affine_skinning_takes_one_step() {
        let rest = [Point::new(1.0, 2.0), Point::new(-3.0, 4.0)];
        let calls = Cell::new(0);
        let posed_with = |offsets: &[Vec2]| -> Result<Vec<Point>, String> {
            calls.set(calls.get() + 1);
            let affine = |p: Point| Point::new(1.5 * p.x - 0.4 * p.y + 7.0, 0.2 * p.x + 0.8 * p.y);
            Ok(rest
                .iter()
                .zip(offsets)
                .map(|(p, o)| affine(p + o))
                .collect())
        };
        let base = vec![Vec2::zeros(); 2];
        let targets = [Some(Point::new(10.0, 3.0)), Some(Point::new(0.0, 0.0))];
        let offsets = offsets_reaching(&base, &targets, posed_with).expect("offsets");
        let reached = posed_with(&offsets).expect("posed");
        assert!((reached[0] - targets[0].expect("a target")).norm() < 1e-9);
        assert!((reached[1] - targets[1].expect("a target")).norm() < 1e-9);
        // One pose to start, two to measure the map, one after the step; one to check above.
        assert_eq!(calls.get(), 5);
    }

    #[test]
    fn the_falloff_is_one_at_the_press_and_fades_to_zero_at_the_radius() {
        assert_eq!(falloff(0.0, 10.0), 1.0);
        assert_eq!(falloff(5.0, 10.0), 0.5625);
        assert_eq!(falloff(10.0, 10.0), 0.0);
        assert_eq!(falloff(12.0, 10.0), 0.0);
        assert_eq!(falloff(1.0, 0.0), 0.0);
    }
}
