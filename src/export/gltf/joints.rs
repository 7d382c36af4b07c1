//! Every handle a glTF joint: where it rests, what it hangs from, and its local map at a frame.
//!
//! In: the rig's handles and the [`GltfFrame`]. Out: one [`Joint`] per weight column
//! ([`crate::rig::handle_columns`]: bones, points, cage vertices, regions): its rest frame in
//! glTF space (a bone at its head turned along it; a point, cage vertex or region at its
//! position or centroid, unturned) and its parent column (a bone's parent bone, a carried
//! point's bone; the rest hang from the root node).
//!
//! Skinning: a joint's world map is W(t) = F·A(t)·F⁻¹·B, with A(t) the handle's transformation
//! (rest canvas → posed canvas), F the frame and B the rest frame; its inverse bind matrix is
//! B⁻¹, so the runtime's joint matrix W(t)·B⁻¹ is F·A(t)·F⁻¹ and skinning is sinew's linear
//! blend, exactly. [`local_maps`] gives each joint's map relative to its parent's world map, which
//! the node hierarchy carries ([`super::frame::Trsr`]).

use super::frame::{rotation, GltfFrame};
use super::GltfError;
use crate::geom::Point;
use crate::rig::{handle_columns, Affine, Handles};

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

/// The joints of `handles`, in column order.
pub fn joints(handles: &Handles, frame: &GltfFrame) -> Vec<Joint> {
    let names = handle_columns(handles);
    let at = |p: Point, angle_rad: f64| Affine {
        linear: rotation(angle_rad),
        translation: frame.from_canvas(p),
    };
    let mut out = Vec::with_capacity(names.len());
    for bone in &handles.bones {
        let d = bone.tail - bone.head;
        // Canvas angles turn clockwise on screen (y down); glTF's turn the other way.
        let angle_rad = if d.norm() > 0.0 { -d.y.atan2(d.x) } else { 0.0 };
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
    frame: &GltfFrame,
) -> Result<Vec<Affine>, GltfError> {
    let world: Vec<Affine> = joints
        .iter()
        .zip(transforms)
        .map(|(joint, a)| frame.affine(a).then_after(&joint.rest))
        .collect();
    joints
        .iter()
        .enumerate()
        .map(|(j, joint)| match joint.parent {
            None => Ok(world[j]),
            Some(p) => {
                let parent = world[p]
                    .inverse()
                    .ok_or_else(|| GltfError::Singular(joints[p].name.clone()))?;
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
