//! What Spine's runtime plays of an export, reproduced in sinew (`--match-runtime spine`).
//!
//! In: a scene, one of its animations and the [`SpineOptions`] of the export. Out: an
//! [`AsPlayed`] animation whose frame at any time is what spine-core computes from the exported
//! JSON at that time — on the baked keys and between them.
//!
//! The export writes each animation as native timelines plus, for the bones whose motion native
//! timelines cannot express (skinning IK, momentum, longer bone-IK chains), linear keys at the
//! bake times ([`super::plan_bake`]). The runtime samples native timelines with its own curve
//! evaluation and interpolates the baked keys linearly in each bone's local rotation,
//! translation, scale and shear. [`as_played`] builds the same thing as a sinew animation: the
//! authored timelines, the baked handles' timelines replaced by linear keys decomposed from the
//! bake's frames ([`crate::rig::pose::pose_from_transforms`], local to the parent bone as Spine's
//! keys are), no `ik` drag timelines, and the bone-IK constraints the export switched off left
//! out of the rig. Sampled with [`CurveEvaluation::SpineRuntime`] and posed by forward
//! kinematics, it plays as the runtime does.
//!
//! Physics: for 4.1 and 4.3 it is baked like any other motion, so an animation flagged `loop`
//! plays its baked steady state ([`crate::scene::play`]). 4.2's runtime simulates it itself,
//! from rest when the animation starts and on across its loops whatever the animation's `loop`
//! flag: [`AsPlayed::frame`] does the same ([`crate::scene::physics::transforms_at`]), times
//! past the end wrapping when asked to loop.
//!
//! A cage with some vertices baked has its whole polygon keyed at the bake times (sinew keys
//! cages as whole polygons); its unbaked vertices then follow the keys linearly between bake
//! times where the runtime would play their authored curves.

use super::constraints;
use super::frame::SpineFrame;
use super::skeleton::{build_skeleton, BoneSource};
use super::{plan_bake, BakePlan, SpineError, SpineOptions};
use crate::anim::{Animation, CurveEvaluation, SampleOptions};
use crate::pipeline::{PipelineError, Scene};
use crate::rig::{handle_transforms, Handles};
use crate::scene::Frame;
use std::collections::BTreeSet;

/// The options of `sinew spine` that change what the runtime plays: what `--match-runtime
/// spine` reproduces. Meshes decimated by `--preset game` are not reproduced (sinew poses its
/// own meshes; the runtime's decimated ones stay within the preset's tolerance).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExportPlayed {
    /// The Spine line exported for (4.1 has no physics: it is baked). Default 4.2.
    pub version: super::SpineVersion,
    /// Keys per second of baked motion, in (0, [`super::MAX_BAKE_FPS`]]. Default 30.
    pub bake_fps: f64,
}

impl Default for ExportPlayed {
    fn default() -> Self {
        let options = SpineOptions::default();
        ExportPlayed {
            version: options.version,
            bake_fps: options.bake_fps,
        }
    }
}

impl ExportPlayed {
    /// The export options these settings stand for (the rest at their defaults).
    pub fn options(&self) -> SpineOptions {
        SpineOptions {
            version: self.version,
            bake_fps: self.bake_fps,
            ..SpineOptions::default()
        }
    }
}

/// An animation as Spine's runtime plays its export (see the module doc).
#[derive(Clone, Debug)]
pub struct AsPlayed {
    /// Authored timelines, baked handles keyed at the bake times, no drags.
    pub animation: Animation,
    /// The rig's handles with only the bone-IK constraints the runtime still solves.
    pub handles: Handles,
}

impl AsPlayed {
    /// The frame at `time_s` (wrapping past the end when `looping`).
    pub fn frame(&self, time_s: f64, looping: bool) -> Result<Frame, PipelineError> {
        let sampling = SampleOptions {
            curves: CurveEvaluation::SpineRuntime,
        };
        let pose = self.animation.sample_with(time_s, looping, &sampling);
        let transforms = if self.handles.physics.is_empty() {
            handle_transforms(&self.handles, &pose)?
        } else {
            // Physics: the runtime updated at a fixed rate from the start (scene::physics).
            let mut posed = |t: f64| {
                let pose = self.animation.sample_with(t, looping, &sampling);
                Ok(handle_transforms(&self.handles, &pose)?)
            };
            crate::scene::physics::transforms_at(&mut None, &self.handles, time_s, &mut posed)?
        };
        Ok(Frame {
            time_s,
            pose,
            transforms,
        })
    }
}

/// `animation` (named `name`) of `scene` as the runtime plays its export under `options`.
pub fn as_played(
    scene: &Scene,
    name: &str,
    animation: &Animation,
    options: &SpineOptions,
) -> Result<AsPlayed, SpineError> {
    let doc = &scene.doc;
    let frame = SpineFrame::for_canvas(doc.canvas);
    let skeleton = build_skeleton(&doc.handles, &frame, &options.root_bone)?;
    let BakePlan {
        times,
        samples,
        baked,
        switched_off,
    } = plan_bake(scene, name, animation, &skeleton, options)?;
    let mut played = Animation {
        ik: Vec::new(),
        ..animation.clone()
    };
    if !baked.is_empty() {
        let poses = samples
            .iter()
            .map(|(_, transforms)| crate::rig::pose::pose_from_transforms(&doc.handles, transforms))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| SpineError::Pose(PipelineError::Pose(e)))?;
        let mut keyed = crate::playback::keyed_animation(&doc.handles, &times, &poses);
        let mut cages = BTreeSet::new();
        for &bone in &baked {
            match skeleton.bones[bone].source {
                BoneSource::Bone(i) => {
                    let name = &doc.handles.bones[i].name;
                    if let Some(t) = keyed.bones.remove(name) {
                        played.bones.insert(name.clone(), t);
                    }
                }
                BoneSource::Point(i) => {
                    let name = &doc.handles.points[i].name;
                    if let Some(t) = keyed.points.remove(name) {
                        played.points.insert(name.clone(), t);
                    }
                }
                BoneSource::CageVertex { cage, .. } => {
                    cages.insert(cage);
                }
                BoneSource::Root | BoneSource::Region(_) => {}
            }
        }
        for cage in cages {
            let name = &doc.handles.cages[cage].name;
            if let Some(keys) = keyed.cages.remove(name) {
                played.cages.insert(name.clone(), keys);
            }
        }
    }
    let solved: Vec<usize> = constraints::exported(&doc.handles)
        .into_iter()
        .filter(|c| !switched_off.contains(c))
        .collect();
    let mut handles = constraints::with_constraints(&doc.handles, &solved);
    if !super::physics::native(options.version) {
        // Not simulated by that runtime: baked into keys instead.
        handles.physics.clear();
    }
    Ok(AsPlayed {
        animation: played,
        handles,
    })
}
