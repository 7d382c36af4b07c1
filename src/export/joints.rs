//! Every handle a glTF joint: where it rests, what it hangs from, and its local map at a frame.
//!
//! In: the rig's handles and the target's frame (where a canvas point lands, which angle a canvas
//! direction has). Out: one [`Joint`] per weight column
//! ([`crate::rig::handle_columns`]: bones, points, cage vertices, regions): its rest frame in
//! the target's space (a bone at its head turned along it; a point, cage vertex or region at its
//! position or centroid, unturned) and its parent column (a bone's parent bone, a carried
//! point's bone; the rest hang from the root node).
//!
//! Skinning: a joint's world map is W(t) = F·A(t)·F⁻¹·B, with A(t) the handle's transformation
//! (rest canvas → posed canvas), F the frame and B the rest frame; its inverse bind matrix is
//! B⁻¹, so the runtime's joint matrix W(t)·B⁻¹ is F·A(t)·F⁻¹ and skinning is sinew's linear
//! blend, exactly. [`local_maps`] gives each joint's map relative to its parent's world map, which
//! the node (or bone) hierarchy carries. glTF ([`super::gltf::frame::Trsr`]) and DragonBones
//! (`crate::export::dragonbones`) both build their skeletons here.

use crate::export::gltf::frame::rotation;
use crate::geom::Point;
use crate::rig::{handle_columns, Affine, Handles};

/// A joint whose posed map is singular (a zero scale): no child can hang from it.
#[derive(Clone, Debug, PartialEq)]
pub struct SingularJoint(pub String);

/// One handle as a joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// The weight column's name (`cage.k` for cage vertex k).
    pub name: String,
    /// The parent joint (a column index), or `None` under the root node.
    pub parent: Option<usize>,
    /// The rest frame B in glTF space.
    pub rest: Affine,
}

/// Where a target puts the canvas: a canvas point's position, and a canvas direction's angle
/// (radians, the target's positive turn).
pub trait Placement {
    fn place(&self, p: Point) -> crate::geom::Vec2;
    fn angle_rad(&self, direction: crate::geom::Vec2) -> f64;
    /// A canvas map (rest → posed) as the same map of the target's space.
    fn map(&self, canvas: &Affine) -> Affine;
}

/// The joints of `handles`, in column order, placed by `frame`.
pub fn joints(handles: &Handles, frame: &impl Placement) -> Vec<Joint> {
    let names = handle_columns(handles);
    let at = |p: Point, angle_rad: f64| Affine {
        linear: rotation(angle_rad),
        translation: frame.place(p),
    };
    let mut out = Vec::with_capacity(names.len());
    for bone in &handles.bones {
        let d = bone.tail - bone.head;
        let angle_rad = if d.norm() > 0.0 {
            frame.angle_rad(d)
        } else {
            0.0
        };
        out.push((
            bone.parent
                .as_deref()
                .and_then(|p| handles.bones.iter().position(|b| b.name == p)),
            at(bone.head, angle_rad),
        ));
    }
    for (i, point) in handles.points.iter().enumerate() {
        out.push((handles.point_parent(i), at(point.at, 0.0)));
    }
    for cage in &handles.cages {
        for &p in &cage.polygon {
            out.push((None, at(p, 0.0)));
        }
    }
    for region in &handles.regions {
        out.push((None, at(centroid(&region.polygon), 0.0)));
    }
    names
        .into_iter()
        .zip(out)
        .map(|(name, (parent, rest))| Joint { name, parent, rest })
        .collect()
}

/// The mean of a polygon's vertices (the origin of an empty one).
fn centroid(polygon: &[Point]) -> Point {
    if polygon.is_empty() {
        return Point::origin();
    }
    let n = polygon.len() as f64;
    let sum = polygon
        .iter()
        .fold(crate::geom::Vec2::zeros(), |s, p| s + p.coords);
    Point::from(sum / n)
}

/// Each joint's map relative to its parent's world map, given every handle's transformation
/// (`transforms`, canvas, in column order): W_parent⁻¹·W (the world map under the root).
pub fn local_maps(
    joints: &[Joint],
    transforms: &[Affine],
    frame: &impl Placement,
) -> Result<Vec<Affine>, SingularJoint> {
    let world: Vec<Affine> = joints
        .iter()
        .zip(transforms)
        .map(|(joint, a)| frame.map(a).then_after(&joint.rest))
        .collect();
    joints
        .iter()
        .enumerate()
        .map(|(j, joint)| match joint.parent {
            None => Ok(world[j]),
            Some(p) => {
                let parent = world[p]
                    .inverse()
                    .ok_or_else(|| SingularJoint(joints[p].name.clone()))?;
                Ok(parent.then_after(&world[j]))
            }
        })
        .collect()
}

/// The rest maps relative to the parents: B_parent⁻¹·B (rest frames are rigid, so never
/// singular).
pub fn rest_locals(joints: &[Joint]) -> Vec<Affine> {
    joints
        .iter()
        .map(
            |joint| match joint.parent.and_then(|p| joints[p].rest.inverse()) {
                Some(parent) => parent.then_after(&joint.rest),
                None => joint.rest,
            },
        )
        .collect()
}

/// Each joint's world map from its map relative to its parent (`locals`, column order):
/// parent · local down the tree, parents first however the columns are ordered (a rig's
/// parents have no cycles; a joint left unreached would be the identity).
pub fn compose_down(joints: &[Joint], locals: &[Affine]) -> Vec<Affine> {
    let mut world: Vec<Option<Affine>> = vec![None; locals.len()];
    for _ in 0..locals.len() {
        for (b, joint) in joints.iter().enumerate() {
            if world[b].is_none() {
                world[b] = match joint.parent {
                    None => Some(locals[b]),
                    Some(parent) => world[parent].map(|g| g.then_after(&locals[b])),
                };
            }
        }
    }
    world
        .into_iter()
        .map(|w| w.unwrap_or(Affine::identity()))
        .collect()
}

/// `angle_rad` plus the whole turns that bring it nearest `near_rad`: how the exports keep a
/// keyed angle continuous from frame to frame.
pub fn nearest_turn(angle_rad: f64, near_rad: f64) -> f64 {
    use std::f64::consts::TAU;
    angle_rad + ((near_rad - angle_rad) / TAU).round() * TAU
}

/// A part whose weights name a handle the rig does not have: (part, handle).
#[derive(Clone, Debug, PartialEq)]
pub struct UnknownColumn(pub String, pub String);

/// `part`'s weight rows with each handle as its index in the rig's `columns` (the document
/// names its columns; exports address the rig's).
pub fn column_rows(
    part: &crate::io::PartDoc,
    weights: &crate::io::WeightsDoc,
    columns: &[String],
) -> Result<Vec<Vec<(usize, f64)>>, UnknownColumn> {
    let to_column = weights
        .handles
        .iter()
        .map(|handle| {
            columns
                .iter()
                .position(|c| c == handle)
                .ok_or_else(|| UnknownColumn(part.name.clone(), handle.clone()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(weights
        .rows
        .iter()
        .map(|row| {
            row.iter()
                .map(|&(h, w)| (to_column[h as usize], w))
                .collect()
        })
        .collect())
}
