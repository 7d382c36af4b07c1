//! A 2D affine map as a DragonBones transform, and the armature's frame.
//!
//! DragonBones' frame is the canvas's (y down, angles clockwise on screen, radians in the
//! runtime, degrees in the file) moved so that the canvas's bottom centre is the origin. A bone's
//! transform (`x`, `y`, rotation r, skew s, `scX`, `scY`) is the matrix whose first column is
//! scX·(cos r, sin r) and second scY·(−sin(r+s), cos(r+s)) (`Transform.toMatrix`,
//! docs/dragonbones-format.md): each column's angle and length are free, so every 2D affine map
//! is one, reflections as a skew of half a turn. [`DbTransform::from_affine`] chooses the angles
//! nearest the previous frame's, so that the runtime's linear tween between frames turns the
//! short way.

use crate::export::joints::nearest_turn;
use crate::geom::{Point, Vec2};
use crate::rig::Affine;
use nalgebra::Matrix2;

/// The canvas point that is the armature's origin: the bottom centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DbFrame {
    pub origin_px: Point,
}

impl DbFrame {
    pub fn for_canvas(canvas_px: [u32; 2]) -> Self {
        DbFrame {
            origin_px: Point::new(f64::from(canvas_px[0]) / 2.0, f64::from(canvas_px[1])),
        }
    }

    /// A canvas point in armature coordinates.
    pub fn from_canvas(&self, p: Point) -> Vec2 {
        p - self.origin_px
    }

    /// An armature point back on the canvas.
    pub fn canvas_from(&self, q: Vec2) -> Point {
        self.origin_px + q
    }
}

impl crate::export::joints::Placement for DbFrame {
    fn place(&self, p: Point) -> Vec2 {
        self.from_canvas(p)
    }
    fn angle_rad(&self, d: Vec2) -> f64 {
        d.y.atan2(d.x)
    }
    /// T(−o)·A·T(o): the same linear part, the translation where the origin goes.
    fn map(&self, canvas: &Affine) -> Affine {
        Affine {
            linear: canvas.linear,
            translation: canvas.apply(self.origin_px) - self.origin_px,
        }
    }
}

/// A DragonBones transform (radians; the file writes degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DbTransform {
    pub x: f64,
    pub y: f64,
    pub rotation_rad: f64,
    pub skew_rad: f64,
    pub scale_x: f64,
    pub scale_y: f64,
}

impl DbTransform {
    /// The transform of `map`, its angles the nearest `previous`'s by whole turns.
    pub fn from_affine(map: &Affine, previous: Option<&DbTransform>) -> DbTransform {
        let m = map.linear;
        let (a, b, c, d) = (m[(0, 0)], m[(1, 0)], m[(0, 1)], m[(1, 1)]);
        let mut rotation_rad = b.atan2(a);
        // The second column's angle r + s.
        let mut second_rad = (-c).atan2(d);
        if let Some(p) = previous {
            rotation_rad = nearest_turn(rotation_rad, p.rotation_rad);
            second_rad = nearest_turn(second_rad, p.rotation_rad + p.skew_rad);
        } else {
            second_rad = nearest_turn(second_rad, rotation_rad);
        }
        DbTransform {
            x: map.translation.x,
            y: map.translation.y,
            rotation_rad,
            skew_rad: second_rad - rotation_rad,
            scale_x: a.hypot(b),
            scale_y: c.hypot(d),
        }
    }

    /// The map `Transform.toMatrix` makes of this transform.
    pub fn to_affine(&self) -> Affine {
        let (sr, cr) = self.rotation_rad.sin_cos();
        let (ss, cs) = (self.rotation_rad + self.skew_rad).sin_cos();
        Affine {
            linear: Matrix2::new(
                cr * self.scale_x,
                -ss * self.scale_y,
                sr * self.scale_x,
                cs * self.scale_y,
            ),
            translation: Vec2::new(self.x, self.y),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_affine_map_is_a_transform() {
        for m in [
            [1.0, 0.0, 0.0, 1.0],
            [0.0, -1.0, 1.0, 0.0],
            [2.0, 0.5, -0.3, 0.7],
            [-1.0, 0.0, 0.0, 1.0],
            [0.3, 2.0, 1.5, -0.2],
        ] {
            let a = Affine {
                linear: Matrix2::new(m[0], m[1], m[2], m[3]),
                translation: Vec2::new(3.0, -4.0),
            };
            let t = DbTransform::from_affine(&a, None);
            let back = t.to_affine();
            assert!((back.linear - a.linear).abs().max() < 1e-12, "{m:?}: {t:?}");
            assert!((back.translation - a.translation).norm() < 1e-12);
        }
    }

    #[test]
    fn turning_past_half_a_turn_continues() {
        let mut previous: Option<DbTransform> = None;
        for k in 0..40 {
            let angle = f64::from(k) * 0.3;
            let (s, c) = angle.sin_cos();
            let a = Affine {
                linear: Matrix2::new(c, -s, s, c),
                translation: Vec2::zeros(),
            };
            let t = DbTransform::from_affine(&a, previous.as_ref());
            assert!((t.rotation_rad - angle).abs() < 1e-9 && t.skew_rad.abs() < 1e-9);
            previous = Some(t);
        }
    }
}
