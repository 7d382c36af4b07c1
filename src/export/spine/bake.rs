//! Baking: motion Spine cannot express natively, sampled into ordinary bone keys.
//!
//! In: an animation, the one function that turns a pose into per-handle transformations (the
//! same path `sinew pose --anim` and `sinew render` take, so that whatever it adds — skinning IK
//! choosing the handles a pose leaves free — is baked too), the skeleton and a frame rate. Out:
//! which bones must be baked and their keys.
//!
//! Which bones: with [`BakeMode::Auto`], a handle is baked when, at any bake time, the path's
//! transformation differs from what forward kinematics of the keyed pose alone gives (which is
//! what the native timelines express) by more than `tolerance_px` at the corners of the rig's
//! bounding box. A baked sinew bone takes its descendants along (their native keys are relative
//! to it). [`BakeMode::All`] bakes every bone.
//!
//! Keys: at 0, 1/fps, 2/fps, … and at the animation's end, linear between. A bone's world
//! transformation at a bake time is the path's transformation after its setup-pose world
//! transformation; its local one is its parent's inverse times that, split into Spine's
//! rotation, scale and shear ([`BoneLocal::from_matrix`]); rotations and shears are unwrapped
//! from key to key, since the runtime interpolates plain numbers. Between keys the runtime
//! interpolates linearly, so baked motion is exact at the keys only.
//!
//! Loops: the bake of an animation flagged `loop` is the steady state of its physics and
//! momentum (the one pose path's, [`crate::scene::play`]): the runtime plays the keys over and
//! over, so a simulation restarted from rest at each loop would jump at the seam (the demo's
//! tail: 22.6 px at the walk's seam before, 4.4 px after, its largest step inside the loop
//! 7.4 px).

use super::frame::{unwrap_deg, BoneLocal, SpineFrame};
use super::skeleton::{BoneSource, Skeleton};
use super::timelines::num;
use super::SpineError;
use crate::anim::Animation;
use crate::geom::Point;
use crate::pipeline::{PipelineError, Scene};
use crate::rig::{handle_transforms, Affine, Handles, Pose};
use crate::scene::PlayOptions;
use serde::{Deserialize, Serialize};
use serde_json::{json, Map, Value};
use std::collections::{BTreeMap, BTreeSet};

/// Which motion is baked.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BakeMode {
    /// Only what native timelines cannot express (default).
    #[default]
    Auto,
    /// Every bone, at the bake rate (for engines that resample anyway, and to test baking).
    All,
}

/// Bake times of an animation lasting `duration_s`: k/fps while below the end, then the end.
pub fn bake_times(duration_s: f64, fps: f64) -> Vec<f64> {
    let mut times = Vec::new();
    let mut k = 0u64;
    loop {
        let t = k as f64 / fps;
        // A frame within a microsecond of the end is the end.
        if t >= duration_s - 1e-6 {
            break;
        }
        times.push(t);
        k += 1;
    }
    times.push(duration_s.max(0.0));
    times
}

/// The animation's frames at each bake time, through the one pose path
/// ([`crate::scene::frames`]: exact curves, times held at the end, skinning IK, momentum and
/// physics included). An animation flagged `loop` bakes its physics and momentum in their
/// periodic steady state ([`crate::scene::play`]), so that its keys at the end run into its
/// keys at 0 as the runtime loops it; otherwise that motion starts from rest at 0.
pub fn sample_path(
    scene: &Scene,
    animation: &Animation,
    times: &[f64],
    native_physics: bool,
) -> Result<Vec<(Pose, Vec<Affine>)>, PipelineError> {
    // Where the runtime simulates physics constraints itself (4.2), the bake leaves them out;
    // elsewhere their motion is baked like any other.
    let unphysical;
    let scene = if !native_physics || scene.doc.handles.physics.is_empty() {
        scene
    } else {
        unphysical = scene.without_physics();
        &unphysical
    };
    let frames = crate::scene::frames(scene, animation, times, PlayOptions::default())?;
    Ok(frames
        .into_iter()
        .map(|frame| (frame.pose, frame.transforms))
        .collect())
}

/// The skeleton bones to bake, by index.
pub fn bones_to_bake(
    mode: BakeMode,
    handles: &Handles,
    skeleton: &Skeleton,
    samples: &[(Pose, Vec<Affine>)],
    corners: &[Point],
    tolerance_px: f64,
) -> Result<BTreeSet<usize>, SpineError> {
    let mut out = BTreeSet::new();
    match mode {
        BakeMode::All => out.extend(1..skeleton.bones.len()),
        BakeMode::Auto => {
            for (pose, path) in samples {
                // Forward kinematics of the keyed pose: what the native timelines say.
                let keyed = Pose {
                    ik: Vec::new(),
                    ..pose.clone()
                };
                let native = handle_transforms(handles, &keyed)
                    .map_err(|e| SpineError::Pose(PipelineError::Pose(e)))?;
                for (column, (a, b)) in path.iter().zip(&native).enumerate() {
                    let apart = corners
                        .iter()
                        .map(|&p| (a.apply(p) - b.apply(p)).norm())
                        .fold(0.0, f64::max);
                    if apart > tolerance_px {
                        out.insert(skeleton.column_bone[column]);
                    }
                }
            }
        }
    }
    // A baked sinew bone takes its descendants along.
    for bone in out.clone() {
        if matches!(skeleton.bones[bone].source, BoneSource::Bone(_)) {
            out.extend(skeleton.descendants(bone));
        }
    }
    Ok(out)
}

/// Timelines (`rotate`, `translate`, `scale`, `shear`) of every bone in `bones`, from the path's
/// transformations at `times`. Timelines that stay at the setup value throughout are left out.
pub fn baked_timelines(
    skeleton: &Skeleton,
    frame: &SpineFrame,
    bones: &BTreeSet<usize>,
    times: &[f64],
    samples: &[(Pose, Vec<Affine>)],
) -> Result<BTreeMap<String, Map<String, Value>>, SpineError> {
    // World transformation of bone i at sample s (Spine world), for any bone.
    let world = |i: usize, s: usize| -> Affine {
        let bone = &skeleton.bones[i];
        match bone.column {
            Some(column) => frame
                .spine_affine(&samples[s].1[column])
                .then_after(&bone.setup_world),
            None => bone.setup_world,
        }
    };
    let mut out = BTreeMap::new();
    for &i in bones {
        let bone = &skeleton.bones[i];
        let setup = bone.setup;
        let mut rows: Vec<[f64; 7]> = Vec::with_capacity(times.len());
        let (mut last_rotation, mut last_shear) = (0.0, 0.0);
        for (s, &t) in times.iter().enumerate() {
            let parent_world = bone.parent.map_or(Affine::identity(), |p| world(p, s));
            let local = parent_world
                .inverse()
                .ok_or_else(|| {
                    SpineError::Singular(skeleton.bones[bone.parent.unwrap_or(0)].name.clone())
                })?
                .then_after(&world(i, s));
            let l = BoneLocal::from_matrix(&local);
            let rotation = unwrap_deg(l.rotation_deg - setup.rotation_deg, last_rotation);
            let shear = unwrap_deg(l.shear_y_deg - setup.shear_y_deg, last_shear);
            last_rotation = rotation;
            last_shear = shear;
            rows.push([
                t,
                rotation,
                l.x - setup.x,
                l.y - setup.y,
                l.scale_x / setup.scale_x,
                l.scale_y / setup.scale_y,
                shear,
            ]);
        }
        let mut timelines = Map::new();
        let unchanged = |cols: &[usize], rest: f64| {
            rows.iter()
                .all(|r| cols.iter().all(|&c| (r[c] - rest).abs() <= 1e-12))
        };
        if !unchanged(&[1], 0.0) {
            timelines.insert(
                "rotate".into(),
                rows.iter()
                    .map(|r| json!({"time": num(r[0]), "value": num(r[1])}))
                    .collect(),
            );
        }
        let two = |cx: usize, cy: usize| -> Value {
            rows.iter()
                .map(|r| json!({"time": num(r[0]), "x": num(r[cx]), "y": num(r[cy])}))
                .collect()
        };
        if !unchanged(&[2, 3], 0.0) {
            timelines.insert("translate".into(), two(2, 3));
        }
        if !unchanged(&[4, 5], 1.0) {
            timelines.insert("scale".into(), two(4, 5));
        }
        if !unchanged(&[6], 0.0) {
            timelines.insert(
                "shear".into(),
                rows.iter()
                    .map(|r| json!({"time": num(r[0]), "x": 0.0, "y": num(r[6])}))
                    .collect(),
            );
        }
        if !timelines.is_empty() {
            out.insert(bone.name.clone(), timelines);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bake_times_end_on_the_duration() {
        assert_eq!(bake_times(0.5, 4.0), vec![0.0, 0.25, 0.5]);
        assert_eq!(bake_times(0.6, 4.0), vec![0.0, 0.25, 0.5, 0.6]);
        assert_eq!(bake_times(0.0, 30.0), vec![0.0]);
        // 0.7 · 30 rounds to 20.999…: no extra key a hair before the end.
        assert_eq!(bake_times(0.7, 30.0).len(), 22);
    }
}
