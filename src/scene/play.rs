//! Playing an animation on a scene: (rig, animation, time) → the pose and its handle transforms.
//!
//! In: a [`Scene`], an [`Animation`], [`PlayOptions`] (curve evaluation, looping) and times in
//! seconds. Out: one [`Frame`] per time.
//!
//! The frame at time t is a function of (rig, animation, t) alone, whatever else is asked for
//! and in whatever order:
//! - without momentum, it is the animation's pose at t posed by [`Scene::handle_transforms`]
//!   (the skinning IK solved from the forward-kinematics pose, never warm-started), so frames
//!   are independent and [`frames`] solves them in parallel;
//! - with momentum ([`crate::ik::IkOptions::momentum`]), the motion depends on its history, so
//!   it is defined by simulation from the animation's start at the fixed step
//!   [`crate::ik::IkOptions::momentum_step_s`] up to the last whole step before t, then one
//!   shorter step to t (taken on a copy, so the simulation's grid never depends on the times
//!   asked for). A [`Playhead`] keeps the simulation, so playing forward costs one pass; asking
//!   for an earlier time restarts it.

use crate::anim::{Animation, SampleOptions};
use crate::ik::RigIk;
use crate::pipeline::{PipelineError, Scene};
use crate::rig::{Affine, Pose};
use rayon::prelude::*;

/// Latest time a rig with momentum is simulated to, s: the simulation runs from the
/// animation's start, one solve per momentum step (an hour at 1/60 s is 216,000 solves).
pub const MAX_SIMULATED_S: f64 = 3600.0;

/// Steps within this share of a step of a grid time are that grid time (absorbs the rounding
/// of times like k/30 s on a 1/60 s grid).
const GRID_SNAP: f64 = 1e-9;

/// An animation's pose at one time and the skinning transformations it poses the rig with.
#[derive(Clone, Debug)]
pub struct Frame {
    pub time_s: f64,
    /// The animation sampled at `time_s` (drags included).
    pub pose: Pose,
    /// One transformation per handle column ([`crate::rig::handle_columns`] order).
    pub transforms: Vec<Affine>,
}

/// How an animation is played.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlayOptions {
    /// How curves are evaluated. Default: exactly.
    pub sampling: SampleOptions,
    /// Whether times past the end wrap to the start (playback) or hold the end (baking, whose
    /// last key is the end itself). Default false.
    pub looping: bool,
}

/// An animation played on a scene at any times (see the module doc).
pub struct Playhead<'a> {
    scene: &'a Scene,
    animation: &'a Animation,
    options: PlayOptions,
    /// The skinning-IK solver for static poses, made on first need; reused for its
    /// factorization only ([`RigIk::solve_pose`]).
    ik: Option<RigIk>,
    simulation: Option<Simulation>,
    physics: Option<super::physics::PhysicsRun>,
}

/// The momentum simulation at `steps · step_s`.
struct Simulation {
    ik: RigIk,
    steps: u64,
    last: Vec<Affine>,
}

impl<'a> Playhead<'a> {
    pub fn new(scene: &'a Scene, animation: &'a Animation, options: PlayOptions) -> Self {
        Playhead {
            scene,
            animation,
            options,
            ik: None,
            simulation: None,
            physics: None,
        }
    }

    /// Whether the rig carries momentum (frames depend on the motion before them).
    pub fn has_momentum(&self) -> bool {
        !self.scene.doc.options.ik.momentum.is_empty()
    }

    /// The animation's pose at `time_s` (drags included, not yet solved).
    pub fn pose_at(&self, time_s: f64) -> Pose {
        self.animation
            .sample_with(time_s, self.options.looping, &self.options.sampling)
    }

    /// Whether the rig has physics constraints (frames depend on the motion before them).
    pub fn has_physics(&self) -> bool {
        !self.scene.doc.handles.physics.is_empty()
    }

    /// The frame at `time_s`.
    pub fn frame(&mut self, time_s: f64) -> Result<Frame, PipelineError> {
        let pose = self.pose_at(time_s);
        let transforms = if self.has_physics() {
            if self.has_momentum() {
                return Err(PipelineError::PhysicsWithMomentum);
            }
            let (scene, animation, options) = (self.scene, self.animation, self.options);
            let mut ik = self.ik.take();
            let mut posed = |t: f64| {
                let pose = animation.sample_with(t, options.looping, &options.sampling);
                scene.handle_transforms_with(&mut ik, &pose)
            };
            let out = super::physics::transforms_at(
                &mut self.physics,
                &scene.doc.handles,
                time_s,
                &mut posed,
            );
            self.ik = ik;
            out?
        } else if self.has_momentum() {
            self.simulate(time_s, &pose)?
        } else {
            self.scene.handle_transforms_with(&mut self.ik, &pose)?
        };
        Ok(Frame {
            time_s,
            pose,
            transforms,
        })
    }

    /// The momentum simulation's transforms at `time_s`, whose pose is `pose`.
    fn simulate(&mut self, time_s: f64, pose: &Pose) -> Result<Vec<Affine>, PipelineError> {
        if !(time_s.is_finite() && (0.0..=MAX_SIMULATED_S).contains(&time_s)) {
            return Err(PipelineError::SimulatedTime(time_s));
        }
        let step_s = self.scene.doc.options.ik.momentum_step_s;
        let whole = (time_s / step_s + GRID_SNAP).floor() as u64;
        let (animation, options) = (self.animation, self.options);
        let sample = |t: f64| animation.sample_with(t, options.looping, &options.sampling);
        let restart = self.simulation.as_ref().is_none_or(|s| s.steps > whole);
        if restart {
            let mut ik = self.scene.rig_ik()?;
            // The start: no motion yet, so no momentum term.
            let last = ik.step(&sample(0.0), 0.0)?.transforms;
            self.simulation = Some(Simulation { ik, steps: 0, last });
        }
        let Some(simulation) = self.simulation.as_mut() else {
            return Err(PipelineError::Ik(crate::ik::IkError::Singular));
        };
        while simulation.steps < whole {
            let t = (simulation.steps + 1) as f64 * step_s;
            simulation.last = simulation.ik.step(&sample(t), step_s)?.transforms;
            simulation.steps += 1;
        }
        let remainder_s = time_s - whole as f64 * step_s;
        if remainder_s <= GRID_SNAP * step_s {
            return Ok(simulation.last.clone());
        }
        let mut ik = simulation.ik.clone();
        Ok(ik.step(pose, remainder_s)?.transforms)
    }
}

/// The frames of `animation` at `times_s` (any order); see [`Playhead::frames`].
pub fn frames(
    scene: &Scene,
    animation: &Animation,
    times_s: &[f64],
    options: PlayOptions,
) -> Result<Vec<Frame>, PipelineError> {
    Playhead::new(scene, animation, options).frames(times_s)
}

impl Playhead<'_> {
    /// The frames at `times_s` (any order). Without momentum they are solved in parallel;
    /// with it, in order of time on this playhead's simulation (so asking for consecutive runs
    /// of times simulates once forward). Either way each frame is what [`Playhead::frame`]
    /// gives for its time alone.
    pub fn frames(&mut self, times_s: &[f64]) -> Result<Vec<Frame>, PipelineError> {
        if self.has_momentum() || self.has_physics() {
            let mut order: Vec<usize> = (0..times_s.len()).collect();
            order.sort_by(|&a, &b| times_s[a].total_cmp(&times_s[b]));
            let mut out: Vec<Option<Frame>> = vec![None; times_s.len()];
            for k in order {
                out[k] = Some(self.frame(times_s[k])?);
            }
            return Ok(out.into_iter().flatten().collect());
        }
        let (scene, animation, options) = (self.scene, self.animation, self.options);
        if !animation.ik.is_empty() {
            // Made here, outside the thread pool: the precomputation runs rayon work of its
            // own, and a worker that steals a frame while initializing the shared cell would
            // wait on itself.
            scene.rig_ik()?;
        }
        times_s
            .par_iter()
            .map_init(
                || None,
                |ik, &time_s| {
                    let pose = animation.sample_with(time_s, options.looping, &options.sampling);
                    let transforms = scene.handle_transforms_with(ik, &pose)?;
                    Ok(Frame {
                        time_s,
                        pose,
                        transforms,
                    })
                },
            )
            .collect()
    }
}
