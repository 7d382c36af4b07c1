//! Forward-kinematics edits of one handle from pointer motion: grab, rotate, scale.
//!
//! In: the rig's [`Handles`], the [`Pose`] being edited, the transforms the editor shows for it
//! (one per handle column, canvas px, as [`handle_transforms`](super::handle_transforms) or the
//! skinning IK returns them), a bone or point handle's name and an [`FkEdit`] measured on the
//! canvas. Out: the pose with that handle *keyed*: its local pose set to where it is shown,
//! then edited. Keying is what mixes FK and IK: the skinning IK keeps a keyed handle where the
//! pose puts it (relative to its nearest free ancestor) and moves the free ones around it, so a
//! bone that the IK had moved starts from where the animator sees it and does not jump.
//!
//! The edits are the ones animators know from other tools' G/R/S keys and gizmos: a grab moves
//! a bone's head (a point) by a canvas offset, a rotation turns a bone about its head (a point
//! about itself) by an on-screen angle, a scale multiplies a bone's length and width (a point's
//! scale) by a factor.

use super::pose::{bone_rest_frame, pose_from_transforms, Affine, PoseError};
use super::{Handles, Pose};
use crate::geom::{Point, Vec2};

/// One edit of a handle, in canvas terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FkEdit {
    /// Move by this offset, canvas px.
    Grab { delta_px: Vec2 },
    /// Turn by this angle, degrees counter-clockwise on screen.
    Rotate { angle_deg: f64 },
    /// Multiply the scale by this factor (> 0), both axes.
    Scale { factor: f64 },
}

/// What the caller got wrong.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum FkEditError {
    #[error("there is no bone or point handle named '{0}'")]
    UnknownHandle(String),
    #[error("{got} transforms shown for {expected} handle columns")]
    TransformCount { got: usize, expected: usize },
    #[error("the edit is not a finite move, angle or positive scale factor")]
    BadEdit,
    #[error(transparent)]
    Pose(#[from] PoseError),
}

/// Which handle an edit applies to, and where its gizmo sits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FkTarget {
    /// The handle's column: bones first, then points (as in [`super::handle_columns`]).
    pub column: usize,
    pub is_bone: bool,
    /// The point edits turn and scale about: a bone's posed head, a point's posed position,
    /// canvas px.
    pub pivot_px: Point,
    /// The handle's posed direction (a bone's head → tail; a point's x axis), canvas px, unit.
    pub direction: Vec2,
}

/// The on-screen counter-clockwise angle from `from` to `to` (vectors from a pivot), in
/// (−180°, 180°].
pub fn turn_deg(from: Vec2, to: Vec2) -> f64 {
    // The canvas' y axis points down: counter-clockwise on screen is clockwise in (x, y).
    let cross = from.perp(&to);
    let dot = from.dot(&to);
    (-cross).atan2(dot).to_degrees()
}

/// The target of an edit of `name`, with `shown` the transforms on screen.
pub fn target(handles: &Handles, shown: &[Affine], name: &str) -> Result<FkTarget, FkEditError> {
    check_count(handles, shown)?;
    let bone_count = handles.bones.len();
    let (column, is_bone, rest_frame) =
        if let Some(i) = handles.bones.iter().position(|b| b.name == name) {
            let bone = &handles.bones[i];
            (i, true, bone_rest_frame(bone.head, bone.tail))
        } else if let Some(i) = handles.points.iter().position(|p| p.name == name) {
            let at = handles.points[i].at;
            (bone_count + i, false, Affine::translation(at.coords))
        } else {
            return Err(FkEditError::UnknownHandle(name.to_string()));
        };
    let world = shown[column].then_after(&rest_frame);
    let axis = world.linear.column(0);
    let length = axis.norm();
    let direction = if length > 0.0 {
        axis / length
    } else {
        Vec2::x()
    };
    Ok(FkTarget {
        column,
        is_bone,
        pivot_px: world.translation.into(),
        direction,
    })
}

fn check_count(handles: &Handles, shown: &[Affine]) -> Result<(), FkEditError> {
    let expected = super::handle_columns(handles).len();
    if shown.len() != expected {
        return Err(FkEditError::TransformCount {
            got: shown.len(),
            expected,
        });
    }
    Ok(())
}

/// `pose` with `name` keyed where `shown` puts it and then edited by `edit` (see the module
/// doc). Other handles' entries are left as they are.
pub fn apply(
    handles: &Handles,
    pose: &Pose,
    shown: &[Affine],
    name: &str,
    edit: FkEdit,
) -> Result<Pose, FkEditError> {
    let valid = match edit {
        FkEdit::Grab { delta_px } => delta_px.iter().all(|v| v.is_finite()),
        FkEdit::Rotate { angle_deg } => angle_deg.is_finite(),
        FkEdit::Scale { factor } => factor.is_finite() && factor > 0.0,
    };
    if !valid {
        return Err(FkEditError::BadEdit);
    }
    let target = target(handles, shown, name)?;
    // Where the handle is shown: with drags, the local pose decomposed from the IK's
    // transforms; without, the pose's own entry (exact, no round trip through matrices).
    let decomposed = if pose.ik.is_empty() {
        None
    } else {
        Some(pose_from_transforms(handles, shown)?)
    };
    let as_shown = decomposed.as_ref().unwrap_or(pose);
    let mut out = pose.clone();
    if target.is_bone {
        let mut local = as_shown.bones.get(name).cloned().unwrap_or_default();
        let bone = &handles.bones[target.column];
        // The parent's posed frame: offsets and angles on screen are measured in it.
        let world_from_parent = match bone
            .parent
            .as_deref()
            .and_then(|p| handles.bones.iter().position(|b| b.name == p))
        {
            Some(p) => {
                let parent = &handles.bones[p];
                shown[p].then_after(&bone_rest_frame(parent.head, parent.tail))
            }
            None => Affine::identity(),
        };
        match edit {
            FkEdit::Grab { delta_px } => {
                let inverse = world_from_parent
                    .inverse()
                    .ok_or_else(|| PoseError::Singular(bone.name.clone()))?;
                let d = inverse.linear * delta_px;
                local.translate[0] += d.x;
                local.translate[1] += d.y;
            }
            FkEdit::Rotate { angle_deg } => {
                // A mirrored parent frame turns the other way on screen.
                let sign = world_from_parent.linear.determinant().signum();
                local.rotate += sign * angle_deg;
            }
            FkEdit::Scale { factor } => {
                local.scale[0] *= factor;
                local.scale[1] *= factor;
            }
        }
        out.bones.insert(name.to_string(), local);
    } else {
        let mut local = as_shown.points.get(name).cloned().unwrap_or_default();
        // A carried point's pose applies before its parent's motion: screen offsets and
        // angles are measured through that motion's linear part.
        let point = target.column - handles.bones.len();
        let world_from_parent = handles
            .point_parent(point)
            .map_or_else(Affine::identity, |b| shown[b]);
        match edit {
            FkEdit::Grab { delta_px } => {
                let inverse = world_from_parent
                    .inverse()
                    .ok_or_else(|| PoseError::Singular(name.to_string()))?;
                let d = inverse.linear * delta_px;
                local.translate[0] += d.x;
                local.translate[1] += d.y;
            }
            FkEdit::Rotate { angle_deg } => {
                let sign = world_from_parent.linear.determinant().signum();
                local.rotate += sign * angle_deg;
            }
            FkEdit::Scale { factor } => {
                local.scale[0] *= factor;
                local.scale[1] *= factor;
            }
        }
        out.points.insert(name.to_string(), local);
    }
    Ok(out)
}

/// Where `column`'s transform in `shown` puts a rest point, canvas px.
pub fn shown_point(shown: &[Affine], column: usize, rest_px: Point) -> Point {
    shown[column].apply(rest_px)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::pose::IkDrag;
    use crate::rig::{handle_transforms, Bone, PointHandle};

    /// An arm along +x: upper (0,0)→(10,0), fore (10,0)→(20,0); a point at (5, 5).
    fn arm() -> Handles {
        let mut h = Handles::default();
        h.bones.push(Bone {
            name: "upper".into(),
            parent: None,
            head: Point::new(0.0, 0.0),
            tail: Point::new(10.0, 0.0),
        });
        h.bones.push(Bone {
            name: "fore".into(),
            parent: Some("upper".into()),
            head: Point::new(10.0, 0.0),
            tail: Point::new(20.0, 0.0),
        });
        h.points.push(PointHandle {
            name: "p".into(),
            at: Point::new(5.0, 5.0),
            parent: None,
        });
        h
    }

    fn close(a: Point, b: impl Into<Point>) -> bool {
        let b = b.into();
        (a.x - b.x).abs() < 1e-9 && (a.y - b.y).abs() < 1e-9
    }

    /// Where the pose puts a bone's head and tail.
    fn ends(h: &Handles, pose: &Pose, bone: usize) -> (Point, Point) {
        let t = handle_transforms(h, pose).unwrap();
        let b = &h.bones[bone];
        (shown_point(&t, bone, b.head), shown_point(&t, bone, b.tail))
    }

    #[test]
    fn turn_is_counter_clockwise_on_screen() {
        // +x to −y (up on screen) is a quarter turn counter-clockwise.
        assert!((turn_deg(Vec2::new(1.0, 0.0), Vec2::new(0.0, -1.0)) - 90.0).abs() < 1e-12);
        assert!((turn_deg(Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)) + 90.0).abs() < 1e-12);
    }

    #[test]
    fn rotating_a_bone_turns_it_about_its_head() {
        let h = arm();
        let pose = Pose::default();
        let shown = handle_transforms(&h, &pose).unwrap();
        let edited = apply(
            &h,
            &pose,
            &shown,
            "fore",
            FkEdit::Rotate { angle_deg: 90.0 },
        )
        .unwrap();
        let (head, tail) = ends(&h, &edited, 1);
        assert!(close(head, [10.0, 0.0]), "{head:?}");
        // Up on screen is −y.
        assert!(close(tail, [10.0, -10.0]), "{tail:?}");
        assert_eq!(edited.bones["fore"].rotate, 90.0);
    }

    #[test]
    fn grabbing_a_child_of_a_turned_parent_moves_it_by_the_canvas_offset() {
        let h = arm();
        let mut pose = Pose::default();
        pose.bones.insert(
            "upper".into(),
            crate::rig::pose::BonePose {
                rotate: 90.0,
                ..Default::default()
            },
        );
        let shown = handle_transforms(&h, &pose).unwrap();
        let (head0, _) = ends(&h, &pose, 1);
        let edited = apply(
            &h,
            &pose,
            &shown,
            "fore",
            FkEdit::Grab {
                delta_px: Vec2::new(3.0, 4.0),
            },
        )
        .unwrap();
        let (head1, _) = ends(&h, &edited, 1);
        assert!(
            close(head1, [head0[0] + 3.0, head0[1] + 4.0]),
            "{head0:?} {head1:?}"
        );
    }

    #[test]
    fn scaling_a_bone_lengthens_it() {
        let h = arm();
        let pose = Pose::default();
        let shown = handle_transforms(&h, &pose).unwrap();
        let edited = apply(&h, &pose, &shown, "upper", FkEdit::Scale { factor: 2.0 }).unwrap();
        let (head, tail) = ends(&h, &edited, 0);
        assert!(
            close(head, [0.0, 0.0]) && close(tail, [20.0, 0.0]),
            "{tail:?}"
        );
    }

    #[test]
    fn points_move_turn_and_scale_about_themselves() {
        let h = arm();
        let pose = Pose::default();
        let shown = handle_transforms(&h, &pose).unwrap();
        let moved = apply(
            &h,
            &pose,
            &shown,
            "p",
            FkEdit::Grab {
                delta_px: Vec2::new(1.0, 2.0),
            },
        )
        .unwrap();
        let t = handle_transforms(&h, &moved).unwrap();
        assert!(close(shown_point(&t, 2, Point::new(5.0, 5.0)), [6.0, 7.0]));
        let turned = apply(&h, &moved, &t, "p", FkEdit::Rotate { angle_deg: 30.0 }).unwrap();
        let t = handle_transforms(&h, &turned).unwrap();
        // The pivot stays; a neighbour turns about it.
        assert!(close(shown_point(&t, 2, Point::new(5.0, 5.0)), [6.0, 7.0]));
        let target = target(&h, &t, "p").unwrap();
        assert!((turn_deg(Vec2::new(1.0, 0.0), target.direction) - 30.0).abs() < 1e-9);
    }

    #[test]
    fn a_point_on_a_turned_bone_moves_and_turns_as_shown_on_screen() {
        let mut h = arm();
        h.points[0].parent = Some("fore".into());
        let mut pose = Pose::default();
        pose.bones.insert(
            "upper".into(),
            crate::rig::pose::BonePose {
                rotate: 90.0,
                ..Default::default()
            },
        );
        let shown = handle_transforms(&h, &pose).unwrap();
        let at = Point::new(5.0, 5.0);
        let before = shown_point(&shown, 2, at);
        let moved = apply(
            &h,
            &pose,
            &shown,
            "p",
            FkEdit::Grab {
                delta_px: Vec2::new(1.0, 2.0),
            },
        )
        .unwrap();
        let t = handle_transforms(&h, &moved).unwrap();
        let after = shown_point(&t, 2, at);
        assert!(close(after, [before.x + 1.0, before.y + 2.0]), "{after:?}");
        let turned = apply(&h, &moved, &t, "p", FkEdit::Rotate { angle_deg: 30.0 }).unwrap();
        let t = handle_transforms(&h, &turned).unwrap();
        assert!(close(shown_point(&t, 2, at), [after.x, after.y]));
        // The bone turned the point's axis to 90°; the edit adds 30° on screen.
        let target = target(&h, &t, "p").unwrap();
        assert!((turn_deg(Vec2::new(1.0, 0.0), target.direction) - 120.0).abs() < 1e-9);
    }

    #[test]
    fn keying_a_bone_the_ik_moved_starts_where_it_is_shown() {
        let h = arm();
        // Stand-in for an IK result: the upper arm turned 30° and moved, fore turned 45° more.
        let mut fk = Pose::default();
        fk.bones.insert(
            "upper".into(),
            crate::rig::pose::BonePose {
                rotate: 30.0,
                translate: [2.0, 1.0],
                ..Default::default()
            },
        );
        fk.bones.insert(
            "fore".into(),
            crate::rig::pose::BonePose {
                rotate: 45.0,
                ..Default::default()
            },
        );
        let shown = handle_transforms(&h, &fk).unwrap();
        // The edited pose only has a drag: nothing keyed yet.
        let pose = Pose {
            ik: vec![IkDrag {
                at: Point::new(20.0, 0.0),
                to: Point::new(15.0, -12.0),
                weight: None,
            }],
            ..Default::default()
        };
        let edited = apply(&h, &pose, &shown, "fore", FkEdit::Rotate { angle_deg: 0.0 }).unwrap();
        assert!((edited.bones["fore"].rotate - 45.0).abs() < 1e-9);
        assert!(
            !edited.bones.contains_key("upper"),
            "only the edited bone is keyed"
        );
        assert_eq!(edited.ik, pose.ik);
    }

    #[test]
    fn bad_edits_and_names_are_refused() {
        let h = arm();
        let shown = handle_transforms(&h, &Pose::default()).unwrap();
        let pose = Pose::default();
        assert_eq!(
            apply(&h, &pose, &shown, "nope", FkEdit::Scale { factor: 2.0 }),
            Err(FkEditError::UnknownHandle("nope".into()))
        );
        assert_eq!(
            apply(&h, &pose, &shown, "fore", FkEdit::Scale { factor: 0.0 }),
            Err(FkEditError::BadEdit)
        );
        assert_eq!(
            apply(
                &h,
                &pose,
                &shown[..1],
                "fore",
                FkEdit::Rotate { angle_deg: 1.0 }
            ),
            Err(FkEditError::TransformCount {
                got: 1,
                expected: 3
            })
        );
    }
}
