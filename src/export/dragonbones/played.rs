//! What the DragonBones runtime plays of an export, reproduced in sinew (`--match-runtime
//! dragonbones`).
//!
//! In: a [`DragonBonesExport`] and the name and time of one of its animations. Out: the handle
//! transformations (canvas, column order) and the pose (deform offsets, slot displays, colours,
//! draw order) that, through sinew's skinning ([`crate::pipeline::Scene::positions_from_transforms`])
//! and drawing, give what the runtime draws at that time.
//!
//! The runtime (docs/dragonbones-format.md) reads the setup transforms from the file (f32
//! numbers, rotation and skew normalized to (−π, π]); at time t it is on frame i = ⌊t·F⌋ with
//! progress u = t·F − i and tweens each bone's stored frame values linearly (translation and
//! rotation, skew added to the setup's, scale multiplied), composes parent · local down the
//! bone tree, and skins each vertex by Σ w · world · bonePose⁻¹. Display and draw-order frames
//! step; colour and deform frames tween linearly.

use super::transform::DbTransform;
use super::{BakedAnimation, DragonBonesExport};
use crate::anim::curve::f32_stored;
use crate::geom::Vec2;
use crate::rig::pose::PartPose;
use crate::rig::{Affine, Pose};
use std::f64::consts::PI;

/// An angle into (−π, π], as `Transform.normalizeRadian`.
fn normalize_radian(a: f64) -> f64 {
    let mut a = (a + PI) % (PI * 2.0);
    a += if a > 0.0 { -PI } else { PI };
    a
}

/// The setup transform as the runtime parses it from the file's numbers.
fn parsed_setup(t: &DbTransform) -> DbTransform {
    let rotation = normalize_radian(f32_stored(t.rotation_rad.to_degrees()) * PI / 180.0);
    let second =
        normalize_radian(f32_stored((t.rotation_rad + t.skew_rad).to_degrees()) * PI / 180.0);
    DbTransform {
        x: f32_stored(t.x),
        y: f32_stored(t.y),
        rotation_rad: rotation,
        skew_rad: second - rotation,
        scale_x: f32_stored(t.scale_x),
        scale_y: f32_stored(t.scale_y),
    }
}

/// What the DragonBones runtime plays of one animation: the export's bones and the animation's
/// frames, without the files ([`super::playback`]), for `--match-runtime dragonbones`.
#[derive(Clone, Debug)]
pub struct DbPlayback {
    pub frame_rate: u32,
    pub frame: super::transform::DbFrame,
    pub joints: Vec<crate::export::joints::Joint>,
    pub setup: Vec<DbTransform>,
    pub animation: BakedAnimation,
    /// The slots in setup draw order, and each slot's displays (part names) in display order.
    pub slots: Vec<(String, Vec<String>)>,
}

impl DbPlayback {
    /// What the runtime poses at `time_s` (played once; clamped to the end).
    pub fn at(&self, time_s: f64) -> (Vec<Affine>, Pose) {
        let slots: Vec<&str> = self.slots.iter().map(|(s, _)| s.as_str()).collect();
        let attachments = |slot: &str| {
            self.slots
                .iter()
                .find(|(s, _)| s == slot)
                .map(|(_, a)| a.clone())
                .unwrap_or_default()
        };
        pose_at(
            Bones {
                frame_rate: self.frame_rate,
                frame: &self.frame,
                joints: &self.joints,
                setup: &self.setup,
            },
            &self.animation,
            &slots,
            &attachments,
            time_s,
        )
    }
}

/// The skeleton an export's frames move.
struct Bones<'a> {
    frame_rate: u32,
    frame: &'a super::transform::DbFrame,
    joints: &'a [crate::export::joints::Joint],
    setup: &'a [DbTransform],
}

/// What the runtime poses at `time_s` of `animation` of `export` (played once; clamped to its
/// end). `slots` are the rig's slots in setup order; `attachments` gives a slot's displays.
pub fn as_played(
    export: &DragonBonesExport,
    animation: &BakedAnimation,
    slots: &[&str],
    attachments: &dyn Fn(&str) -> Vec<String>,
    time_s: f64,
) -> (Vec<Affine>, Pose) {
    pose_at(
        Bones {
            frame_rate: export.frame_rate,
            frame: &export.frame,
            joints: &export.joints,
            setup: &export.setup,
        },
        animation,
        slots,
        attachments,
        time_s,
    )
}

fn pose_at(
    export: Bones,
    animation: &BakedAnimation,
    slots: &[&str],
    attachments: &dyn Fn(&str) -> Vec<String>,
    time_s: f64,
) -> (Vec<Affine>, Pose) {
    let fps = f64::from(export.frame_rate);
    let n = animation.frame_count as usize;
    let position = (time_s.max(0.0) * fps).min(n as f64);
    let i = (position.floor() as usize).min(n);
    let u = if i < n { position - i as f64 } else { 0.0 };
    let j = (i + 1).min(n);
    let lerp = |a: f64, b: f64| a + (b - a) * u;

    // Bones: setup plus the tweened frame values, composed down the tree.
    let locals: Vec<Affine> = export
        .joints
        .iter()
        .enumerate()
        .map(|(b, _)| {
            let setup = parsed_setup(&export.setup[b]);
            let (p, q) = (&animation.bones[i][b], &animation.bones[j][b]);
            DbTransform {
                x: setup.x + lerp(p.x, q.x),
                y: setup.y + lerp(p.y, q.y),
                rotation_rad: setup.rotation_rad + lerp(p.rotation_rad, q.rotation_rad),
                skew_rad: setup.skew_rad + lerp(p.skew_rad, q.skew_rad),
                scale_x: setup.scale_x * lerp(p.scale_x, q.scale_x),
                scale_y: setup.scale_y * lerp(p.scale_y, q.scale_y),
            }
            .to_affine()
        })
        .collect();
    let world = crate::export::joints::compose_down(export.joints, &locals);
    let origin = export.frame.origin_px.coords;
    let transforms = export
        .joints
        .iter()
        .zip(&world)
        .map(|(joint, global)| {
            let rest = &joint.rest;
            let bone_pose = Affine {
                linear: rest.linear.map(f32_stored),
                translation: rest.translation.map(f32_stored),
            };
            let armature = global.then_after(&bone_pose.inverse().unwrap_or(Affine::identity()));
            // Back to the canvas: T(o)·A·T(−o).
            Affine {
                linear: armature.linear,
                translation: armature.translation + origin - armature.linear * origin,
            }
        })
        .collect();

    let mut pose = Pose::default();
    for (part, frames) in &animation.deforms {
        let offsets: Vec<Vec2> = frames[i]
            .iter()
            .zip(&frames[j])
            .map(|(a, b)| Vec2::new(lerp(a.x, b.x), lerp(a.y, b.y)))
            .collect();
        pose.deform.insert(part.clone(), offsets);
    }
    for (slot, values) in &animation.displays {
        let state = pose
            .parts
            .entry(slot.clone())
            .or_insert_with(PartPose::default);
        match usize::try_from(values[i]) {
            Ok(k) => state.attachment = attachments(slot).get(k).cloned(),
            Err(_) => state.visible = false,
        }
    }
    for (slot, values) in &animation.colors {
        let state = pose
            .parts
            .entry(slot.clone())
            .or_insert_with(PartPose::default);
        for (c, (a, b)) in state.color.iter_mut().zip(values[i].iter().zip(&values[j])) {
            *c = lerp(*a as f64, *b as f64) / 100.0;
        }
    }
    if let Some(orders) = &animation.draw_order {
        let order = &orders[i];
        if order.iter().map(String::as_str).ne(slots.iter().copied()) {
            pose.draw_order = Some(order.clone());
        }
    }
    (transforms, pose)
}
