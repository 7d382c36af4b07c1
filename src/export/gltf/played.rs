//! What a glTF runtime plays of an export, reproduced in sinew (`--match-runtime gltf`).
//!
//! In: a [`GltfExport`] and one of its animations ([`GltfAnimation`]: the keys as the file
//! stores them, f32) and a time. Out: the handle transformations (canvas, column order) and the
//! pose (deform offsets from the morph weights) that, skinned with the export's four influences
//! ([`crate::pipeline::Scene::with_influences_limited`]), give the runtime's vertices.
//!
//! A runtime (glTF 2.0 §3.11, three.js's `AnimationMixer`) finds the keys around t, interpolates
//! translations, scales and morph weights linearly and rotations by spherical interpolation
//! (for turns about z: the angle, the short way), composes each node's translation · rotation ·
//! scale down the node tree, and skins with world · inverse bind matrix. Before the first key
//! and after the last it holds the end key.

use super::frame::Trsr;
use super::GltfExport;
use crate::anim::curve::f32_stored;
use crate::geom::Vec2;
use crate::rig::{Affine, Pose};
use std::collections::BTreeMap;
use std::f64::consts::{PI, TAU};

/// One animation's keys as written.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfAnimation {
    pub name: String,
    /// Key times (f32 values).
    pub times_s: Vec<f64>,
    /// Per key, each joint's pivot and joint factors relative to its parent (f32 values, angles
    /// those of the stored quaternions).
    pub locals: Vec<Vec<Trsr>>,
    /// Per part with morph targets (by name), per key, the target weights (f32 values).
    pub morph_weights: BTreeMap<String, Vec<Vec<f64>>>,
}

/// `b − a` brought into (−π, π]: the short way from angle `a` to `b`.
fn short_way(a: f64, b: f64) -> f64 {
    let d = (b - a).rem_euclid(TAU);
    if d > PI {
        d - TAU
    } else {
        d
    }
}

/// What a glTF runtime plays of one animation: the export's skeleton and morph targets and the
/// animation's keys, without the file ([`super::playback`]), for `--match-runtime gltf`.
#[derive(Clone, Debug)]
pub struct GltfPlayback {
    pub frame: super::frame::GltfFrame,
    pub joints: Vec<crate::export::joints::Joint>,
    pub morph_targets: BTreeMap<String, Vec<Vec<Vec2>>>,
    pub animation: GltfAnimation,
}

impl GltfPlayback {
    /// What the runtime poses at `time_s` (held at the ends).
    pub fn at(&self, time_s: f64) -> (Vec<Affine>, Pose) {
        pose_at(
            &self.frame,
            &self.joints,
            &self.morph_targets,
            &self.animation,
            time_s,
        )
    }
}

/// What the runtime poses at `time_s` of `animation` of `export`.
pub fn as_played(
    export: &GltfExport,
    animation: &GltfAnimation,
    time_s: f64,
) -> (Vec<Affine>, Pose) {
    pose_at(
        &export.frame,
        &export.joints,
        &export.morph_targets,
        animation,
        time_s,
    )
}

fn pose_at(
    frame: &super::frame::GltfFrame,
    joints: &[crate::export::joints::Joint],
    morph_targets: &BTreeMap<String, Vec<Vec<Vec2>>>,
    animation: &GltfAnimation,
    time_s: f64,
) -> (Vec<Affine>, Pose) {
    let times = &animation.times_s;
    let last = times.len().saturating_sub(1);
    // The keys around t and the fraction between them.
    let (i, j, u) = match times.iter().position(|&k| k > time_s) {
        Some(0) | None if times.is_empty() => (0, 0, 0.0),
        Some(0) => (0, 0, 0.0),
        None => (last, last, 0.0),
        Some(k) => (
            k - 1,
            k,
            (time_s - times[k - 1]) / (times[k] - times[k - 1]),
        ),
    };
    let lerp = |a: f64, b: f64| a + (b - a) * u;
    let locals: Vec<Affine> = (0..joints.len())
        .map(|b| {
            let (p, q) = (&animation.locals[i][b], &animation.locals[j][b]);
            Trsr {
                translation: Vec2::new(
                    lerp(p.translation.x, q.translation.x),
                    lerp(p.translation.y, q.translation.y),
                ),
                pivot_rad: p.pivot_rad + u * short_way(p.pivot_rad, q.pivot_rad),
                scale: [lerp(p.scale[0], q.scale[0]), lerp(p.scale[1], q.scale[1])],
                joint_rad: p.joint_rad + u * short_way(p.joint_rad, q.joint_rad),
            }
            .to_affine()
        })
        .collect();
    let world = crate::export::joints::compose_down(joints, &locals);
    let transforms = joints
        .iter()
        .zip(world)
        .map(|(joint, w)| {
            let ibm = joint.rest.inverse().unwrap_or(Affine::identity());
            let ibm = Affine {
                linear: ibm.linear.map(f32_stored),
                translation: ibm.translation.map(f32_stored),
            };
            let gltf = w.then_after(&ibm);
            // Back to the canvas: F⁻¹ · J · F.
            let flip = nalgebra::Matrix2::new(1.0, 0.0, 0.0, -1.0);
            let linear = flip * gltf.linear * flip;
            let origin = frame.canvas_from(gltf.translation);
            Affine {
                linear,
                translation: origin.coords - linear * frame.origin_px.coords,
            }
        })
        .collect();
    let mut pose = Pose::default();
    for (part, per_key) in &animation.morph_weights {
        let Some(targets) = morph_targets.get(part) else {
            continue;
        };
        let weights: Vec<f64> = per_key[i]
            .iter()
            .zip(&per_key[j])
            .map(|(a, b)| lerp(*a, *b))
            .collect();
        let n = targets.first().map_or(0, Vec::len);
        let mut offsets = vec![Vec2::zeros(); n];
        for (w, target) in weights.iter().zip(targets) {
            for (o, t) in offsets.iter_mut().zip(target) {
                *o += *w * t.map(f32_stored);
            }
        }
        pose.deform.insert(part.clone(), offsets);
    }
    (transforms, pose)
}
