//! One animation as glTF channels: every joint's pivot and joint node, and the morph weights of
//! deformed parts, keyed linearly at the bake times.
//!
//! In: the animation, the scene it plays on, the joints and the parts written. Out: the
//! accessors of the key times and of each channel's values, appended to the buffer. The frames
//! come from the one pose path ([`bake::sample_path`], exact curves, physics and momentum
//! simulated from the start), so a runtime's pose at a bake time is sinew's.

use super::frame::{z_quaternion, GltfFrame, Trsr};
use super::glb::Buffer;
use super::{morph_weights, GltfError, GltfOptions, WrittenPart};
use crate::anim::Animation;
use crate::export::joints::{local_maps, Joint};
use crate::export::spine::{bake, MAX_BAKE_SAMPLES};
use crate::pipeline::Scene;
use crate::rig::Affine;

/// The accessors of one baked animation.
pub struct BakedAnimation {
    /// The key times.
    pub input: usize,
    /// The keys as written.
    pub played: super::played::GltfAnimation,
    /// (node, path, output accessor) per channel.
    pub channels: Vec<(usize, &'static str, usize)>,
}

/// Bakes `animation` (named `name`) into `buffer`.
#[allow(clippy::too_many_arguments)]
pub(super) fn bake_animation(
    scene: &Scene,
    name: &str,
    animation: &Animation,
    joints: &[Joint],
    rest_locals: &[Affine],
    frame: &GltfFrame,
    written: &[WrittenPart],
    options: &GltfOptions,
    buffer: &mut Buffer,
) -> Result<BakedAnimation, GltfError> {
    let duration = animation.duration_s();
    let samples = duration * options.bake_fps;
    if samples.is_nan() || samples > MAX_BAKE_SAMPLES {
        return Err(GltfError::TooLong {
            animation: name.to_string(),
            samples,
        });
    }
    let times = bake::bake_times(duration, options.bake_fps);
    let frames = bake::sample_path(scene, animation, &times, false)
        .map_err(|e| GltfError::Pose(Box::new(e)))?;
    let n = joints.len();
    let mut translation = vec![Vec::with_capacity(3 * times.len()); n];
    let mut pivot = vec![Vec::with_capacity(4 * times.len()); n];
    let mut scale = vec![Vec::with_capacity(3 * times.len()); n];
    let mut joint_rotation = vec![Vec::with_capacity(4 * times.len()); n];
    // Each frame's factorization nearest the previous frame's, from the rest's.
    let mut keyed: Vec<Vec<Trsr>> = Vec::with_capacity(times.len());
    let mut previous: Vec<Trsr> = rest_locals
        .iter()
        .map(|a| Trsr::from_affine(a, None))
        .collect();
    for (_, transforms) in &frames {
        let locals = local_maps(joints, transforms, frame).map_err(|e| GltfError::Singular(e.0))?;
        let mut row = Vec::with_capacity(n);
        for (j, local) in locals.iter().enumerate() {
            let t = Trsr::from_affine(local, Some(&previous[j]));
            row.push(t.stored());
            translation[j].extend([t.translation.x as f32, t.translation.y as f32, 0.0]);
            pivot[j].extend(z_quaternion(t.pivot_rad).map(|v| v as f32));
            scale[j].extend([t.scale[0] as f32, t.scale[1] as f32, 1.0]);
            joint_rotation[j].extend(z_quaternion(t.joint_rad).map(|v| v as f32));
            previous[j] = t;
        }
        keyed.push(row);
    }
    let times_f32: Vec<f32> = times.iter().map(|&t| t as f32).collect();
    let input = buffer.floats(&times_f32, "SCALAR", true, None);
    let mut channels = Vec::with_capacity(4 * n + written.len());
    let mut morphs = std::collections::BTreeMap::new();
    for j in 0..n {
        let (pivot_node, joint_node) = (1 + 2 * j, 2 + 2 * j);
        channels.push((
            pivot_node,
            "translation",
            buffer.floats(&translation[j], "VEC3", false, None),
        ));
        channels.push((
            pivot_node,
            "rotation",
            buffer.floats(&pivot[j], "VEC4", false, None),
        ));
        channels.push((
            pivot_node,
            "scale",
            buffer.floats(&scale[j], "VEC3", false, None),
        ));
        channels.push((
            joint_node,
            "rotation",
            buffer.floats(&joint_rotation[j], "VEC4", false, None),
        ));
    }
    for (k, w) in written.iter().enumerate() {
        if w.targets.is_empty() {
            continue;
        }
        let part = &scene.doc.parts[w.part].name;
        let mut weights = Vec::with_capacity(times.len() * w.targets.len());
        for &t in &times {
            match animation.deform.get(part) {
                Some(keys) => weights.extend(
                    morph_weights(keys, &w.targets, t)
                        .into_iter()
                        .map(|v| v as f32),
                ),
                None => weights.extend(std::iter::repeat_n(0.0f32, w.targets.len())),
            }
        }
        morphs.insert(
            part.clone(),
            weights
                .chunks(w.targets.len())
                .map(|c| c.iter().map(|&v| f64::from(v)).collect())
                .collect(),
        );
        let node = 1 + 2 * n + k;
        channels.push((
            node,
            "weights",
            buffer.floats(&weights, "SCALAR", false, None),
        ));
    }
    Ok(BakedAnimation {
        input,
        played: super::played::GltfAnimation {
            name: name.to_string(),
            times_s: times_f32.iter().map(|&t| f64::from(t)).collect(),
            locals: keyed,
            morph_weights: morphs,
        },
        channels,
    })
}

/// What of `animation` glTF cannot carry, one line each.
pub(super) fn unexpressed(name: &str, animation: &Animation) -> Vec<String> {
    let mut out = Vec::new();
    let keyed = |f: &dyn Fn(&crate::anim::PartTimelines) -> bool| -> Vec<&str> {
        animation
            .parts
            .iter()
            .filter(|(_, t)| f(t))
            .map(|(p, _)| p.as_str())
            .collect()
    };
    for (what, parts) in [
        ("colour", keyed(&|t| t.color.is_some())),
        ("visibility", keyed(&|t| t.visible.is_some())),
        ("attachment", keyed(&|t| t.attachment.is_some())),
    ] {
        if !parts.is_empty() {
            out.push(format!(
                "animation '{name}': {what} keys of {} (glTF animates no {what})",
                parts.join(", ")
            ));
        }
    }
    if animation.draw_order.is_some() {
        out.push(format!(
            "animation '{name}': draw-order keys (glTF layers are fixed along z)"
        ));
    }
    out
}
