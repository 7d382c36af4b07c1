//! The canvas (px, y down) as glTF's space (units, y up), and a 2D affine map as the two glTF
//! nodes that carry it.
//!
//! glTF nodes animate translation, rotation and scale only, with no shear, while a sinew handle's
//! transformation is any 2D affine map (the skinning IK fits affine maps). Every 2D linear map
//! with a positive determinant factors as R(θ₁)·diag(s₁, s₂)·R(θ₂) (polar decomposition, then
//! the stretch's eigenvectors); one with a negative determinant does with s₂ < 0. So a handle
//! is two nodes: a *pivot* carrying translation, R(θ₁) and the scale, and under it the *joint*
//! carrying R(θ₂). [`Trsr`] is that factorization, [`Trsr::from_affine`] finds it, choosing
//! among its equivalent forms the one nearest the previous frame's so that a runtime's
//! interpolation between keys turns the short way.

use crate::anim::curve::f32_stored;
use crate::export::joints::nearest_turn;
use crate::geom::{Point, Vec2};
use crate::rig::Affine;
use nalgebra::Matrix2;
use std::f64::consts::FRAC_PI_2;

/// Where the canvas sits in glTF space: canvas point `origin_px` is glTF's origin, one unit is
/// `px_per_unit` canvas px, glTF's y points up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltfFrame {
    pub origin_px: Point,
    pub px_per_unit: f64,
}

impl GltfFrame {
    /// The origin at the canvas's bottom centre (as the Spine export's), `px_per_unit` px a unit.
    pub fn for_canvas(canvas_px: [u32; 2], px_per_unit: f64) -> Self {
        GltfFrame {
            origin_px: Point::new(f64::from(canvas_px[0]) / 2.0, f64::from(canvas_px[1])),
            px_per_unit,
        }
    }

    /// A canvas position in glTF units (x, y; z is the layer's).
    pub fn from_canvas(&self, p: Point) -> Vec2 {
        Vec2::new(
            (p.x - self.origin_px.x) / self.px_per_unit,
            (self.origin_px.y - p.y) / self.px_per_unit,
        )
    }

    /// A glTF position (units, y up) back on the canvas: the inverse of [`Self::from_canvas`].
    pub fn canvas_from(&self, q: Vec2) -> Point {
        Point::new(
            q.x * self.px_per_unit + self.origin_px.x,
            self.origin_px.y - q.y * self.px_per_unit,
        )
    }

    /// A canvas displacement (px) in glTF units.
    pub fn vector(&self, v: Vec2) -> Vec2 {
        Vec2::new(v.x / self.px_per_unit, -v.y / self.px_per_unit)
    }

    /// A map of the canvas (rest → posed) as the same map of glTF space: F ∘ A ∘ F⁻¹.
    pub fn affine(&self, canvas: &Affine) -> Affine {
        let flip = Matrix2::new(1.0, 0.0, 0.0, -1.0);
        let linear = flip * canvas.linear * flip;
        // F(A(F⁻¹(0))): where glTF's origin goes.
        let origin = canvas.apply(self.origin_px);
        let moved = self.from_canvas(origin);
        Affine {
            linear,
            translation: moved,
        }
    }
}

impl crate::export::joints::Placement for GltfFrame {
    fn place(&self, p: Point) -> Vec2 {
        self.from_canvas(p)
    }
    /// Canvas angles turn clockwise on screen (y down); glTF's turn the other way.
    fn angle_rad(&self, d: Vec2) -> f64 {
        -d.y.atan2(d.x)
    }
    fn map(&self, canvas: &Affine) -> Affine {
        self.affine(canvas)
    }
}

/// A 2D affine map as translation · R(θ₁) · diag(s₁, s₂) · R(θ₂) (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trsr {
    pub translation: Vec2,
    /// The pivot node's rotation about z, radians (counter-clockwise, y up).
    pub pivot_rad: f64,
    pub scale: [f64; 2],
    /// The joint node's rotation about z, radians.
    pub joint_rad: f64,
}

/// Stretches whose two scales differ by less than this (relative) have no axis of their own:
/// the previous frame's is kept.
const ISOTROPIC_TOLERANCE: f64 = 1e-12;

impl Trsr {
    /// The factorization of `map`, the one nearest `previous` among its equivalent forms (the
    /// stretch's axis turned by quarter turns with its scales swapped, each angle by whole
    /// turns); without `previous`, the joint angle nearest zero.
    pub fn from_affine(map: &Affine, previous: Option<&Trsr>) -> Trsr {
        let m = map.linear;
        let reflected = m.determinant() < 0.0;
        // N = M·D with D = diag(1, −1) when M reflects, so det N > 0.
        let n = if reflected {
            Matrix2::new(m[(0, 0)], -m[(0, 1)], m[(1, 0)], -m[(1, 1)])
        } else {
            m
        };
        // Polar decomposition N = R(θ)·P, P symmetric positive definite.
        let theta = (n[(1, 0)] - n[(0, 1)]).atan2(n[(0, 0)] + n[(1, 1)]);
        let p = rotation(-theta) * n;
        let (pxx, pxy, pyy) = (p[(0, 0)], 0.5 * (p[(0, 1)] + p[(1, 0)]), p[(1, 1)]);
        // P = R(φ)·diag(s₁, s₂)·R(−φ).
        let mut phi = 0.5 * (2.0 * pxy).atan2(pxx - pyy);
        let eigen = |phi: f64| {
            let (s, c) = phi.sin_cos();
            (
                pxx * c * c + 2.0 * pxy * c * s + pyy * s * s,
                pxx * s * s - 2.0 * pxy * c * s + pyy * c * c,
            )
        };
        let (mut s1, mut s2) = eigen(phi);
        // M = R(θ+φ)·diag(s₁, s₂)·R(−φ), or with a reflection R(θ+φ)·diag(s₁, −s₂)·R(φ).
        let joint_of = |phi: f64| if reflected { phi } else { -phi };
        let isotropic = (s1 - s2).abs() <= ISOTROPIC_TOLERANCE * s1.abs().max(s2.abs());
        if let Some(prev) = previous {
            if isotropic {
                phi = if reflected {
                    prev.joint_rad
                } else {
                    -prev.joint_rad
                };
            } else {
                // The quarter turn of the stretch's axis nearest the previous joint angle.
                let mut best = (f64::INFINITY, phi, s1, s2);
                for k in -2i32..=2 {
                    let candidate = phi + f64::from(k) * FRAC_PI_2;
                    let joint = nearest_turn(joint_of(candidate), prev.joint_rad);
                    let distance = (joint - prev.joint_rad).abs();
                    if distance < best.0 {
                        let (a, b) = if k % 2 == 0 { (s1, s2) } else { (s2, s1) };
                        best = (distance, candidate, a, b);
                    }
                }
                (_, phi, s1, s2) = best;
            }
        } else if isotropic {
            phi = 0.0;
        }
        let mut joint_rad = joint_of(phi);
        let mut pivot_rad = theta + phi;
        if let Some(prev) = previous {
            joint_rad = nearest_turn(joint_rad, prev.joint_rad);
            pivot_rad = nearest_turn(pivot_rad, prev.pivot_rad);
        }
        Trsr {
            translation: map.translation,
            pivot_rad,
            scale: [s1, if reflected { -s2 } else { s2 }],
            joint_rad,
        }
    }

    /// The factorization as the file stores it: translation and scale in f32, each angle as
    /// its f32 quaternion's.
    pub fn stored(&self) -> Trsr {
        let angle = |a: f64| {
            let [_, _, z, w] = z_quaternion(a).map(f32_stored);
            2.0 * z.atan2(w)
        };
        let f = f32_stored;
        Trsr {
            translation: Vec2::new(f(self.translation.x), f(self.translation.y)),
            pivot_rad: angle(self.pivot_rad),
            scale: [f(self.scale[0]), f(self.scale[1])],
            joint_rad: angle(self.joint_rad),
        }
    }

    /// The affine map this factorization stands for.
    pub fn to_affine(&self) -> Affine {
        let scale = Matrix2::new(self.scale[0], 0.0, 0.0, self.scale[1]);
        Affine {
            linear: rotation(self.pivot_rad) * scale * rotation(self.joint_rad),
            translation: self.translation,
        }
    }
}

/// The counter-clockwise rotation by `angle_rad`.
pub fn rotation(angle_rad: f64) -> Matrix2<f64> {
    let (s, c) = angle_rad.sin_cos();
    Matrix2::new(c, -s, s, c)
}

/// A rotation about z as a glTF quaternion `[x, y, z, w]`.
pub fn z_quaternion(angle_rad: f64) -> [f64; 4] {
    let (s, c) = (0.5 * angle_rad).sin_cos();
    [0.0, 0.0, s, c]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &Affine, b: &Affine) -> bool {
        (a.linear - b.linear).abs().max() < 1e-12 && (a.translation - b.translation).norm() < 1e-12
    }

    fn map(m: [f64; 4], t: [f64; 2]) -> Affine {
        Affine {
            linear: Matrix2::new(m[0], m[1], m[2], m[3]),
            translation: Vec2::new(t[0], t[1]),
        }
    }

    #[test]
    fn every_affine_map_factors_exactly() {
        for m in [
            [1.0, 0.0, 0.0, 1.0],
            [0.0, -1.0, 1.0, 0.0],
            [2.0, 0.5, -0.3, 0.7],
            [1.0, 0.4, 0.0, 1.0],
            [-1.0, 0.0, 0.0, 1.0],
            [0.3, 2.0, 1.5, -0.2],
            [-2.0, 0.0, 0.0, -2.0],
        ] {
            let a = map(m, [3.0, -4.0]);
            let f = Trsr::from_affine(&a, None);
            assert!(close(&f.to_affine(), &a), "{m:?}: {f:?}");
            let prev = Trsr {
                translation: Vec2::zeros(),
                pivot_rad: 5.0,
                scale: [1.0, 1.0],
                joint_rad: -4.0,
            };
            let g = Trsr::from_affine(&a, Some(&prev));
            assert!(close(&g.to_affine(), &a), "{m:?} after a previous: {g:?}");
        }
    }

    #[test]
    fn a_rotation_is_the_pivot_alone_and_turns_continue_past_a_half_turn() {
        let mut previous: Option<Trsr> = None;
        for k in 0..40 {
            let angle = f64::from(k) * 0.3;
            let a = Affine {
                linear: rotation(angle),
                translation: Vec2::zeros(),
            };
            let f = Trsr::from_affine(&a, previous.as_ref());
            assert!((f.pivot_rad - angle).abs() < 1e-9, "{k}: {f:?}");
            assert!(f.joint_rad.abs() < 1e-12);
            previous = Some(f);
        }
    }

    #[test]
    fn the_stretch_axis_follows_the_previous_frame() {
        // A stretch along an axis turning slowly past where its two scales swap roles.
        let mut previous: Option<Trsr> = None;
        for k in 0..30 {
            let axis = f64::from(k) * 0.1;
            let linear = rotation(axis) * Matrix2::new(1.5, 0.0, 0.0, 0.8) * rotation(-axis);
            let a = Affine {
                linear,
                translation: Vec2::zeros(),
            };
            let f = Trsr::from_affine(&a, previous.as_ref());
            assert!(close(&f.to_affine(), &a));
            if let Some(p) = previous {
                assert!(
                    (f.joint_rad - p.joint_rad).abs() < 0.11,
                    "{k}: {p:?} → {f:?}"
                );
                assert!(
                    (f.pivot_rad - p.pivot_rad).abs() < 0.11,
                    "{k}: {p:?} → {f:?}"
                );
            }
            previous = Some(f);
        }
    }

    #[test]
    fn the_frame_maps_canvas_maps_into_gltf_space() {
        let frame = GltfFrame::for_canvas([200, 100], 50.0);
        let a = map([0.0, -1.0, 1.0, 0.0], [7.0, 3.0]);
        let g = frame.affine(&a);
        let p = Point::new(30.0, 20.0);
        let expected = frame.from_canvas(a.apply(p));
        let q = frame.from_canvas(p);
        let got = g.linear * q + g.translation;
        assert!((got - expected).norm() < 1e-12);
    }
}
