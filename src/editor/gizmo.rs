//! Pose-mode gizmos: grab, rotate and scale the selected bone or point by forward kinematics.
//!
//! In: the selected handle's [`FkTarget`] (where it is shown), the pointer (screen points, then
//! canvas px through [`Placed`]). Out: shapes to draw and, while a gesture runs, the previewed
//! pose from [`crate::rig::fk_edit::apply`]; the editor commits it as one pose command.
//!
//! Two ways in, as animators know them: drag the gizmo drawn at the handle's pivot (the centre
//! grabs, the ring rotates, the square knob on the ring scales), or press G, R or S and move the
//! pointer (Blender's modal way): a click confirms, Esc or a right click cancels.

use super::canvas::Placed;
use crate::geom::Point;
use crate::rig::fk_edit::{self, FkEdit, FkEditError, FkTarget};
use crate::rig::{Affine, Handles, Pose};
use eframe::egui::{self, Color32, Pos2, Shape, Stroke};

/// The rotate ring's radius, screen points.
pub const RING_RADIUS_PT: f32 = 36.0;
/// A press this close to the ring (either side), screen points, grabs it.
pub const RING_HALF_WIDTH_PT: f32 = 6.0;
/// A press this close to the pivot grabs the handle, screen points.
pub const CENTRE_RADIUS_PT: f32 = 8.0;
/// A press this close to the scale knob (on the ring, along the handle) scales, screen points.
pub const KNOB_RADIUS_PT: f32 = 7.0;
/// A scale gesture measures distances from the pivot of at least this much, canvas px, so a
/// start on the pivot itself does not divide by zero.
pub const MIN_SCALE_REACH_PX: f64 = 1.0;

/// Which edit a gesture makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FkKind {
    Grab,
    Rotate,
    Scale,
}

/// An FK edit in progress: the pose before, what was shown, and the preview so far.
#[derive(Clone, Debug)]
pub struct FkGesture {
    pub name: String,
    pub kind: FkKind,
    /// Started by a key: the hovering pointer drives it until a click.
    pub modal: bool,
    base: Pose,
    shown: Vec<Affine>,
    pub target: FkTarget,
    start_px: Point,
    last_px: Point,
    /// Rotation so far, degrees: summed frame to frame, so turning past 180° keeps going.
    turned_deg: f64,
    pub preview: Pose,
}

impl FkGesture {
    /// Starts an edit of `name` with the pointer at `pointer_px` (canvas).
    pub fn start(
        handles: &Handles,
        pose: &Pose,
        shown: &[Affine],
        name: &str,
        kind: FkKind,
        pointer_px: Point,
        modal: bool,
    ) -> Result<Self, FkEditError> {
        let target = fk_edit::target(handles, shown, name)?;
        Ok(FkGesture {
            name: name.to_string(),
            kind,
            modal,
            base: pose.clone(),
            shown: shown.to_vec(),
            target,
            start_px: pointer_px,
            last_px: pointer_px,
            turned_deg: 0.0,
            preview: pose.clone(),
        })
    }

    /// Follows the pointer to `pointer_px` (canvas) and recomputes the preview.
    pub fn update(&mut self, handles: &Handles, pointer_px: Point) -> Result<(), FkEditError> {
        let pivot = self.target.pivot_px;
        let from_pivot = |p: Point| p - pivot;
        let edit = match self.kind {
            FkKind::Grab => FkEdit::Grab {
                delta_px: pointer_px - self.start_px,
            },
            FkKind::Rotate => {
                let (a, b) = (from_pivot(self.last_px), from_pivot(pointer_px));
                if a != crate::geom::Vec2::zeros() && b != crate::geom::Vec2::zeros() {
                    self.turned_deg += fk_edit::turn_deg(a, b);
                }
                FkEdit::Rotate {
                    angle_deg: self.turned_deg,
                }
            }
            FkKind::Scale => {
                let reach = |p: Point| from_pivot(p).norm().max(MIN_SCALE_REACH_PX);
                FkEdit::Scale {
                    factor: reach(pointer_px) / reach(self.start_px),
                }
            }
        };
        self.last_px = pointer_px;
        self.preview = fk_edit::apply(handles, &self.base, &self.shown, &self.name, edit)?;
        Ok(())
    }
}

/// The gizmo's scale knob, screen points.
fn knob(placed: &Placed, target: &FkTarget) -> Pos2 {
    let centre = placed.screen_from_canvas(target.pivot_px);
    centre + egui::vec2(target.direction[0] as f32, target.direction[1] as f32) * RING_RADIUS_PT
}

/// Which part of the gizmo of `target` is under `at` (screen points), if any.
pub fn hit(placed: &Placed, target: &FkTarget, at: Pos2) -> Option<FkKind> {
    let centre = placed.screen_from_canvas(target.pivot_px);
    let d = centre.distance(at);
    if knob(placed, target).distance(at) <= KNOB_RADIUS_PT {
        Some(FkKind::Scale)
    } else if d <= CENTRE_RADIUS_PT {
        Some(FkKind::Grab)
    } else if (d - RING_RADIUS_PT).abs() <= RING_HALF_WIDTH_PT {
        Some(FkKind::Rotate)
    } else {
        None
    }
}

/// The gizmo of `target`; `active` (the running gesture's kind) highlighted.
pub fn shapes(placed: &Placed, target: &FkTarget, active: Option<FkKind>) -> Vec<Shape> {
    let centre = placed.screen_from_canvas(target.pivot_px);
    let color = |kind: FkKind| {
        if active == Some(kind) {
            Color32::from_rgb(255, 230, 120)
        } else {
            Color32::from_rgb(255, 170, 40)
        }
    };
    let k = knob(placed, target);
    vec![
        Shape::circle_stroke(
            centre,
            RING_RADIUS_PT,
            Stroke::new(2.0, color(FkKind::Rotate)),
        ),
        Shape::circle_filled(centre, 4.0, color(FkKind::Grab)),
        Shape::circle_stroke(
            centre,
            CENTRE_RADIUS_PT,
            Stroke::new(1.0, color(FkKind::Grab)),
        ),
        Shape::rect_filled(
            egui::Rect::from_center_size(k, egui::vec2(9.0, 9.0)),
            0.0,
            color(FkKind::Scale),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::editor::canvas::View;
    use crate::rig::{handle_transforms, Bone};

    fn one_bone() -> Handles {
        let mut h = Handles::default();
        h.bones.push(Bone {
            name: "b".into(),
            parent: None,
            head: Point::new(100.0, 100.0),
            tail: Point::new(200.0, 100.0),
        });
        h
    }

    #[test]
    fn gizmo_parts_are_hit_where_drawn() {
        let h = one_bone();
        let shown = handle_transforms(&h, &Pose::default()).unwrap();
        let target = fk_edit::target(&h, &shown, "b").unwrap();
        let placed = Placed {
            view: View {
                zoom: 1.0,
                pan: egui::Vec2::ZERO,
            },
            origin: Pos2::ZERO,
        };
        let c = placed.screen_from_canvas(Point::new(100.0, 100.0));
        assert_eq!(hit(&placed, &target, c), Some(FkKind::Grab));
        assert_eq!(
            hit(&placed, &target, c + egui::vec2(0.0, RING_RADIUS_PT)),
            Some(FkKind::Rotate)
        );
        assert_eq!(
            hit(&placed, &target, c + egui::vec2(RING_RADIUS_PT, 0.0)),
            Some(FkKind::Scale)
        );
        assert_eq!(hit(&placed, &target, c + egui::vec2(20.0, 0.0)), None);
    }

    #[test]
    fn rotation_accumulates_past_half_a_turn() {
        let h = one_bone();
        let pose = Pose::default();
        let shown = handle_transforms(&h, &pose).unwrap();
        let mut g = FkGesture::start(
            &h,
            &pose,
            &shown,
            "b",
            FkKind::Rotate,
            Point::new(150.0, 100.0),
            true,
        )
        .unwrap();
        // Three quarter turns counter-clockwise on screen: right → up → left → down.
        for p in [
            Point::new(100.0, 50.0),
            Point::new(50.0, 100.0),
            Point::new(100.0, 150.0),
        ] {
            g.update(&h, p).unwrap();
        }
        assert!((g.turned_deg - 270.0).abs() < 1e-9);
        assert!((g.preview.bones["b"].rotate - 270.0).abs() < 1e-9);
    }

    #[test]
    fn scale_follows_the_distance_from_the_pivot() {
        let h = one_bone();
        let pose = Pose::default();
        let shown = handle_transforms(&h, &pose).unwrap();
        let mut g = FkGesture::start(
            &h,
            &pose,
            &shown,
            "b",
            FkKind::Scale,
            Point::new(110.0, 100.0),
            false,
        )
        .unwrap();
        g.update(&h, Point::new(100.0, 130.0)).unwrap();
        assert!((g.preview.bones["b"].scale[0] - 3.0).abs() < 1e-12);
    }
}
