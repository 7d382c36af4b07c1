//! Bone physics constraints, as Spine 4.2 simulates them.
//!
//! In: a [`PhysicsConstraint`] of the handles file (Spine 4.2's parameters: what it moves —
//! `x`, `y`, `rotate`, `scale_x`, `shear_x` as mix factors — and `inertia`, `strength`,
//! `damping`, `mass`, `wind`, `gravity`, `limit`, `fps`, `mix`), the constrained bone's world
//! frame as posed (forward kinematics, bone IK, skinning IK) at each skeleton update, and the
//! skeleton's clock. Out: the bone's world frame moved by the simulated offsets; its
//! descendants move with it (`crate::scene::physics`).
//!
//! [`PhysicsState::update`] is spine-core 4.2's `PhysicsConstraint.update`
//! (spine-ts/spine-core/src/PhysicsConstraint.ts, branch 4.2) ported term by term, in Spine's
//! world axes (y up; [`SpineWorld::from_canvas`] converts sinew's canvas frames): the bone's
//! translation is pulled back by `inertia` times its motion (at most `limit` px/s), then a
//! damped spring of stiffness `strength` and mass `mass` under `wind` and `gravity` (× the
//! skeleton's reference scale, 100) is stepped at the constraint's fixed step `1/fps` as many
//! times as whole steps have accumulated since the last update; rotation and scale follow the
//! tip's lag the same way. History matters, so the result depends on when the skeleton is
//! updated: sinew updates it at [`UPDATE_HZ`] from the animation's start (see
//! `crate::scene::physics`), whatever the output frame rate.

use serde::{Deserialize, Serialize};

/// The skeleton's reference scale, px (spine-core's default `referenceScale`): wind and
/// gravity are in units of it.
pub const REFERENCE_SCALE: f64 = 100.0;
/// How often sinew updates a skeleton with physics, Hz (a game's frame rate; 60 as Spine's
/// editor previews).
pub const UPDATE_HZ: f64 = 60.0;
/// The highest simulation rate a constraint may ask for, steps per second.
pub const MAX_PHYSICS_FPS: f64 = 1000.0;

/// A physics constraint on one bone (Spine 4.2's, with its defaults).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PhysicsConstraint {
    pub name: String,
    /// The bone it moves.
    pub bone: String,
    /// How much of the simulated x translation is applied (0: none). Default 0.
    #[serde(default)]
    pub x: f64,
    /// How much of the simulated y translation is applied. Default 0.
    #[serde(default)]
    pub y: f64,
    /// How much of the simulated rotation is applied. Default 0.
    #[serde(default)]
    pub rotate: f64,
    /// How much of the simulated stretch along the bone is applied. Default 0.
    #[serde(default)]
    pub scale_x: f64,
    /// How much of the simulated rotation is applied as x shear. Default 0.
    #[serde(default)]
    pub shear_x: f64,
    /// Most motion taken in per second, px/s. Default 5000.
    #[serde(default = "default_limit")]
    pub limit: f64,
    /// Simulation steps per second (the fixed step is 1/fps). Default 60.
    #[serde(default = "default_fps")]
    pub fps: f64,
    /// How much of the bone's motion is held back (0..1). Default 1.
    #[serde(default = "one")]
    pub inertia: f64,
    /// Spring stiffness back to the pose. Default 100.
    #[serde(default = "default_strength")]
    pub strength: f64,
    /// Velocity kept per 1/60 s (0..1; 1: undamped). Default 1.
    #[serde(default = "one")]
    pub damping: f64,
    /// Default 1; must be > 0.
    #[serde(default = "one")]
    pub mass: f64,
    /// Force along +x (right), in reference-scale units. Default 0.
    #[serde(default)]
    pub wind: f64,
    /// Force down the screen, in reference-scale units. Default 0.
    #[serde(default)]
    pub gravity: f64,
    /// 0: off; 1: fully applied. Default 1.
    #[serde(default = "one")]
    pub mix: f64,
}

fn default_limit() -> f64 {
    5000.0
}
fn default_fps() -> f64 {
    60.0
}
fn default_strength() -> f64 {
    100.0
}
fn one() -> f64 {
    1.0
}

/// The smallest mass, f32's smallest normal number: the runtimes store `massInverse = 1 / mass`
/// in f32 (spine-cpp, spine-csharp, spine-libgdx; sinew writes the export's numbers as f32),
/// which is then finite, and the exported mass is not 0. A mass this small passes only with a
/// spring and forces its step can take ([`PhysicsConstraint::check_on_bone`]).
pub const MIN_MASS: f64 = f32::MIN_POSITIVE as f64;
/// The largest offset, px, a constant wind or gravity may hold a moved (`x`, `y`) bone at:
/// a quarter of [`super::frames::MAX_POSED_PX`], leaving room for the spring's overshoot on the
/// way there (up to as far again) and for the bone's own place.
pub const MAX_FORCED_OFFSET_PX: f64 = super::frames::MAX_POSED_PX / 4.0;
/// The largest stretch a constant wind or gravity may hold a `scale_x` bone at: a quarter of
/// [`super::frames::MAX_POSED_SCALE`], for the same reasons.
pub const MAX_FORCED_SCALE: f64 = super::frames::MAX_POSED_SCALE / 4.0;

/// A number as a message shows it: as written, or in exponent form when extreme.
fn shown(x: f64) -> crate::shown::Shown {
    crate::shown::Shown(x)
}

impl PhysicsConstraint {
    /// [`PhysicsConstraint::check_on_bone`] for a bone of no length (no rotational pull).
    pub fn check(&self) -> Result<(), String> {
        self.check_on_bone(0.0)
    }

    /// The parameters the runtime can step, on a bone of rest length `length_px`: a one-line
    /// reason naming the field as the file writes it otherwise. Every number finite and within
    /// ±1e6; `x`, `y`, `rotate`, `scale_x`, `shear_x`, `inertia` and `mix` in [0, 1] (shares of
    /// the motion; with them at most 1 the runtime's rotation lag, `offset += (angle − offset ×
    /// (rotate + shear_x) × mix) × inertia` per update, cannot overshoot and grow); `damping`
    /// in [0, 1] (each step multiplies the velocity by `damping^(60/fps)`: above 1 it grows
    /// without bound, below 0 `pow` is NaN); `strength` ≥ 0; `limit` ≥ 0; `fps` in (0,
    /// [`MAX_PHYSICS_FPS`]]; `mass` ≥ [`MIN_MASS`]; the spring's step stable; a constant
    /// wind or gravity on a moved or stretched bone held by a spring within
    /// [`MAX_FORCED_OFFSET_PX`] / [`MAX_FORCED_SCALE`].
    ///
    /// Stability: spine-core steps `v += −(strength · x + k_f · x) · t / mass; x += v · t;
    /// v *= d` with `t = 1/fps`, `d = damping^(60 t)`; per step (x, v) is multiplied by
    /// `[[1 − K, t], [−d K / t, d]]` with `K = (strength + k_f) · t² / mass`, whose
    /// eigenvalues stay in the unit circle exactly when `K < 2 (1 + d)` (Jury: determinant d
    /// ≤ 1, trace 1 − K + d > −(1 + d)). `k_f` is the stiffness wind and gravity add to the
    /// rotation (`(wind · sin + gravity · cos) · length / 100` varies by at most
    /// `hypot(wind, gravity) · length / 100 · (rotate + shear_x) · mix` per radian).
    pub fn check_on_bone(&self, length_px: f64) -> Result<(), String> {
        let named = [
            ("x", self.x),
            ("y", self.y),
            ("rotate", self.rotate),
            ("scale_x", self.scale_x),
            ("shear_x", self.shear_x),
            ("limit", self.limit),
            ("fps", self.fps),
            ("inertia", self.inertia),
            ("strength", self.strength),
            ("damping", self.damping),
            ("mass", self.mass),
            ("wind", self.wind),
            ("gravity", self.gravity),
            ("mix", self.mix),
        ];
        if let Some((field, value)) = named.iter().find(|(_, v)| !v.is_finite()) {
            return Err(format!("\"{field}\" is {value}: not a finite number"));
        }
        if let Some((field, value)) = named.iter().find(|(_, v)| v.abs() > 1e6) {
            return Err(format!("\"{field}\" is {}: beyond ±1e6", shown(*value)));
        }
        let shares = [
            ("x", self.x),
            ("y", self.y),
            ("rotate", self.rotate),
            ("scale_x", self.scale_x),
            ("shear_x", self.shear_x),
            ("inertia", self.inertia),
            ("mix", self.mix),
        ];
        if let Some((field, value)) = shares.iter().find(|(_, v)| !(0.0..=1.0).contains(v)) {
            return Err(format!(
                "\"{field}\" is {}: in [0, 1] (a share of the motion the runtime blends in)",
                shown(*value)
            ));
        }
        if !(0.0..=1.0).contains(&self.damping) {
            return Err(format!(
                "\"damping\" is {}: in [0, 1] (the runtime multiplies the velocity by \
                 damping^(60/fps) each step: above 1 it grows without bound, below 0 it is NaN)",
                shown(self.damping)
            ));
        }
        if self.strength < 0.0 {
            return Err(format!(
                "\"strength\" is {}: at least 0 (a negative spring pushes the bone away without bound)",
                shown(self.strength)
            ));
        }
        if self.limit < 0.0 {
            return Err(format!("\"limit\" is {}: at least 0", shown(self.limit)));
        }
        if !(self.fps > 0.0 && self.fps <= MAX_PHYSICS_FPS) {
            return Err(format!(
                "\"fps\" is {}: in (0, {MAX_PHYSICS_FPS}]",
                shown(self.fps)
            ));
        }
        if self.mass < MIN_MASS {
            return Err(format!(
                "\"mass\" is {}: at least {:e} (the runtime divides by it in f32)",
                shown(self.mass),
                MIN_MASS as f32
            ));
        }
        let t = self.step_s();
        let d = self.damping.powf(60.0 * t);
        let turning = (self.rotate + self.shear_x) * self.mix;
        let pull = if turning > 0.0 {
            self.wind.hypot(self.gravity) * length_px / REFERENCE_SCALE * turning
        } else {
            0.0
        };
        let k = (self.strength + pull) * t * t / self.mass;
        let bound = 2.0 * (1.0 + d);
        if !(k < bound) {
            let what = if pull > 0.0 {
                "(\"strength\" + the pull of \"wind\" and \"gravity\" on the bone)"
            } else {
                "\"strength\""
            };
            return Err(format!(
                "\"strength\" {}, \"mass\" {}, \"fps\" {}: the runtime's spring step diverges: \
                 {what} / (mass × fps²) is {} but must stay below 2 × (1 + damping^(60/fps)) = {} \
                 (raise the mass or fps, or lower the strength)",
                shown(self.strength),
                shown(self.mass),
                shown(self.fps),
                shown(k),
                shown(bound)
            ));
        }
        let forced = self.wind != 0.0 || self.gravity != 0.0;
        let moved = self.x > 0.0 || self.y > 0.0;
        if forced && (moved || self.scale_x > 0.0) {
            let force = self.wind.abs().max(self.gravity.abs());
            if self.strength == 0.0 {
                return Err(
                    "\"wind\" or \"gravity\" without \"strength\" carries a moved or stretched \
                     bone away without bound (give it a spring, or move only \"rotate\")"
                        .into(),
                );
            }
            let offset_px = force * REFERENCE_SCALE / self.strength;
            if moved && offset_px > MAX_FORCED_OFFSET_PX {
                return Err(format!(
                    "\"wind\"/\"gravity\" {} against \"strength\" {} hold the bone {} px away: \
                     at most {} px",
                    shown(force),
                    shown(self.strength),
                    shown(offset_px),
                    shown(MAX_FORCED_OFFSET_PX)
                ));
            }
            let stretch = (self.wind.abs() + self.gravity.abs()) / self.strength;
            if self.scale_x > 0.0 && stretch > MAX_FORCED_SCALE {
                return Err(format!(
                    "\"wind\"/\"gravity\" against \"strength\" {} stretch the bone by {}: \
                     at most {MAX_FORCED_SCALE}",
                    shown(self.strength),
                    shown(stretch)
                ));
            }
        }
        Ok(())
    }

    /// The fixed simulation step, s.
    pub fn step_s(&self) -> f64 {
        1.0 / self.fps
    }
}

/// A bone's world transform as spine-core holds it: `[a b; c d]` and the origin, y up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpineWorld {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub d: f64,
    pub world_x: f64,
    pub world_y: f64,
}

impl SpineWorld {
    /// A canvas frame (`world_from_bone`, y down; sinew's bone frames are rotations of the
    /// canvas axes) in Spine's axes: y flipped on both sides.
    pub fn from_canvas(frame: &super::Affine) -> SpineWorld {
        let l = frame.linear;
        SpineWorld {
            a: l[(0, 0)],
            b: -l[(0, 1)],
            c: -l[(1, 0)],
            d: l[(1, 1)],
            world_x: frame.translation.x,
            world_y: -frame.translation.y,
        }
    }

    /// Back to a canvas frame.
    pub fn to_canvas(self) -> super::Affine {
        super::Affine {
            linear: nalgebra::Matrix2::new(self.a, -self.b, -self.c, self.d),
            translation: crate::geom::Vec2::new(self.world_x, -self.world_y),
        }
    }

    /// spine-core's `Bone.getWorldScaleX`.
    fn world_scale_x(&self) -> f64 {
        (self.a * self.a + self.c * self.c).sqrt()
    }
}

/// How a skeleton update treats physics (spine-core's `Physics`, less `none` and `reset`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhysicsMode {
    /// Advance the simulation to the skeleton's time, then apply it.
    Update,
    /// Apply the simulation as it stands (a time between updates).
    Pose,
}

/// One constraint's simulation state (spine-core's `PhysicsConstraint` fields).
#[derive(Clone, Debug, PartialEq)]
pub struct PhysicsState {
    reset: bool,
    ux: f64,
    uy: f64,
    cx: f64,
    cy: f64,
    tx: f64,
    ty: f64,
    x_offset: f64,
    x_velocity: f64,
    y_offset: f64,
    y_velocity: f64,
    rotate_offset: f64,
    rotate_velocity: f64,
    scale_offset: f64,
    scale_velocity: f64,
    remaining: f64,
    last_time: f64,
}

impl Default for PhysicsState {
    /// As constructed: nothing moving, reset pending, the clock at 0.
    fn default() -> Self {
        PhysicsState {
            reset: true,
            ux: 0.0,
            uy: 0.0,
            cx: 0.0,
            cy: 0.0,
            tx: 0.0,
            ty: 0.0,
            x_offset: 0.0,
            x_velocity: 0.0,
            y_offset: 0.0,
            y_velocity: 0.0,
            rotate_offset: 0.0,
            rotate_velocity: 0.0,
            scale_offset: 0.0,
            scale_velocity: 0.0,
            remaining: 0.0,
            last_time: 0.0,
        }
    }
}

const PI2: f64 = std::f64::consts::PI * 2.0;
const INV_PI2: f64 = 1.0 / PI2;

impl PhysicsState {
    /// spine-core 4.2 `PhysicsConstraint.update(physics)` for `data` on a bone of rest length
    /// `length_px` whose world transform (after forward kinematics) is `bone`, with the
    /// skeleton's clock at `time_s` (skeleton scale 1, y up).
    pub fn update(
        &mut self,
        data: &PhysicsConstraint,
        length_px: f64,
        bone: &mut SpineWorld,
        time_s: f64,
        mode: PhysicsMode,
    ) {
        let mix = data.mix;
        if mix == 0.0 {
            return;
        }
        let x = data.x > 0.0;
        let y = data.y > 0.0;
        let rotate_or_shear_x = data.rotate > 0.0 || data.shear_x > 0.0;
        let scale_x = data.scale_x > 0.0;
        let l = length_px;
        let mass_inverse = 1.0 / data.mass;
        match mode {
            PhysicsMode::Update => {
                let delta = (time_s - self.last_time).max(0.0);
                self.remaining += delta;
                self.last_time = time_s;
                let (bx, by) = (bone.world_x, bone.world_y);
                if self.reset {
                    self.reset = false;
                    self.ux = bx;
                    self.uy = by;
                } else {
                    let mut a = self.remaining;
                    let i = data.inertia;
                    let t = data.step_s();
                    let f = REFERENCE_SCALE;
                    let mut d = -1.0;
                    let qx = data.limit * delta;
                    let qy = qx;
                    if x || y {
                        if x {
                            let u = (self.ux - bx) * i;
                            self.x_offset += u.clamp(-qx, qx);
                            self.ux = bx;
                        }
                        if y {
                            let u = (self.uy - by) * i;
                            self.y_offset += u.clamp(-qy, qy);
                            self.uy = by;
                        }
                        if a >= t {
                            d = data.damping.powf(60.0 * t);
                            let m = mass_inverse * t;
                            let e = data.strength;
                            let w = data.wind * f;
                            let g = data.gravity * f;
                            loop {
                                if x {
                                    self.x_velocity += (w - self.x_offset * e) * m;
                                    self.x_offset += self.x_velocity * t;
                                    self.x_velocity *= d;
                                }
                                if y {
                                    self.y_velocity -= (g + self.y_offset * e) * m;
                                    self.y_offset += self.y_velocity * t;
                                    self.y_velocity *= d;
                                }
                                a -= t;
                                if a < t {
                                    break;
                                }
                            }
                        }
                        if x {
                            bone.world_x += self.x_offset * mix * data.x;
                        }
                        if y {
                            bone.world_y += self.y_offset * mix * data.y;
                        }
                    }
                    if rotate_or_shear_x || scale_x {
                        let ca = bone.c.atan2(bone.a);
                        let (mut c, mut s, mut mr): (f64, f64, f64);
                        mr = 0.0;
                        let dx = (self.cx - bone.world_x).clamp(-qx, qx);
                        let dy = (self.cy - bone.world_y).clamp(-qy, qy);
                        if rotate_or_shear_x {
                            mr = (data.rotate + data.shear_x) * mix;
                            let mut r =
                                (dy + self.ty).atan2(dx + self.tx) - ca - self.rotate_offset * mr;
                            self.rotate_offset += (r - (r * INV_PI2 - 0.5).ceil() * PI2) * i;
                            r = self.rotate_offset * mr + ca;
                            c = r.cos();
                            s = r.sin();
                            if scale_x {
                                r = l * bone.world_scale_x();
                                if r > 0.0 {
                                    self.scale_offset += (dx * c + dy * s) * i / r;
                                }
                            }
                        } else {
                            c = ca.cos();
                            s = ca.sin();
                            let r = l * bone.world_scale_x();
                            if r > 0.0 {
                                self.scale_offset += (dx * c + dy * s) * i / r;
                            }
                        }
                        a = self.remaining;
                        if a >= t {
                            if d == -1.0 {
                                d = data.damping.powf(60.0 * t);
                            }
                            let m = mass_inverse * t;
                            let e = data.strength;
                            let w = data.wind;
                            let g = data.gravity;
                            let h = l / f;
                            loop {
                                a -= t;
                                if scale_x {
                                    self.scale_velocity +=
                                        (w * c - g * s - self.scale_offset * e) * m;
                                    self.scale_offset += self.scale_velocity * t;
                                    self.scale_velocity *= d;
                                }
                                if rotate_or_shear_x {
                                    self.rotate_velocity -=
                                        ((w * s + g * c) * h + self.rotate_offset * e) * m;
                                    self.rotate_offset += self.rotate_velocity * t;
                                    self.rotate_velocity *= d;
                                    if a < t {
                                        break;
                                    }
                                    let r = self.rotate_offset * mr + ca;
                                    c = r.cos();
                                    s = r.sin();
                                } else if a < t {
                                    break;
                                }
                            }
                        }
                    }
                    self.remaining = a;
                }
                self.cx = bone.world_x;
                self.cy = bone.world_y;
            }
            PhysicsMode::Pose => {
                if x {
                    bone.world_x += self.x_offset * mix * data.x;
                }
                if y {
                    bone.world_y += self.y_offset * mix * data.y;
                }
            }
        }
        if rotate_or_shear_x {
            let mut o = self.rotate_offset * mix;
            if data.shear_x > 0.0 {
                let mut r = 0.0;
                if data.rotate > 0.0 {
                    r = o * data.rotate;
                    let (s, c) = r.sin_cos();
                    let a = bone.b;
                    bone.b = c * a - s * bone.d;
                    bone.d = s * a + c * bone.d;
                }
                r += o * data.shear_x;
                let (s, c) = r.sin_cos();
                let a = bone.a;
                bone.a = c * a - s * bone.c;
                bone.c = s * a + c * bone.c;
            } else {
                o *= data.rotate;
                let (s, c) = o.sin_cos();
                let a = bone.a;
                bone.a = c * a - s * bone.c;
                bone.c = s * a + c * bone.c;
                let a = bone.b;
                bone.b = c * a - s * bone.d;
                bone.d = s * a + c * bone.d;
            }
        }
        if scale_x {
            let s = 1.0 + self.scale_offset * mix * data.scale_x;
            bone.a *= s;
            bone.c *= s;
        }
        if mode != PhysicsMode::Pose {
            self.tx = l * bone.a;
            self.ty = l * bone.c;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn constraint() -> PhysicsConstraint {
        serde_json::from_value(serde_json::json!({"name": "p", "bone": "b", "x": 1})).unwrap()
    }

    fn bone_at(x: f64) -> SpineWorld {
        SpineWorld {
            a: 1.0,
            b: 0.0,
            c: 0.0,
            d: 1.0,
            world_x: x,
            world_y: 0.0,
        }
    }

    #[test]
    fn defaults_are_spine_cores() {
        let c = constraint();
        assert_eq!(
            (c.limit, c.fps, c.inertia, c.strength, c.damping, c.mass, c.mix),
            (5000.0, 60.0, 1.0, 100.0, 1.0, 1.0, 1.0)
        );
        assert_eq!((c.y, c.rotate, c.scale_x, c.shear_x), (0.0, 0.0, 0.0, 0.0));
        let mut nan = c.clone();
        nan.gravity = f64::NAN;
        assert_eq!(
            nan.check().unwrap_err(),
            "\"gravity\" is NaN: not a finite number"
        );
    }

    #[test]
    fn a_jump_is_held_back_then_sprung_back_as_spine_core_steps_it() {
        let c = constraint();
        let step = c.step_s();
        let mut state = PhysicsState::default();
        // The first update only records where the bone is.
        let mut bone = bone_at(0.0);
        state.update(&c, 10.0, &mut bone, 0.0, PhysicsMode::Update);
        assert_eq!(bone.world_x, 0.0);
        // The bone jumps 10 px in one step: inertia 1 holds it back entirely (offset −10), then
        // one spring step (strength 100, mass 1, undamped) by hand, as PhysicsConstraint.ts:
        // v += (0 − (−10)·100)·t; offset += v·t.
        let mut bone = bone_at(10.0);
        state.update(&c, 10.0, &mut bone, step, PhysicsMode::Update);
        let v = 10.0 * 100.0 * step;
        let offset = -10.0 + v * step;
        assert!(
            (bone.world_x - (10.0 + offset)).abs() < 1e-12,
            "{}",
            bone.world_x
        );
        // Between updates: the same offset, no step.
        let mut posed = bone_at(10.0);
        state
            .clone()
            .update(&c, 10.0, &mut posed, step, PhysicsMode::Pose);
        assert_eq!(posed.world_x, bone.world_x);
        // Damped, it settles back on the pose.
        let mut damped = c.clone();
        damped.damping = 0.5;
        let mut state = PhysicsState::default();
        for k in 0..600 {
            let mut bone = bone_at(if k == 0 { 0.0 } else { 10.0 });
            state.update(
                &damped,
                10.0,
                &mut bone,
                k as f64 * step,
                PhysicsMode::Update,
            );
            if k == 599 {
                assert!((bone.world_x - 10.0).abs() < 1e-6, "{}", bone.world_x);
            }
        }
    }

    #[test]
    fn canvas_frames_round_trip_through_spines_axes() {
        let frame = crate::rig::pose::bone_rest_frame(
            crate::geom::Point::new(3.0, 4.0),
            crate::geom::Point::new(13.0, -6.0),
        );
        let spine = SpineWorld::from_canvas(&frame);
        // 45° up on screen: counter-clockwise in Spine's y-up axes too.
        assert!((spine.c.atan2(spine.a).to_degrees() - 45.0).abs() < 1e-12);
        assert!((spine.a * spine.d - spine.b * spine.c - 1.0).abs() < 1e-12);
        assert_eq!(spine.to_canvas(), frame);
    }
}
