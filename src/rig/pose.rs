//! Poses and forward kinematics over the bone forest.
//!
//! In: validated [`Handles`] and a [`Pose`] (the pose file of `docs/formats.md`). Out: one affine
//! [`Affine`] per handle that maps rest canvas positions to posed canvas positions — the
//! transformations skinning blends.
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

/// A point handle's pose: about its rest position, in canvas axes.
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
    pub polygon: Vec<[f64; 2]>,
}

/// A drag for skinning IK: the material point at rest position `at` goes to `to` (canvas px).
/// Without a `weight` the drag is a hard constraint (met exactly when feasible); with one it is
/// a soft pull of that strength (1 ≈ the stiffness of moving one handle).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct IkDrag {
    pub at: [f64; 2],
    pub to: [f64; 2],
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
}

impl Default for PartPose {
    fn default() -> Self {
        PartPose {
            color: [1.0, 1.0, 1.0, 1.0],
            visible: true,
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
    #[error("the pose of '{0}' makes its transformation singular (a zero scale?)")]
    Singular(String),
    #[error(
        "the pose of '{0}' moves it beyond ±{MAX_POSED_PX} px or scales it by more than \
         {MAX_POSED_SCALE}"
    )]
    OutOfRange(String),
}

/// How far a posed handle may move anything, px (either sign): no canvas is that large, and
/// beyond it skinning and drawing overflow.
pub const MAX_POSED_PX: f64 = 1e6;
/// How much a posed handle may scale anything.
pub const MAX_POSED_SCALE: f64 = 1e4;

/// Whether `transform` stays within [`MAX_POSED_PX`] and [`MAX_POSED_SCALE`].
fn within_reach(transform: &Affine) -> bool {
    transform
        .translation
        .iter()
        .all(|v| v.abs() <= MAX_POSED_PX)
        && transform.linear.iter().all(|v| v.abs() <= MAX_POSED_SCALE)
}

/// A bone's rest frame: origin at the head, x axis along head → tail.
pub fn bone_rest_frame(head: [f64; 2], tail: [f64; 2]) -> Affine {
    let direction = Vec2::new(tail[0] - head[0], tail[1] - head[1]);
    Affine {
        linear: rotation(screen_angle_deg(direction)),
        translation: Vec2::new(head[0], head[1]),
    }
}

/// The linear part of a local pose: rotate, then shear, then scale, in Spine's composition.
fn local_linear(rotate_deg: f64, scale: [f64; 2], shear_deg: [f64; 2]) -> Matrix2<f64> {
    let x_axis = rotation(rotate_deg + shear_deg[0]) * Vec2::new(scale[0], 0.0);
    let y_axis = rotation(rotate_deg + shear_deg[1]) * Vec2::new(0.0, scale[1]);
    Matrix2::from_columns(&[x_axis, y_axis])
}

fn finite(values: &[f64]) -> bool {
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
fn check_names<'a>(
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

/// Every bone's skinning transformation (rest canvas → posed canvas), in bone order.
///
/// A bone left at its default local pose moves exactly as its parent (a root stays exactly
/// put), so a pose that names nothing reproduces the rest mesh bit for bit; the general
/// formula `world_from_bone · (world_from_bone_rest)⁻¹` would only cancel up to rounding.
fn bone_transforms(handles: &Handles, pose: &Pose) -> Result<Vec<Affine>, PoseError> {
    let world = bone_world_frames(handles, pose)?;
    let index: BTreeMap<&str, usize> = handles
        .bones
        .iter()
        .enumerate()
        .map(|(i, b)| (b.name.as_str(), i))
        .collect();
    let mut out: Vec<Option<Affine>> = vec![None; handles.bones.len()];
    // Parents are acyclic (validated, and checked again by bone_world_frames): each pass
    // settles at least one more bone.
    while out.iter().any(Option::is_none) {
        for (i, bone) in handles.bones.iter().enumerate() {
            if out[i].is_some() {
                continue;
            }
            let parent = match bone.parent.as_deref().and_then(|p| index.get(p)) {
                Some(&p) => match out[p] {
                    Some(t) => t,
                    None => continue,
                },
                None => Affine::identity(),
            };
            let is_default = pose
                .bones
                .get(&bone.name)
                .is_none_or(|local| *local == BonePose::default());
            out[i] = Some(if is_default {
                parent
            } else {
                let rest_inverse = bone_rest_frame(bone.head, bone.tail)
                    .inverse()
                    .ok_or_else(|| PoseError::Singular(bone.name.clone()))?;
                world[i].then_after(&rest_inverse)
            });
        }
    }
    Ok(out.into_iter().flatten().collect())
}

/// How a bone scaled along its length stretches a limb instead of scaling it (Jacobson &
/// Sorkine 2011, "Stretchable and Twistable Bones for Skeletal Shape Deformation"): a vertex
/// moves by the bone's rigid motion plus the stretch of its tail times its endpoint weight —
/// its position along the bone, 0 at the head and 1 at the tail, clamped — so what lies past the
/// tail is carried along, not enlarged.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoneStretch {
    /// The bone's skinning transformation without its own along-bone scale.
    pub rigid: Affine,
    /// Where the scale moves the tail, beyond where the rigid part puts it (px).
    pub stretch: Vec2,
    /// The rest head, and the rest head → tail vector divided by its squared length.
    pub head: Point,
    pub axis_per_length2: Vec2,
}

impl BoneStretch {
    /// The endpoint weight of a rest position: its parameter along the bone, clamped to [0, 1].
    pub fn endpoint_weight(&self, p: Point) -> f64 {
        (p - self.head).dot(&self.axis_per_length2).clamp(0.0, 1.0)
    }
}

/// Per bone, its stretch when its pose scales it along its length (`scale[0] ≠ 1`).
pub fn bone_stretches(
    handles: &Handles,
    pose: &Pose,
) -> Result<Vec<Option<BoneStretch>>, PoseError> {
    bone_stretches_under(handles, pose, &bone_transforms(handles, pose)?)
}

/// [`bone_stretches`] for given skinning `transforms` (bones first, e.g. solved by the skinning
/// IK): the along-bone scale comes from the pose, everything else from the transforms.
pub fn bone_stretches_under(
    handles: &Handles,
    pose: &Pose,
    transforms: &[Affine],
) -> Result<Vec<Option<BoneStretch>>, PoseError> {
    let mut out = Vec::with_capacity(handles.bones.len());
    for (bone, t) in handles.bones.iter().zip(transforms) {
        let scale_along = pose.bones.get(&bone.name).map_or(1.0, |p| p.scale[0]);
        if scale_along == 1.0 || scale_along == 0.0 {
            out.push(None);
            continue;
        }
        let rest = bone_rest_frame(bone.head, bone.tail);
        let rest_inverse = rest
            .inverse()
            .ok_or_else(|| PoseError::Singular(bone.name.clone()))?;
        // world_from_bone = t · rest; dropping the bone's own x scale is a right factor there.
        let world = t.then_after(&rest);
        let unscale = Affine {
            linear: Matrix2::from_diagonal(&Vec2::new(1.0 / scale_along, 1.0)),
            translation: Vec2::zeros(),
        };
        let rigid = world.then_after(&unscale).then_after(&rest_inverse);
        let (head, tail) = (
            Point::new(bone.head[0], bone.head[1]),
            Point::new(bone.tail[0], bone.tail[1]),
        );
        let axis = tail - head;
        out.push(Some(BoneStretch {
            rigid,
            stretch: t.apply(tail) - rigid.apply(tail),
            head,
            axis_per_length2: axis / axis.norm_squared(),
        }));
    }
    Ok(out)
}

/// One skinning transformation per handle column, in [`Handles::names`]' order expanded as
/// [`handle_columns`] lists them: bones, points, cage vertices, regions (regions stay at rest
/// unless IK moves them). The rig's bone IK constraints apply first.
pub fn handle_transforms(handles: &Handles, pose: &Pose) -> Result<Vec<Affine>, PoseError> {
    let constrained;
    let pose = if handles.ik.is_empty() {
        pose
    } else {
        constrained = super::bone_ik::constrained_pose(handles, pose)?;
        &constrained
    };
    let mut out = bone_transforms(handles, pose)?;
    check_names(
        "point",
        pose.points.keys(),
        handles.points.iter().map(|p| &p.name),
    )?;
    for point in &handles.points {
        let p = pose.points.get(&point.name).cloned().unwrap_or_default();
        if !finite(&[
            p.translate[0],
            p.translate[1],
            p.rotate,
            p.scale[0],
            p.scale[1],
            p.shear[0],
            p.shear[1],
        ]) {
            return Err(PoseError::NonFinite(point.name.clone()));
        }
        // About the rest position: move there, turn and scale, move back, then translate.
        let at = Vec2::new(point.at[0], point.at[1]);
        let linear = local_linear(p.rotate, p.scale, p.shear);
        out.push(Affine {
            linear,
            translation: at - linear * at + Vec2::new(p.translate[0], p.translate[1]),
        });
    }
    check_names(
        "cage",
        pose.cages.keys(),
        handles.cages.iter().map(|c| &c.name),
    )?;
    for cage in &handles.cages {
        match pose.cages.get(&cage.name) {
            Some(posed) => {
                if posed.polygon.len() != cage.polygon.len() {
                    return Err(PoseError::CageSize {
                        name: cage.name.clone(),
                        got: posed.polygon.len(),
                        expected: cage.polygon.len(),
                    });
                }
                if !finite(&posed.polygon.iter().flatten().copied().collect::<Vec<_>>()) {
                    return Err(PoseError::NonFinite(cage.name.clone()));
                }
                for (rest, to) in cage.polygon.iter().zip(&posed.polygon) {
                    out.push(Affine::translation(Vec2::new(
                        to[0] - rest[0],
                        to[1] - rest[1],
                    )));
                }
            }
            None => out.extend(cage.polygon.iter().map(|_| Affine::identity())),
        }
    }
    out.extend(handles.regions.iter().map(|_| Affine::identity()));
    // Names are built only for a failure: this runs every frame and every drag.
    if let Some(column) = out.iter().position(|t| !within_reach(t)) {
        let name = handle_columns(handles).swap_remove(column);
        return Err(PoseError::OutOfRange(name));
    }
    Ok(out)
}

/// The pose whose forward kinematics gives `transforms` (one per handle column, as
/// [`handle_transforms`] returns them): the inverse of forward kinematics, for baking solved
/// transformations into keys. Bones get rotate, translate, scale and shear with shear x = 0
/// (any affine map with a non-zero determinant has such a form); points likewise about their rest
/// position; cages get the polygon their vertices' translations make (exact for translation-only
/// cage vertices, the default). Regions have no pose and are left out. Constrained bones (bone
/// IK) are baked like any other, so the result needs no constraint to reproduce them.
pub fn pose_from_transforms(handles: &Handles, transforms: &[Affine]) -> Result<Pose, PoseError> {
    let mut pose = Pose::default();
    let rest: Vec<Affine> = handles
        .bones
        .iter()
        .map(|b| bone_rest_frame(b.head, b.tail))
        .collect();
    let index = |name: &str| handles.bones.iter().position(|b| b.name == name);
    for (i, bone) in handles.bones.iter().enumerate() {
        let singular = || PoseError::Singular(bone.name.clone());
        let world_from_bone = transforms[i].then_after(&rest[i]);
        let (world_from_parent, parent_from_bone_rest) =
            match bone.parent.as_deref().and_then(index) {
                Some(p) => (
                    transforms[p].then_after(&rest[p]),
                    rest[p].inverse().ok_or_else(singular)?.then_after(&rest[i]),
                ),
                None => (Affine::identity(), rest[i]),
            };
        let parent_from_bone = world_from_parent
            .inverse()
            .ok_or_else(singular)?
            .then_after(&world_from_bone);
        let rest_angle = screen_angle_deg(parent_from_bone_rest.linear.column(0).into());
        let (rotate, scale, shear) =
            decompose_linear(&parent_from_bone.linear).ok_or_else(singular)?;
        let offset = parent_from_bone.translation - parent_from_bone_rest.translation;
        pose.bones.insert(
            bone.name.clone(),
            BonePose {
                rotate: wrap_deg(rotate - rest_angle),
                translate: [offset.x, offset.y],
                scale,
                shear,
            },
        );
    }
    let mut j = handles.bones.len();
    for point in &handles.points {
        let t = &transforms[j];
        let (rotate, scale, shear) =
            decompose_linear(&t.linear).ok_or_else(|| PoseError::Singular(point.name.clone()))?;
        let at = Vec2::new(point.at[0], point.at[1]);
        let translate = t.translation - at + t.linear * at;
        pose.points.insert(
            point.name.clone(),
            PointPose {
                translate: [translate.x, translate.y],
                rotate,
                scale,
                shear,
            },
        );
        j += 1;
    }
    for cage in &handles.cages {
        let polygon = cage
            .polygon
            .iter()
            .enumerate()
            .map(|(k, v)| {
                let p = transforms[j + k].apply(Point::new(v[0], v[1]));
                [p.x, p.y]
            })
            .collect();
        pose.cages.insert(cage.name.clone(), CagePose { polygon });
        j += cage.polygon.len();
    }
    Ok(pose)
}

fn wrap_deg(a: f64) -> f64 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}

/// (rotate°, scale, shear°) with shear x = 0 such that [`local_linear`] gives back `l`, or `None`
/// for a singular `l`. A reflection gets a negative y scale.
fn decompose_linear(l: &Matrix2<f64>) -> Option<(f64, [f64; 2], [f64; 2])> {
    let (x, y) = (
        Vec2::new(l[(0, 0)], l[(1, 0)]),
        Vec2::new(l[(0, 1)], l[(1, 1)]),
    );
    let det = l.determinant();
    if x.norm() == 0.0 || det == 0.0 || !det.is_finite() {
        return None;
    }
    let rotate = screen_angle_deg(x);
    let (sy, y_dir) = if det < 0.0 {
        (-y.norm(), -y)
    } else {
        (y.norm(), y)
    };
    // rotation(θ)·(0, 1) points at screen angle θ − 90°.
    let shear_y = wrap_deg(screen_angle_deg(y_dir) + 90.0 - rotate);
    Some((rotate, [x.norm(), sy], [0.0, shear_y]))
}

/// The weight columns of a rig, in order: each bone, each point, each cage vertex
/// (`cage.0`, `cage.1`, …), each region.
pub fn handle_columns(handles: &Handles) -> Vec<String> {
    let mut names: Vec<String> = handles.bones.iter().map(|b| b.name.clone()).collect();
    names.extend(handles.points.iter().map(|p| p.name.clone()));
    for cage in &handles.cages {
        names.extend((0..cage.polygon.len()).map(|k| format!("{}.{k}", cage.name)));
    }
    names.extend(handles.regions.iter().map(|r| r.name.clone()));
    names
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::{Bone, PointHandle};

    fn arm() -> Handles {
        Handles {
            bones: vec![
                Bone {
                    name: "upper".into(),
                    parent: None,
                    head: [0.0, 0.0],
                    tail: [10.0, 0.0],
                },
                Bone {
                    name: "lower".into(),
                    parent: Some("upper".into()),
                    head: [10.0, 0.0],
                    tail: [20.0, 0.0],
                },
            ],
            points: vec![PointHandle {
                name: "p".into(),
                at: [5.0, 5.0],
            }],
            ..Default::default()
        }
    }

    fn close(a: Point, b: [f64; 2]) -> bool {
        (a.x - b[0]).abs() < 1e-9 && (a.y - b[1]).abs() < 1e-9
    }

    #[test]
    fn rest_pose_is_identity() {
        for t in handle_transforms(&arm(), &Pose::default()).unwrap() {
            assert!(close(t.apply(Point::new(3.0, -7.0)), [3.0, -7.0]));
        }
    }

    #[test]
    fn rotating_the_parent_carries_the_child_counter_clockwise_on_screen() {
        let mut pose = Pose::default();
        pose.bones.insert(
            "upper".into(),
            BonePose {
                rotate: 90.0,
                ..Default::default()
            },
        );
        let t = handle_transforms(&arm(), &pose).unwrap();
        // Counter-clockwise on screen with y down: +x turns to −y (up).
        assert!(close(t[0].apply(Point::new(10.0, 0.0)), [0.0, -10.0]));
        assert!(close(t[1].apply(Point::new(20.0, 0.0)), [0.0, -20.0]));
        // The child's own rotation turns about its (moved) head.
        pose.bones.insert(
            "lower".into(),
            BonePose {
                rotate: -90.0,
                ..Default::default()
            },
        );
        let t = handle_transforms(&arm(), &pose).unwrap();
        assert!(close(t[1].apply(Point::new(20.0, 0.0)), [10.0, -10.0]));
    }

    #[test]
    fn scale_is_along_the_bone_and_translate_in_the_parent_frame() {
        let handles = Handles {
            bones: vec![Bone {
                name: "b".into(),
                parent: None,
                head: [0.0, 0.0],
                tail: [0.0, 10.0],
            }],
            ..Default::default()
        };
        let mut pose = Pose::default();
        pose.bones.insert(
            "b".into(),
            BonePose {
                scale: [2.0, 1.0],
                translate: [3.0, 0.0],
                ..Default::default()
            },
        );
        let t = handle_transforms(&handles, &pose).unwrap();
        assert!(close(t[0].apply(Point::new(0.0, 10.0)), [3.0, 20.0]));
        assert!(close(t[0].apply(Point::new(1.0, 0.0)), [4.0, 0.0]));
    }

    #[test]
    fn point_pose_and_errors() {
        let mut pose = Pose::default();
        pose.points.insert(
            "p".into(),
            PointPose {
                rotate: 180.0,
                translate: [1.0, 0.0],
                ..Default::default()
            },
        );
        let t = handle_transforms(&arm(), &pose).unwrap();
        let back = handle_transforms(&arm(), &pose_from_transforms(&arm(), &t).unwrap()).unwrap();
        assert!(t
            .iter()
            .zip(&back)
            .all(|(a, b)| (a.linear - b.linear).norm() < 1e-12
                && (a.translation - b.translation).norm() < 1e-9));
        assert!(close(t[2].apply(Point::new(5.0, 5.0)), [6.0, 5.0]));
        assert!(close(t[2].apply(Point::new(6.0, 5.0)), [5.0, 5.0]));
        pose.bones.insert("nope".into(), BonePose::default());
        assert!(matches!(
            handle_transforms(&arm(), &pose),
            Err(PoseError::UnknownName { .. })
        ));
        let mut nan = Pose::default();
        nan.bones.insert(
            "upper".into(),
            BonePose {
                rotate: f64::NAN,
                ..Default::default()
            },
        );
        assert!(matches!(
            handle_transforms(&arm(), &nan),
            Err(PoseError::NonFinite(_))
        ));
        // Finite but absurd: thrown a light-year away, or scaled beyond any canvas.
        for local in [
            BonePose {
                translate: [1e300, 0.0],
                ..Default::default()
            },
            BonePose {
                scale: [1e300, 1.0],
                ..Default::default()
            },
        ] {
            let mut far = Pose::default();
            far.bones.insert("upper".into(), local);
            assert_eq!(
                handle_transforms(&arm(), &far).err(),
                Some(PoseError::OutOfRange("upper".into()))
            );
        }
    }
}
