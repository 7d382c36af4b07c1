//! Deform keys as Spine deform timelines.
//!
//! In: one part's deform keys ([`crate::anim::deform`]: per key one offset per vertex of the
//! fine mesh, canvas px, rest frame), the part's exported [`MeshAttachment`] (its vertices'
//! sources in the fine mesh and their influences), the [`Skeleton`] and the [`SpineFrame`].
//! Out: the `deform` timeline of the part's attachment (spine-format.md §7): per key, `vertices`
//! with two numbers per influence, in the attachment's vertex order and each vertex's
//! influence order.
//!
//! spine-core adds a weighted mesh's deform to each influence's bind position (bone-local,
//! setup pose) before skinning. An offset `o` in the rest frame is therefore written, for an
//! influence of bone j, as `o` in bone j's setup frame, `(setup_world_j)⁻¹·o` (its linear
//! part, y flipped into Spine's axes): the runtime then skins `bind + that`, which linear blend
//! skinning maps exactly where it maps the rest vertex moved by `o` — sinew's deform.
//! The curve is one 0..1 Bézier for all numbers, Spine's deform curve as it stands; a first key
//! after 0 s gets a copy at 0 s (Spine would show the setup pose before it).
//!
//! Keys that change nothing are not written out: a key whose offsets are all zero (as written,
//! f32) has no `vertices`, which spine-core 4.1–4.3 reads as zero offsets of a weighted mesh
//! (`SkeletonJson.readAnimation`: `deform = Utils.newFloatArray(deformLength)` when `vertices`
//! is missing); a timeline whose keys are all zero is not written at all
//! ([`deform_timeline`] returns `None`), since zero offsets draw the setup mesh as no timeline
//! does.

use super::frame::SpineFrame;
use super::mesh::MeshAttachment;
use super::skeleton::Skeleton;
use super::timelines::{curve_json, key_object, num, with_start};
use super::SpineError;
use crate::anim::deform::DeformKeys;
use crate::geom::Vec2;
use serde_json::Value;

/// The deform timeline of `mesh` for `keys` (offsets of the fine mesh's vertices), or `None`
/// when every key's offsets are zero at the exported vertices (nothing to write).
pub fn deform_timeline(
    keys: &DeformKeys,
    mesh: &MeshAttachment,
    skeleton: &Skeleton,
    frame: &SpineFrame,
) -> Result<Option<Value>, SpineError> {
    // Per influence, the inverse of its bone's setup linear map.
    let mut inverses = Vec::with_capacity(skeleton.bones.len());
    for bone in &skeleton.bones {
        let inverse = bone
            .setup_world
            .linear
            .try_inverse()
            .ok_or_else(|| SpineError::Singular(bone.name.clone()))?;
        inverses.push(inverse);
    }
    let mut out = Vec::with_capacity(keys.len() + 1);
    let mut any_offset = false;
    for k in with_start(keys) {
        let mut vertices = Vec::new();
        for (source, influences) in mesh.vertex_source.iter().zip(&mesh.influences) {
            let o = k.value.get(*source).copied().unwrap_or_else(Vec2::zeros);
            let o = frame.spine_vector(o);
            for i in influences {
                let local = inverses[i.bone] * o;
                vertices.extend([num(local.x), num(local.y)]);
            }
        }
        // As the runtime reads the numbers: all zero (f32), the key needs no `vertices`.
        let zero = vertices.iter().all(|v| v.as_f64() == Some(0.0));
        any_offset |= !zero;
        let fields = if zero {
            Vec::new()
        } else {
            vec![("vertices", Value::Array(vertices))]
        };
        out.push(key_object(k.time, fields, curve_json(&k.curve, &|_, y| y)));
    }
    Ok(any_offset.then_some(Value::Array(out)))
}
