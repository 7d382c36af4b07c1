//! The Spine skeleton of a rig: every sinew handle becomes a Spine bone.
//!
//! In: validated [`Handles`], the [`SpineFrame`] and the root bone's name. Out: a
//! [`Skeleton`]: bones in an order where parents come before children (the runtime resolves a
//! parent only among bones already read), each with its setup-pose [`BoneLocal`] and
//! world transform (Spine world units, y up), and for every weight column of the rig
//! ([`handle_columns`]) the bone that carries it.
//!
//! Layout: one root bone at Spine's origin; under it every bone forest of the rig (disjoint
//! skeletons stay disjoint below the root), each sinew bone with its head as origin and its x axis
//! along head → tail (sinew's bone frames already follow Spine's conventions); then one
//! zero-length bone per point handle (at the point, with the world's axes at rest; a child of
//! the bone that carries it, or of the root), per cage vertex (named `cage.k`, as its weight
//! column) and per region (at its first polygon vertex), both children of the root.

use super::frame::{BoneLocal, SpineFrame};
use super::SpineError;
use crate::geom::Point;
use crate::rig::pose::bone_rest_frame;
use crate::rig::{handle_columns, Affine, Handles};
use std::collections::HashMap;

/// What a Spine bone stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoneSource {
    Root,
    /// Index into `handles.bones`.
    Bone(usize),
    /// Index into `handles.points`.
    Point(usize),
    CageVertex {
        cage: usize,
        vertex: usize,
    },
    /// Index into `handles.regions`.
    Region(usize),
}

/// One bone of the export.
#[derive(Clone, Debug, PartialEq)]
pub struct SpineBone {
    pub name: String,
    /// Index of the parent among the skeleton's bones (always smaller than this bone's).
    pub parent: Option<usize>,
    /// Length along the bone's x axis (px); 0 for handles that are points.
    pub length: f64,
    pub setup: BoneLocal,
    /// Setup-pose world transform (Spine world, y up): bone-local → world.
    pub setup_world: Affine,
    pub source: BoneSource,
    /// The handle column this bone carries (`None` for the root).
    pub column: Option<usize>,
}

/// The bones of an export.
#[derive(Clone, Debug, PartialEq)]
pub struct Skeleton {
    pub bones: Vec<SpineBone>,
    /// For each handle column (in [`handle_columns`] order), the index of its bone.
    pub column_bone: Vec<usize>,
}

impl Skeleton {
    /// The bones that descend from `bone` (itself excluded), in skeleton order.
    pub fn descendants(&self, bone: usize) -> Vec<usize> {
        let mut inside = vec![false; self.bones.len()];
        inside[bone] = true;
        let mut out = Vec::new();
        for (i, b) in self.bones.iter().enumerate().skip(bone + 1) {
            if b.parent.is_some_and(|p| inside[p]) {
                inside[i] = true;
                out.push(i);
            }
        }
        out
    }
}

/// The setup pose, local to `parent`, of a bone at `origin` (Spine world) whose x axis points
/// at `world_rotation_deg`. Every setup frame is a rotation and a translation (unscaled,
/// unsheared), so the local one is too: the relative rotation alone, as sinew's pose computes
/// it.
fn setup_under(
    parent: &SpineBone,
    origin: Point,
    world_rotation_deg: f64,
) -> Result<BoneLocal, SpineError> {
    let world = BoneLocal {
        x: origin[0],
        y: origin[1],
        rotation_deg: world_rotation_deg,
        ..Default::default()
    }
    .matrix();
    let local = parent
        .setup_world
        .inverse()
        .ok_or_else(|| SpineError::Singular(parent.name.clone()))?
        .then_after(&world);
    Ok(BoneLocal {
        x: local.translation.x,
        y: local.translation.y,
        rotation_deg: local.linear[(1, 0)]
            .atan2(local.linear[(0, 0)])
            .to_degrees(),
        ..Default::default()
    })
}

/// Builds the skeleton; fails on a handle name that collides with the root's or a cage
/// vertex's generated name (`cage.k`).
pub fn build_skeleton(
    handles: &Handles,
    frame: &SpineFrame,
    root_name: &str,
) -> Result<Skeleton, SpineError> {
    let columns = handle_columns(handles);
    let mut column_index: HashMap<&str, usize> = HashMap::new();
    for (j, name) in columns.iter().enumerate() {
        if name == root_name || column_index.insert(name.as_str(), j).is_some() {
            return Err(SpineError::NameTaken { name: name.clone() });
        }
    }
    let mut bones = vec![SpineBone {
        name: root_name.to_string(),
        parent: None,
        length: 0.0,
        setup: BoneLocal::default(),
        setup_world: Affine::identity(),
        source: BoneSource::Root,
        column: None,
    }];
    let mut column_bone = vec![usize::MAX; columns.len()];

    // Bone forests, parents first: depth-first from each sinew root in file order.
    let children = |parent: Option<&str>| -> Vec<usize> {
        (0..handles.bones.len())
            .filter(|&i| handles.bones[i].parent.as_deref() == parent)
            .collect()
    };
    let mut stack: Vec<(usize, usize)> = children(None).into_iter().rev().map(|i| (i, 0)).collect();
    while let Some((i, parent)) = stack.pop() {
        let bone = &handles.bones[i];
        // The bone's rest frame (canvas) seen in Spine's world: head at its Spine position,
        // x axis along head → tail.
        let rest = bone_rest_frame(bone.head, bone.tail);
        let dir = rest.linear.column(0);
        let world_rotation_deg = (-dir[1]).atan2(dir[0]).to_degrees();
        let head = frame.spine_from_canvas(bone.head);
        let parent_world = bones[parent].setup_world;
        let setup = setup_under(&bones[parent], head, world_rotation_deg)?;
        let index = bones.len();
        let column = column_index[bone.name.as_str()];
        column_bone[column] = index;
        bones.push(SpineBone {
            name: bone.name.clone(),
            parent: Some(parent),
            length: ((bone.tail[0] - bone.head[0]).powi(2) + (bone.tail[1] - bone.head[1]).powi(2))
                .sqrt(),
            setup_world: parent_world.then_after(&setup.matrix()),
            setup,
            source: BoneSource::Bone(i),
            column: Some(column),
        });
        for child in children(Some(&bone.name)).into_iter().rev() {
            stack.push((child, index));
        }
    }

    // A point's bone: world axes at rest, origin at the point, under the Spine bone of sinew
    // bone `carrier` (placed above: bones come before points), or the root.
    let mut point_bone = |name: String,
                          at: Point,
                          source: BoneSource,
                          carrier: Option<usize>|
     -> Result<(), SpineError> {
        let parent = carrier
            .map(|b| column_bone[b])
            .filter(|&k| k < bones.len())
            .unwrap_or(0);
        let parent_world = bones[parent].setup_world;
        let setup = setup_under(&bones[parent], frame.spine_from_canvas(at), 0.0)?;
        let column = column_index[name.as_str()];
        column_bone[column] = bones.len();
        bones.push(SpineBone {
            name,
            parent: Some(parent),
            length: 0.0,
            setup_world: parent_world.then_after(&setup.matrix()),
            setup,
            source,
            column: Some(column),
        });
        Ok(())
    };
    for (i, point) in handles.points.iter().enumerate() {
        let carrier = handles.point_parent(i);
        point_bone(point.name.clone(), point.at, BoneSource::Point(i), carrier)?;
    }
    for (c, cage) in handles.cages.iter().enumerate() {
        for (k, at) in cage.polygon.iter().enumerate() {
            point_bone(
                format!("{}.{k}", cage.name),
                *at,
                BoneSource::CageVertex { cage: c, vertex: k },
                None,
            )?;
        }
    }
    for (i, region) in handles.regions.iter().enumerate() {
        let at = region
            .polygon
            .first()
            .copied()
            .unwrap_or_else(Point::origin);
        point_bone(region.name.clone(), at, BoneSource::Region(i), None)?;
    }
    if let Some(j) = column_bone.iter().position(|&b| b == usize::MAX) {
        // Only a bone whose parent chain never reaches a root is left out; validation
        // rejects cycles, so this names a rig that skipped validation.
        return Err(SpineError::Singular(columns[j].clone()));
    }
    Ok(Skeleton { bones, column_bone })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::rig::pose::{handle_transforms, BonePose, Pose};
    use crate::rig::{Bone, Cage, PointHandle};

    fn handles() -> Handles {
        Handles {
            bones: vec![
                // A child listed before its parent, and two skeletons.
                Bone {
                    name: "lower".into(),
                    parent: Some("upper".into()),
                    head: Point::new(60.0, 40.0),
                    tail: Point::new(60.0, 80.0),
                },
                Bone {
                    name: "upper".into(),
                    parent: None,
                    head: Point::new(20.0, 40.0),
                    tail: Point::new(60.0, 40.0),
                },
                Bone {
                    name: "other".into(),
                    parent: None,
                    head: Point::new(90.0, 90.0),
                    tail: Point::new(80.0, 70.0),
                },
            ],
            points: vec![PointHandle {
                name: "p".into(),
                at: Point::new(5.0, 6.0),
                parent: None,
            }],
            cages: vec![Cage {
                name: "c".into(),
                polygon: vec![
                    Point::new(0.0, 0.0),
                    Point::new(10.0, 0.0),
                    Point::new(10.0, 10.0),
                ],
            }],
            ..Default::default()
        }
    }

    #[test]
    fn parents_come_first_and_every_column_has_a_bone() {
        let frame = SpineFrame::for_canvas([100, 100]);
        let s = build_skeleton(&handles(), &frame, "root").unwrap();
        let names: Vec<&str> = s.bones.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(
            names,
            ["root", "upper", "lower", "other", "p", "c.0", "c.1", "c.2"]
        );
        for (i, b) in s.bones.iter().enumerate() {
            assert!(b.parent.is_none_or(|p| p < i));
        }
        assert_eq!(s.column_bone, vec![2, 1, 3, 4, 5, 6, 7]);
        assert_eq!(s.descendants(1), vec![2]);
        // Lower points down on screen: −90° in world, −90° relative to upper (pointing right).
        assert!((s.bones[2].setup.rotation_deg + 90.0).abs() < 1e-12);
        assert!((s.bones[2].setup.x - 40.0).abs() < 1e-12 && s.bones[2].setup.y.abs() < 1e-12);
        assert_eq!(s.bones[2].length, 40.0);
    }

    #[test]
    fn spine_forward_kinematics_matches_sinew_pose() {
        // Pose upper and lower; Spine's FK with rotate added to the setup rotation must move
        // points exactly as sinew's skinning transforms do.
        let h = handles();
        let frame = SpineFrame::for_canvas([100, 100]);
        let s = build_skeleton(&h, &frame, "root").unwrap();
        let mut pose = Pose::default();
        pose.bones.insert(
            "upper".into(),
            BonePose {
                rotate: 30.0,
                translate: [2.0, 3.0],
                ..Default::default()
            },
        );
        pose.bones.insert(
            "lower".into(),
            BonePose {
                rotate: -50.0,
                scale: [1.5, 0.5],
                shear: [0.0, 10.0],
                ..Default::default()
            },
        );
        let t = handle_transforms(&h, &pose).unwrap();
        let mut world: Vec<Affine> = Vec::new();
        for b in &s.bones {
            let mut local = b.setup;
            if let BoneSource::Bone(i) = b.source {
                if let Some(p) = pose.bones.get(&h.bones[i].name) {
                    local.rotation_deg += p.rotate;
                    let v = frame.spine_vector(p.translate.into());
                    local.x += v[0];
                    local.y += v[1];
                    local.scale_x *= p.scale[0];
                    local.scale_y *= p.scale[1];
                    local.shear_x_deg += p.shear[0];
                    local.shear_y_deg += p.shear[1];
                }
            }
            let parent = b.parent.map_or(Affine::identity(), |p| world[p]);
            world.push(parent.then_after(&local.matrix()));
        }
        let rest_point = Point::new(63.0, 70.0);
        for (bone, column) in [(1, 1), (2, 0)] {
            let bind = s.bones[bone]
                .setup_world
                .inverse()
                .unwrap()
                .apply(frame.spine_from_canvas(rest_point));
            let spine = world[bone].apply(bind);
            let sinew = t[column].apply(Point::from(rest_point));
            let back = frame.canvas_from_spine(spine);
            assert!((back[0] - sinew.x).abs() < 1e-9 && (back[1] - sinew.y).abs() < 1e-9);
        }
    }

    #[test]
    fn a_carried_point_hangs_from_its_bone_with_the_worlds_axes_at_rest() {
        let mut h = handles();
        // "lower" points down the screen: −90° in Spine's world.
        h.points[0].parent = Some("lower".into());
        let frame = SpineFrame::for_canvas([100, 100]);
        let s = build_skeleton(&h, &frame, "root").unwrap();
        let point = &s.bones[s.column_bone[3]];
        let lower = s.bones.iter().position(|b| b.name == "lower").unwrap();
        assert_eq!(point.parent, Some(lower));
        assert!(
            (point.setup.rotation_deg - 90.0).abs() < 1e-9,
            "{:?}",
            point.setup
        );
        assert!((point.setup_world.linear - nalgebra::Matrix2::identity()).norm() < 1e-12);
        let at = frame.spine_from_canvas(Point::new(5.0, 6.0));
        assert!((point.setup_world.translation - at.coords).norm() < 1e-9);
    }

    #[test]
    fn a_handle_named_like_the_root_is_refused() {
        let mut h = handles();
        h.points[0].name = "root".into();
        let frame = SpineFrame::for_canvas([100, 100]);
        assert!(matches!(
            build_skeleton(&h, &frame, "root"),
            Err(SpineError::NameTaken { .. })
        ));
    }
}
