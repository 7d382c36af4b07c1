//! The one place where sinew's canvas meets Spine's axes.
//!
//! sinew: canvas px, x right, **y down**, angles counter-clockwise *on screen*. Spine: world
//! units (= px here), x right, **y up**, angles counter-clockwise. The export puts Spine's
//! origin at the canvas point [`SpineFrame::origin_px`] (the bottom centre of the canvas, where a
//! character's feet usually stand) and flips y. Because both count angles counter-clockwise as
//! seen on screen, rotations and shears keep their values; only y coordinates (positions,
//! translations, a bone's local y) change sign. Scales are unchanged.
//!
//! [`BoneLocal`] is a bone's local transform as Spine stores it and [`BoneLocal::matrix`] is
//! spine-core's `Bone.updateWorldTransformWith` for the default inheritance (`normal`):
//! `a = cos(rotation + shearX)·scaleX`, `b = cos(rotation + 90 + shearY)·scaleY`,
//! `c = sin(rotation + shearX)·scaleX`, `d = sin(rotation + 90 + shearY)·scaleY`, and a child's
//! world transform is its parent's times its local one.

use crate::geom::{Point, Vec2};
use crate::rig::Affine;
use nalgebra::Matrix2;
use serde::{Deserialize, Serialize};

/// Where the Spine origin sits on the canvas; y flips between the two.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpineFrame {
    /// The canvas point (px) that becomes Spine's (0, 0).
    pub origin_px: Point,
}

impl SpineFrame {
    /// Spine's origin at the bottom centre of a canvas of `canvas_px`.
    pub fn for_canvas(canvas_px: [u32; 2]) -> Self {
        SpineFrame {
            origin_px: Point::new(f64::from(canvas_px[0]) / 2.0, f64::from(canvas_px[1])),
        }
    }

    /// A canvas position (px, y down) in Spine world units (y up).
    pub fn spine_from_canvas(&self, p: Point) -> Point {
        Point::new(p.x - self.origin_px.x, self.origin_px.y - p.y)
    }

    /// A Spine world position back on the canvas.
    pub fn canvas_from_spine(&self, q: Point) -> Point {
        Point::new(q.x + self.origin_px.x, self.origin_px.y - q.y)
    }

    /// A canvas displacement (px) as a Spine displacement.
    pub fn spine_vector(&self, v: Vec2) -> Vec2 {
        Vec2::new(v.x, -v.y)
    }

    /// A map of the canvas (rest canvas → posed canvas) as the same map of Spine's world.
    pub fn spine_affine(&self, canvas: &Affine) -> Affine {
        let flip = Matrix2::new(1.0, 0.0, 0.0, -1.0);
        let to_spine = Affine {
            linear: flip,
            translation: Vec2::new(-self.origin_px.x, self.origin_px.y),
        };
        let from_spine = Affine {
            linear: flip,
            translation: self.origin_px.coords,
        };
        to_spine.then_after(canvas).then_after(&from_spine)
    }
}

/// A bone's local transform in its parent's frame, as Spine's JSON stores it (y up, degrees
/// counter-clockwise).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoneLocal {
    pub x: f64,
    pub y: f64,
    pub rotation_deg: f64,
    pub scale_x: f64,
    pub scale_y: f64,
    pub shear_x_deg: f64,
    pub shear_y_deg: f64,
}

impl Default for BoneLocal {
    fn default() -> Self {
        BoneLocal {
            x: 0.0,
            y: 0.0,
            rotation_deg: 0.0,
            scale_x: 1.0,
            scale_y: 1.0,
            shear_x_deg: 0.0,
            shear_y_deg: 0.0,
        }
    }
}

impl BoneLocal {
    /// parent_from_bone, as spine-core composes it (inheritance `normal`).
    pub fn matrix(&self) -> Affine {
        let (rx, ry) = (
            (self.rotation_deg + self.shear_x_deg).to_radians(),
            (self.rotation_deg + 90.0 + self.shear_y_deg).to_radians(),
        );
        Affine {
            linear: Matrix2::new(
                rx.cos() * self.scale_x,
                ry.cos() * self.scale_y,
                rx.sin() * self.scale_x,
                ry.sin() * self.scale_y,
            ),
            translation: Vec2::new(self.x, self.y),
        }
    }

    /// The local transform with shearX = 0 that [`BoneLocal::matrix`] turns into `m`: rotation
    /// from the x axis, scaleY and shearY from the y axis (a reflection shows as shearY ≈ 180°).
    pub fn from_matrix(m: &Affine) -> BoneLocal {
        let (a, b, c, d) = (
            m.linear[(0, 0)],
            m.linear[(0, 1)],
            m.linear[(1, 0)],
            m.linear[(1, 1)],
        );
        let rotation_deg = c.atan2(a).to_degrees();
        let y_axis_deg = d.atan2(b).to_degrees();
        BoneLocal {
            x: m.translation.x,
            y: m.translation.y,
            rotation_deg,
            scale_x: a.hypot(c),
            scale_y: b.hypot(d),
            shear_x_deg: 0.0,
            shear_y_deg: wrap_deg(y_axis_deg - 90.0 - rotation_deg),
        }
    }
}

/// An angle in (−180°, 180°].
pub fn wrap_deg(angle_deg: f64) -> f64 {
    let mut a = angle_deg % 360.0;
    if a <= -180.0 {
        a += 360.0;
    } else if a > 180.0 {
        a -= 360.0;
    }
    a
}

/// `angle_deg` plus the multiple of 360° that brings it closest to `previous_deg`: the runtime
/// interpolates plain numbers, so consecutive baked angles must not jump by a turn.
pub fn unwrap_deg(angle_deg: f64, previous_deg: f64) -> f64 {
    angle_deg - ((angle_deg - previous_deg) / 360.0).round() * 360.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::rig::pose::bone_rest_frame;

    #[test]
    fn canvas_round_trip_and_flip() {
        let f = SpineFrame::for_canvas([100, 50]);
        let p = Point::new;
        assert_eq!(f.spine_from_canvas(p(50.0, 50.0)), p(0.0, 0.0));
        assert_eq!(f.spine_from_canvas(p(60.0, 40.0)), p(10.0, 10.0));
        assert_eq!(f.canvas_from_spine(p(10.0, 10.0)), p(60.0, 40.0));
    }

    #[test]
    fn a_bone_pointing_up_on_screen_points_up_in_spine() {
        // Head (50, 50) → tail (50, 30) on the canvas: up on screen, 90° counter-clockwise.
        let f = SpineFrame::for_canvas([100, 100]);
        let rest = bone_rest_frame(Point::new(50.0, 50.0), Point::new(50.0, 30.0));
        // Bone-local (u, v) in Spine is (u, −v) in sinew's bone frame; through the canvas into
        // Spine's world that is Spine's bone matrix of rotation 90° at (0, 50).
        let bone_local_flip = Affine {
            linear: Matrix2::new(1.0, 0.0, 0.0, -1.0),
            translation: Vec2::zeros(),
        };
        let spine_world = {
            let to_spine = |p: Point| {
                let q = f.spine_from_canvas(p);
                Point::new(q[0], q[1])
            };
            move |u: f64, v: f64| to_spine(rest.apply(bone_local_flip.apply(Point::new(u, v))))
        };
        let local = BoneLocal {
            x: 0.0,
            y: 50.0,
            rotation_deg: 90.0,
            ..Default::default()
        };
        for (u, v) in [(0.0, 0.0), (20.0, 0.0), (3.0, 7.0)] {
            let a = spine_world(u, v);
            let b = local.matrix().apply(Point::new(u, v));
            assert!((a - b).norm() < 1e-12, "{a} {b}");
        }
    }

    #[test]
    fn decomposition_inverts_the_matrix() {
        for local in [
            BoneLocal {
                x: 3.0,
                y: -4.0,
                rotation_deg: 37.0,
                scale_x: 1.5,
                scale_y: 0.5,
                shear_y_deg: 12.0,
                ..Default::default()
            },
            BoneLocal {
                rotation_deg: -170.0,
                scale_y: -2.0,
                ..Default::default()
            },
        ] {
            let m = local.matrix();
            let back = BoneLocal::from_matrix(&m).matrix();
            assert!((m.linear - back.linear).norm() < 1e-12);
            assert!((m.translation - back.translation).norm() < 1e-12);
        }
        assert_eq!(unwrap_deg(-175.0, 170.0), 185.0);
        assert_eq!(unwrap_deg(10.0, 370.0), 370.0);
        assert_eq!(wrap_deg(270.0), -90.0);
    }
}
