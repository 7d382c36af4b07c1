//! The pose model and the bone frames forward kinematics builds on: affine maps, the pose file's
//! types ([`Pose`] and its parts), what can be wrong with a pose ([`PoseError`]), bones' rest
//! frames and their posed world frames. Below both [`super::bone_ik`] (which solves constraints on
//! these frames) and [`super::pose`] (which applies the constraints and turns frames into the
//! skinning transformations), so that neither imports the other's caller; `pose` re-exports all
//! of it, which is where the rest of the crate finds it.
//!
//! Bone frames follow Spine's conventions, so that export is a change of axes only: a bone's
//! frame has its origin at the head and its x axis along head → tail. A bone's local pose acts
//! in its parent's frame (the canvas for a root bone): `translate` (px) offsets the head,
//! `rotate` (degrees, counter-clockwise on screen) turns the bone about its head, `scale` scales
//! along the bone (x) and across it (y), `shear` (degrees) skews the two axes.
//!
//! Angles are counter-clockwise as seen on screen; with y pointing down, that is a clockwise
//! turn in the usual math orientation, so every rotation matrix here comes from [`rotation`].

use super::handles::Handles;
use crate::geom::{Point, Vec2};
use crate::shown::Shown;
use nalgebra::Matrix2;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// An affine map of the canvas: p ↦ linear · p + translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine {
    pub linear: Matrix2<f64>,
    pub translation: Vec2,
}

impl Affine {
    pub fn identity() -> Self {
        Affine {
            linear: Matrix2::identity(),
            translation: Vec2::zeros(),
        }
    }

    pub fn translation(t: Vec2) -> Self {
        Affine {
            linear: Matrix2::identity(),
            translation: t,
        }
    }

    pub fn apply(&self, p: Point) -> Point {
        Point::from(self.linear * p.coords + self.translation)
    }

    /// self ∘ other: first `other`, then `self`.
    pub fn then_after(&self, other: &Affine) -> Affine {
        Affine {
            linear: self.linear * other.linear,
            translation: self.linear * other.translation + self.translation,
        }
    }

    pub fn inverse(&self) -> Option<Affine> {
        let inv = self.linear.try_inverse()?;
        Some(Affine {
            linear: inv,
            translation: -(inv * self.translation),
        })
    }
}

/// The matrix that turns vectors by `angle_deg` counter-clockwise on screen (y down).
pub fn rotation(angle_deg: f64) -> Matrix2<f64> {
    let (s, c) = (-angle_deg.to_radians()).sin_cos();
    Matrix2::new(c, -s, s, c)
}

/// The on-screen counter-clockwise angle of a canvas vector, degrees.
pub fn screen_angle_deg(v: Vec2) -> f64 {
    (-v.y).atan2(v.x).to_degrees()
}

/// A bone's local pose, in its parent's frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct BonePose {
    /// Degrees, counter-clockwise on screen, about the head.
    pub rotate: f64,
    /// Offset of the head, px, in the parent's frame.
    pub translate: [f64; 2],
    /// Along the bone, across it.
    pub scale: [f64; 2],
    /// Degrees: x axis, y axis.
    pub shear: [f64; 2],
}

impl Default for BonePose {
    fn default() -> Self {
        BonePose {
            rotate: 0.0,
            translate: [0.0, 0.0],
            scale: [1.0, 1.0],
            shear: [0.0, 0.0],
        }
    }
}

/// A point handle's pose: about its rest position, in canvas axes. A point carried by a bone
/// ([`super::PointHandle::parent`]) takes this pose at rest, then moves as its parent does.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct PointPose {
    pub translate: [f64; 2],
    /// Degrees, counter-clockwise on screen.
    pub rotate: f64,
    pub scale: [f64; 2],
    /// Degrees: x axis, y axis (as a bone's), so that any affine map of a point is a pose.
    #[serde(skip_serializing_if = "is_zero2")]
    pub shear: [f64; 2],
}

fn is_zero2(v: &[f64; 2]) -> bool {
    *v == [0.0, 0.0]
}

impl Default for PointPose {
    fn default() -> Self {
        PointPose {
            translate: [0.0, 0.0],
            rotate: 0.0,
            scale: [1.0, 1.0],
            shear: [0.0, 0.0],
        }
    }
}

/// A cage's posed polygon (same vertex count as at rest), canvas px.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CagePose {
    #[schemars(with = "Vec<[f64; 2]>")]
    pub polygon: Vec<Point>,
}

/// A drag for skinning IK: the material point at rest position `at` goes to `to` (canvas px).
/// Without a `weight` the drag is a hard constraint (met exactly when feasible); with one it is
/// a soft pull of that strength (1 ≈ the stiffness of moving one handle).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct IkDrag {
    #[schemars(with = "[f64; 2]")]
    pub at: Point,
    #[schemars(with = "[f64; 2]")]
    pub to: Point,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weight: Option<f64>,
}

/// A part's look: a tint multiplying its texture, and whether it is drawn.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct PartPose {
    /// RGBA multiplier, each channel in [0, 1].
    pub color: [f64; 4],
    pub visible: bool,
    /// The attachment the slot shows (a part of the slot, by name); absent or the slot's own
    /// name: its default, as the active skins resolve it (see [`crate::io::slots`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub attachment: Option<String>,
}

impl Default for PartPose {
    fn default() -> Self {
        PartPose {
            color: [1.0, 1.0, 1.0, 1.0],
            visible: true,
            attachment: None,
        }
    }
}

/// The pose file: anything not named stays at rest.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Pose {
    pub bones: BTreeMap<String, BonePose>,
    pub points: BTreeMap<String, PointPose>,
    pub cages: BTreeMap<String, CagePose>,
    pub ik: Vec<IkDrag>,
    /// Parts by name; a part not named keeps [`PartPose::default`].
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub parts: BTreeMap<String, PartPose>,
    /// Part names back to front; `None` keeps the rig's order.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub draw_order: Option<Vec<String>>,
    /// Deform offsets by part: one per vertex of the part's mesh (canvas px, rest frame), added
    /// to the rest vertices before skinning ([`crate::anim::deform`]).
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    #[schemars(with = "BTreeMap<String, Vec<[f64; 2]>>")]
    pub deform: BTreeMap<String, Vec<Vec2>>,
}

/// What is wrong with a pose for a given set of handles.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum PoseError {
    #[error("the pose names {kind} '{name}', which the rig does not have")]
    UnknownName { kind: &'static str, name: String },
    #[error("cage '{name}' has {got} vertices in the pose but {expected} at rest")]
    CageSize {
        name: String,
        got: usize,
        expected: usize,
    },
    #[error("the pose of '{0}' has a value that is not a finite number")]
    NonFinite(String),
    #[error(
        "the pose of '{name}' has the value {value}, beyond ±{MAX_POSE_VALUE} (px, degrees or scale)",
        name = .0, value = Shown(*.1)
    )]
    TooLarge(String, f64),
    #[error("ik drag {0}")]
    BadDrag(String),
    #[error("the pose of part '{0}' has a color channel outside [0, 1]")]
    Color(String),
    #[error("the pose of '{0}' makes its transformation singular (a zero scale?)")]
    Singular(String),
    #[error(
        "the pose of '{0}' moves it beyond ±{MAX_POSED_PX} px or scales it by more than \
         {MAX_POSED_SCALE}"
    )]
    OutOfRange(String),
}

/// The largest magnitude of a number in a pose (px, degrees, scale factors): a rotation of
/// 1e300° has no meaning and loses every digit in the rotation it makes.
pub const MAX_POSE_VALUE: f64 = 1e6;

impl IkDrag {
    /// Every number finite, `at` and `to` within ±[`MAX_POSED_PX`], a weight ≥ 0: the one check
    /// of a drag, wherever it comes from (a pose file, an animation's keys, the editor).
    pub fn check(&self) -> Result<(), PoseError> {
        let numbers = [self.at[0], self.at[1], self.to[0], self.to[1]];
        if !finite(&numbers) || self.weight.is_some_and(|w| !(w.is_finite() && w >= 0.0)) {
            return Err(PoseError::BadDrag(format!(
                "at {:?} to {:?}: every number must be finite (and a weight ≥ 0)",
                self.at, self.to
            )));
        }
        if numbers.iter().any(|v| v.abs() > MAX_POSED_PX) {
            return Err(PoseError::BadDrag(format!(
                "at [{}, {}] to [{}, {}] lies beyond ±{MAX_POSED_PX} px",
                Shown(self.at[0]),
                Shown(self.at[1]),
                Shown(self.to[0]),
                Shown(self.to[1])
            )));
        }
        Ok(())
    }
}

impl Pose {
    /// The checks that need no rig: every number finite and within ±[`MAX_POSE_VALUE`], drags
    /// as [`IkDrag::check`], part colours in [0, 1]. [`crate::rig::handle_transforms`] runs it
    /// first, so every pose is checked where it is posed.
    pub fn check_values(&self) -> Result<(), PoseError> {
        let bad = |name: &str, numbers: &[f64]| {
            if !finite(numbers) {
                Err(PoseError::NonFinite(name.to_string()))
            } else if let Some(v) = numbers.iter().find(|v| v.abs() > MAX_POSE_VALUE) {
                Err(PoseError::TooLarge(name.to_string(), *v))
            } else {
                Ok(())
            }
        };
        for (name, b) in &self.bones {
            let [t0, t1] = b.translate;
            bad(
                name,
                &[
                    b.rotate, t0, t1, b.scale[0], b.scale[1], b.shear[0], b.shear[1],
                ],
            )?;
        }
        for (name, p) in &self.points {
            let [t0, t1] = p.translate;
            bad(
                name,
                &[
                    p.rotate, t0, t1, p.scale[0], p.scale[1], p.shear[0], p.shear[1],
                ],
            )?;
        }
        for (name, c) in &self.cages {
            bad(name, crate::geom::point_numbers(&c.polygon))?;
        }
        for (name, offsets) in &self.deform {
            bad(name, bytemuck::cast_slice(offsets))?;
        }
        for drag in &self.ik {
            drag.check()?;
        }
        for (name, part) in &self.parts {
            if !part.color.iter().all(|c| (0.0..=1.0).contains(c)) {
                return Err(PoseError::Color(name.clone()));
            }
        }
        Ok(())
    }
}

/// How far a posed handle may move anything, px (either sign): no canvas is that large, and
/// beyond it skinning and drawing overflow.
pub const MAX_POSED_PX: f64 = 1e6;
/// How much a posed handle may scale anything.
pub const MAX_POSED_SCALE: f64 = 1e4;

/// Whether `transform` stays within [`MAX_POSED_PX`] and [`MAX_POSED_SCALE`].
pub(super) fn within_reach(transform: &Affine) -> bool {
    transform
        .translation
        .iter()
        .all(|v| v.abs() <= MAX_POSED_PX)
        && transform.linear.iter().all(|v| v.abs() <= MAX_POSED_SCALE)
}

/// A bone's rest frame: origin at the head, x axis along head → tail.
pub fn bone_rest_frame(head: Point, tail: Point) -> Affine {
    Affine {
        linear: rotation(screen_angle_deg(tail - head)),
        translation: head.coords,
    }
}

/// The linear part of a local pose: rotate, then shear, then scale, in Spine's composition.
pub(super) fn local_linear(rotate_deg: f64, scale: [f64; 2], shear_deg: [f64; 2]) -> Matrix2<f64> {
    let x_axis = rotation(rotate_deg + shear_deg[0]) * Vec2::new(scale[0], 0.0);
    let y_axis = rotation(rotate_deg + shear_deg[1]) * Vec2::new(0.0, scale[1]);
    Matrix2::from_columns(&[x_axis, y_axis])
}

pub(super) fn finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}

/// Every bone's posed frame in canvas coordinates (`world_from_bone`), in bone order.
pub fn bone_world_frames(handles: &Handles, pose: &Pose) -> Result<Vec<Affine>, PoseError> {
    check_names(
        "bone",
        pose.bones.keys(),
        handles.bones.iter().map(|b| &b.name),
    )?;
    let index: BTreeMap<&str, usize> = handles
        .bones
        .iter()
        .enumerate()
        .map(|(i, b)| (b.name.as_str(), i))
        .collect();
    let rest: Vec<Affine> = handles
        .bones
        .iter()
        .map(|b| bone_rest_frame(b.head, b.tail))
        .collect();
    let mut world: Vec<Option<Affine>> = vec![None; handles.bones.len()];
    // Validated parents are acyclic: resolving each bone after its ancestors terminates.
    fn resolve(
        i: usize,
        handles: &Handles,
        pose: &Pose,
        index: &BTreeMap<&str, usize>,
        rest: &[Affine],
        world: &mut Vec<Option<Affine>>,
    ) -> Result<Affine, PoseError> {
        if let Some(frame) = world[i] {
            return Ok(frame);
        }
        let bone = &handles.bones[i];
        let parent = bone.parent.as_deref().and_then(|p| index.get(p).copied());
        let (world_from_parent, world_from_parent_rest) = match parent {
            Some(p) => (resolve(p, handles, pose, index, rest, world)?, rest[p]),
            None => (Affine::identity(), Affine::identity()),
        };
        let parent_from_bone_rest = world_from_parent_rest
            .inverse()
            .ok_or_else(|| PoseError::Singular(bone.name.clone()))?
            .then_after(&rest[i]);
        let local = pose.bones.get(&bone.name).cloned().unwrap_or_default();
        if !finite(&[
            local.rotate,
            local.translate[0],
            local.translate[1],
            local.scale[0],
            local.scale[1],
            local.shear[0],
            local.shear[1],
        ]) {
            return Err(PoseError::NonFinite(bone.name.clone()));
        }
        let rest_angle = screen_angle_deg(parent_from_bone_rest.linear.column(0).into());
        let parent_from_bone = Affine {
            linear: local_linear(rest_angle + local.rotate, local.scale, local.shear),
            translation: parent_from_bone_rest.translation
                + Vec2::new(local.translate[0], local.translate[1]),
        };
        let frame = world_from_parent.then_after(&parent_from_bone);
        world[i] = Some(frame);
        Ok(frame)
    }
    (0..handles.bones.len())
        .map(|i| resolve(i, handles, pose, &index, &rest, &mut world))
        .collect()
}

/// Fails on the first name the pose uses that the rig lacks.
pub(super) fn check_names<'a>(
    kind: &'static str,
    posed: impl Iterator<Item = &'a String>,
    known: impl Iterator<Item = &'a String> + Clone,
) -> Result<(), PoseError> {
    for name in posed {
        if !known.clone().any(|k| k == name) {
            return Err(PoseError::UnknownName {
                kind,
                name: name.clone(),
            });
        }
    }
    Ok(())
}
