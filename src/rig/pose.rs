//! Poses and forward kinematics over the bone forest.
//!
//! In: validated [`Handles`] and a [`Pose`] (the pose file of `docs/formats.md`). Out: one affine
//! [`Affine`] per handle that maps rest canvas positions to posed canvas positions — the
//! transformations skinning blends. The pose model and the bone frames live in
//! [`super::frames`] (re-exported here), below [`super::bone_ik`], which this module calls.
//! Bone frames, local poses and angles follow Spine's conventions (see [`super::frames`]).

pub use super::frames::{
    bone_rest_frame, bone_world_frames, rotation, screen_angle_deg, Affine, BonePose, CagePose,
    IkDrag, PartPose, PointPose, Pose, PoseError, MAX_POSED_PX, MAX_POSED_SCALE, MAX_POSE_VALUE,
};
use super::frames::{check_names, finite, local_linear, within_reach};
use super::handles::Handles;
use crate::geom::{Point, Vec2};
use nalgebra::Matrix2;
use std::collections::BTreeMap;

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
        let (head, tail) = (bone.head, bone.tail);
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
    pose.check_values()?;
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
    for (i, point) in handles.points.iter().enumerate() {
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
        // A point carried by a bone moves as it does: a default local pose is its parent's
        // transformation exactly (as a bone's is).
        let world_from_parent = handles.point_parent(i).map(|b| out[b]);
        if p == PointPose::default() {
            out.push(world_from_parent.unwrap_or_else(Affine::identity));
            continue;
        }
        // About the rest position: move there, turn and scale, move back, then translate.
        let at = point.at.coords;
        let linear = local_linear(p.rotate, p.scale, p.shear);
        let local = Affine {
            linear,
            translation: at - linear * at + Vec2::new(p.translate[0], p.translate[1]),
        };
        out.push(match world_from_parent {
            Some(parent) => parent.then_after(&local),
            None => local,
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
                if !finite(crate::geom::point_numbers(&posed.polygon)) {
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
    for (i, point) in handles.points.iter().enumerate() {
        // A carried point's pose is about its parent's motion: local = parent⁻¹ · transform.
        let carried;
        let t = match handles.point_parent(i) {
            Some(b) => {
                carried = transforms[b]
                    .inverse()
                    .ok_or_else(|| PoseError::Singular(handles.bones[b].name.clone()))?
                    .then_after(&transforms[j]);
                &carried
            }
            None => &transforms[j],
        };
        let (rotate, scale, shear) =
            decompose_linear(&t.linear).ok_or_else(|| PoseError::Singular(point.name.clone()))?;
        let at = point.at.coords;
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
            .map(|(k, &v)| transforms[j + k].apply(v))
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
                    head: Point::new(0.0, 0.0),
                    tail: Point::new(10.0, 0.0),
                },
                Bone {
                    name: "lower".into(),
                    parent: Some("upper".into()),
                    head: Point::new(10.0, 0.0),
                    tail: Point::new(20.0, 0.0),
                },
            ],
            points: vec![PointHandle {
                name: "p".into(),
                at: Point::new(5.0, 5.0),
                parent: None,
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
                head: Point::new(0.0, 0.0),
                tail: Point::new(0.0, 10.0),
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
    fn a_carried_point_moves_as_its_bone_then_by_its_own_pose() {
        let mut handles = arm();
        handles.points[0].parent = Some("lower".into());
        let mut pose = Pose::default();
        pose.bones.insert(
            "upper".into(),
            BonePose {
                rotate: 90.0,
                ..Default::default()
            },
        );
        let t = handle_transforms(&handles, &pose).unwrap();
        // Unposed, it is its parent's transformation, bit for bit.
        assert_eq!(t[2], t[1]);
        assert!(close(t[2].apply(Point::new(5.0, 5.0)), [5.0, -5.0]));
        // Its own pose applies at rest, before the bone's motion: +x at rest is up on screen.
        pose.points.insert(
            "p".into(),
            PointPose {
                translate: [2.0, 0.0],
                rotate: 30.0,
                ..Default::default()
            },
        );
        let t = handle_transforms(&handles, &pose).unwrap();
        assert!(close(t[2].apply(Point::new(5.0, 5.0)), [5.0, -7.0]));
        // Back from the transformations, about the parent: the same pose.
        let back = pose_from_transforms(&handles, &t).unwrap();
        let p = &back.points["p"];
        assert!((p.translate[0] - 2.0).abs() < 1e-9 && p.translate[1].abs() < 1e-9);
        assert!((p.rotate - 30.0).abs() < 1e-9);
        // Loose, the same pose ignores the bones.
        handles.points[0].parent = None;
        let t = handle_transforms(&handles, &pose).unwrap();
        assert!(close(t[2].apply(Point::new(5.0, 5.0)), [7.0, 5.0]));
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
                Some(PoseError::TooLarge("upper".into(), 1e300))
            );
        }
        // Within the numbers' limit, but the posed transformation goes beyond its own.
        let mut far = Pose::default();
        far.bones.insert(
            "upper".into(),
            BonePose {
                scale: [MAX_POSE_VALUE, 1.0],
                ..Default::default()
            },
        );
        assert_eq!(
            handle_transforms(&arm(), &far).err(),
            Some(PoseError::OutOfRange("upper".into()))
        );
    }
}
