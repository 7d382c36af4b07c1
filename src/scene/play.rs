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
//!
//! Looping. An animation flagged `loop` ([`Animation::looping`]) is a cycle: its motion with a
//! history (physics constraints, [`super::physics`]; skinning-IK momentum) is shown in its
//! periodic steady state, the motion as it is once the cycle has played for ever, so that its
//! end runs into its start without a jump. The simulation runs period after period on one
//! period's grid ([`Cycle`]: updates at k · step below the duration, the same in every period;
//! across the loop a shorter step when the duration is not a whole number of steps) until the
//! motion repeats: the transforms of the first [`STEADY_WINDOW_UPDATES`] updates of a period
//! within [`STEADY_TOLERANCE_PX`] of the previous period's at the corners of the rig's rest
//! bounding box, or [`STEADY_MAX_PERIODS`] periods simulated. The frame at t in [0, duration]
//! is then that last period's at t (the end: its next period's first update, with the pose at
//! the end). Which period that is depends on the rig and the animation only, so frames stay a
//! function of (rig, animation, t). An animation without the flag starts from rest at 0, as
//! before, bit for bit; a flagged animation without physics or momentum is unaffected.
//!
//! The flag and [`PlayOptions::looping`] are two things: the flag says what the motion inside
//! [0, duration] is (the steady state of a cycle, or a start from rest); `looping` only says
//! what a time outside it shows (wrapped into it, or held at the end). So every consumer of an
//! animation flagged `loop` — `sinew render` and `pose`, the editor, the Spine bake
//! ([`crate::export::spine::bake::sample_path`], hence `--match-runtime spine` for the baked
//! lines) and the glTF bake — shows the steady state, whether it wraps times or not. What a
//! runtime that simulates physics itself (Spine 4.2) shows is the runtime's: it starts from
//! rest ([`crate::export::spine::played`]).

use crate::anim::sample::local_time_s;
use crate::anim::{Animation, SampleOptions};
use crate::geom::Point;
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

/// How close, px, two successive periods of a looping animation's simulation must come for its
/// motion to be taken as repeating: the largest distance between where their transforms put
/// the corners of the rig's rest bounding box, over the first [`STEADY_WINDOW_UPDATES`]
/// updates of each period (see the module doc).
pub const STEADY_TOLERANCE_PX: f64 = 1e-3;

/// The most periods a looping animation is simulated for to reach its steady state (fewer when
/// they would pass [`MAX_SIMULATED_S`], but at least two); a motion that has not repeated by
/// then is shown as the last period simulated.
pub const STEADY_MAX_PERIODS: u32 = 20;

/// How many updates at the start of a period stand for the simulation's state there when two
/// periods are compared: positions over a few updates also pin down how fast things move.
pub const STEADY_WINDOW_UPDATES: u64 = 8;

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
    /// A looping animation's physics in its steady state, found on first need.
    steady_physics: Option<Steady<super::physics::PhysicsRun>>,
    /// A looping animation's momentum simulation in its steady state, found on first need.
    steady_momentum: Option<Steady<RigIk>>,
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
            steady_physics: None,
            steady_momentum: None,
        }
    }

    /// The grid of one period at `step_s` when the animation loops (flagged `loop`, lasting
    /// longer than 0), else `None`: its simulations start from rest.
    fn cycle(&self, step_s: f64) -> Option<Cycle> {
        if self.animation.looping {
            Cycle::new(self.animation.duration_s(), step_s)
        } else {
            None
        }
    }

    /// How many periods a looping animation's simulation ran to reach its steady state (the
    /// period shown included), once a frame needed it; `None` before, or when nothing is
    /// simulated in a steady state (no loop flag, no physics or momentum).
    pub fn steady_periods(&self) -> Option<u32> {
        let physics = self.steady_physics.as_ref().map(|s| s.periods);
        physics.or(self.steady_momentum.as_ref().map(|s| s.periods))
    }

    /// The time within the animation that `time_s` shows (wrapped or held by
    /// [`PlayOptions::looping`]), for a simulation's steady state: a time must be a finite
    /// number ≥ 0.
    fn local_time_s(&self, time_s: f64) -> Result<f64, PipelineError> {
        if !(time_s.is_finite() && time_s >= 0.0) {
            return Err(PipelineError::SimulatedTime(time_s));
        }
        Ok(local_time_s(
            self.animation.duration_s(),
            time_s,
            self.options.looping,
        ))
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
            if let Some(cycle) = self.cycle(super::physics::update_step_s()) {
                self.steady_physics(cycle, time_s)?
            } else {
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
            }
        } else if self.has_momentum() {
            match self.cycle(self.scene.doc.options.ik.momentum_step_s) {
                Some(cycle) => self.steady_momentum(cycle, time_s, &pose)?,
                None => self.simulate(time_s, &pose)?,
            }
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

    /// The physics of a looping animation in its steady state, at `time_s`.
    fn steady_physics(&mut self, cycle: Cycle, time_s: f64) -> Result<Vec<Affine>, PipelineError> {
        let local_s = self.local_time_s(time_s)?;
        let mut ik = self.ik.take();
        let out = self.steady_physics_with(&mut ik, cycle, local_s);
        self.ik = ik;
        out
    }

    /// [`Playhead::steady_physics`] at `local_s` within the period, static poses solved with
    /// `ik`.
    fn steady_physics_with(
        &mut self,
        ik: &mut Option<RigIk>,
        cycle: Cycle,
        local_s: f64,
    ) -> Result<Vec<Affine>, PipelineError> {
        let (scene, animation, sampling) = (self.scene, self.animation, self.options.sampling);
        let handles = &scene.doc.handles;
        // The pose at a time within the period (the end included).
        let posed = |ik: &mut Option<RigIk>, t: f64| {
            let pose = animation.sample_with(t, false, &sampling);
            scene.handle_transforms_with(ik, &pose)
        };
        let run = {
            let mut update = |run: &mut super::physics::PhysicsRun, t: f64, advance_s: f64| {
                Ok(run.update_after(handles, posed(ik, t)?, advance_s))
            };
            if self.steady_physics.is_none() {
                let fresh = super::physics::PhysicsRun::new(handles);
                let corners = crate::playback::rest_corners(&scene.doc);
                self.steady_physics = Some(Steady::settle(fresh, cycle, &corners, &mut update)?);
            }
            let Some(steady) = self.steady_physics.as_mut() else {
                return Err(PipelineError::Ik(crate::ik::IkError::Singular));
            };
            let (run, last, on_grid) = steady.advance(local_s, &mut update)?;
            if on_grid {
                return Ok(last.to_vec());
            }
            run.clone()
        };
        Ok(run.pose(handles, posed(ik, local_s)?))
    }

    /// The momentum simulation of a looping animation in its steady state, at `time_s`, whose
    /// pose is `pose`.
    fn steady_momentum(
        &mut self,
        cycle: Cycle,
        time_s: f64,
        pose: &Pose,
    ) -> Result<Vec<Affine>, PipelineError> {
        let local_s = self.local_time_s(time_s)?;
        let (animation, sampling) = (self.animation, self.options.sampling);
        let mut update = |ik: &mut RigIk, t: f64, advance_s: f64| {
            let pose = animation.sample_with(t, false, &sampling);
            Ok(ik.step(&pose, advance_s)?.transforms)
        };
        if self.steady_momentum.is_none() {
            let fresh = self.scene.rig_ik()?;
            let corners = crate::playback::rest_corners(&self.scene.doc);
            self.steady_momentum = Some(Steady::settle(fresh, cycle, &corners, &mut update)?);
        }
        let Some(steady) = self.steady_momentum.as_mut() else {
            return Err(PipelineError::Ik(crate::ik::IkError::Singular));
        };
        let (ik, last, on_grid) = steady.advance(local_s, &mut update)?;
        if on_grid {
            return Ok(last.to_vec());
        }
        let remainder_s = local_s - cycle.time_s(cycle.place(local_s).0);
        let mut ik = ik.clone();
        Ok(ik.step(pose, remainder_s)?.transforms)
    }
}

/// The simulation grid of one period of a looping animation: updates at k · `step_s` for every
/// k with k · `step_s` below the duration (the same times in every period), the next period's
/// first update `duration_s` after the period's first, so across the loop the clock advances
/// by what is left of the last step (a whole step when the duration is a whole number of
/// steps, as on the continuous grid).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cycle {
    pub duration_s: f64,
    pub step_s: f64,
    /// Updates per period (≥ 1).
    pub updates: u64,
}

impl Cycle {
    /// The grid of an animation lasting `duration_s` at `step_s`; `None` unless both are finite
    /// and > 0.
    pub fn new(duration_s: f64, step_s: f64) -> Option<Cycle> {
        if !(duration_s.is_finite() && duration_s > 0.0 && step_s.is_finite() && step_s > 0.0) {
            return None;
        }
        let updates = (duration_s / step_s - GRID_SNAP).floor().max(0.0) as u64 + 1;
        Some(Cycle {
            duration_s,
            step_s,
            updates,
        })
    }

    /// The time within the period of update `k` (`k` = [`Cycle::updates`]: the end, which is the
    /// next period's first update).
    pub fn time_s(&self, k: u64) -> f64 {
        if k >= self.updates {
            self.duration_s
        } else {
            k as f64 * self.step_s
        }
    }

    /// How far the clock advances before update `k` (`k` = 0: across the loop, from the last
    /// update of the period before).
    pub fn advance_s(&self, k: u64) -> f64 {
        match k {
            0 => self.duration_s - self.time_s(self.updates - 1),
            k => self.time_s(k) - self.time_s(k - 1),
        }
    }

    /// The last update at or before `local_s` (a time in [0, duration]; within a billionth of
    /// a step of an update's time is that time), and whether `local_s` is its time.
    pub fn place(&self, local_s: f64) -> (u64, bool) {
        let snap = GRID_SNAP * self.step_s;
        if local_s >= self.duration_s - snap {
            return (self.updates, true);
        }
        let k = ((local_s / self.step_s + GRID_SNAP).floor().max(0.0) as u64).min(self.updates - 1);
        (k, local_s - self.time_s(k) <= snap)
    }
}

/// One update of a simulation: its state, the time within the period, and the clock's advance
/// since the last update (ignored by the first update of all). Returns the update's transforms.
type Update<'u, S> = dyn FnMut(&mut S, f64, f64) -> Result<Vec<Affine>, PipelineError> + 'u;

/// A simulation over a looping animation in its periodic steady state (see the module doc).
pub(crate) struct Steady<S> {
    cycle: Cycle,
    /// The state at the start of the period shown.
    start: S,
    /// Periods simulated to find it (the period shown included).
    pub periods: u32,
    /// Playing through the period shown: the state after `done` updates, and the last one's
    /// transforms.
    cursor: Option<(S, u64, Vec<Affine>)>,
}

impl<S: Clone> Steady<S> {
    /// Simulates `fresh` (at rest, before its first update) period after period of `cycle`
    /// until the motion repeats within [`STEADY_TOLERANCE_PX`] at `corners`, or
    /// [`STEADY_MAX_PERIODS`].
    pub(crate) fn settle(
        fresh: S,
        cycle: Cycle,
        corners: &[Point],
        update: &mut Update<'_, S>,
    ) -> Result<Self, PipelineError> {
        let affordable = (MAX_SIMULATED_S / cycle.duration_s).floor().max(2.0);
        let max_periods = f64::from(STEADY_MAX_PERIODS).min(affordable) as u32;
        let window = cycle.updates.min(STEADY_WINDOW_UPDATES) as usize;
        let mut state = fresh;
        let mut previous: Option<Vec<Vec<Affine>>> = None;
        let mut periods = 0;
        loop {
            let start = state.clone();
            let mut seen = Vec::with_capacity(window);
            for k in 0..cycle.updates {
                let transforms = update(&mut state, cycle.time_s(k), cycle.advance_s(k))?;
                if seen.len() < window {
                    seen.push(transforms);
                }
            }
            periods += 1;
            let repeats = previous
                .as_ref()
                .is_some_and(|p| apart_px(p, &seen, corners) <= STEADY_TOLERANCE_PX);
            if repeats || periods >= max_periods {
                return Ok(Steady {
                    cycle,
                    start,
                    periods,
                    cursor: None,
                });
            }
            previous = Some(seen);
        }
    }

    /// Plays the period shown up to the last update at or before `local_s` (restarting it when
    /// that is before the cursor): the state after it, its transforms, and whether `local_s`
    /// is its time.
    pub(crate) fn advance(
        &mut self,
        local_s: f64,
        update: &mut Update<'_, S>,
    ) -> Result<(&S, &[Affine], bool), PipelineError> {
        let (k, on_grid) = self.cycle.place(local_s);
        if self.cursor.as_ref().is_some_and(|c| c.1 > k + 1) {
            self.cursor = None;
        }
        let (state, done, last) = self
            .cursor
            .get_or_insert_with(|| (self.start.clone(), 0, Vec::new()));
        while *done <= k {
            *last = update(state, self.cycle.time_s(*done), self.cycle.advance_s(*done))?;
            *done += 1;
        }
        Ok((state, last, on_grid))
    }
}

/// The largest distance between where two runs of transforms put `corners`.
fn apart_px(a: &[Vec<Affine>], b: &[Vec<Affine>], corners: &[Point]) -> f64 {
    let mut worst = 0.0_f64;
    for (ta, tb) in a.iter().zip(b) {
        for (x, y) in ta.iter().zip(tb) {
            for &p in corners {
                worst = worst.max((x.apply(p) - y.apply(p)).norm());
            }
        }
    }
    worst
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::anim::timeline::{BoneTimelines, Key};
    use crate::anim::Curve;
    use crate::geom::Point;
    use crate::io::BuildOptions;
    use crate::pipeline::{build_rig, Layer};
    use crate::rig::physics::PhysicsConstraint;
    use crate::rig::{Bone, Handles};

    /// A bar 120 px long, two bones end to end; the outer one swings on a physics constraint
    /// (or, with `momentum`, carries momentum instead).
    fn bar_scene(momentum: bool) -> Scene {
        let image = image::RgbaImage::from_fn(140, 40, |x, y| {
            let inside = (10..130).contains(&x) && (12..28).contains(&y);
            image::Rgba(if inside { [200, 80, 40, 255] } else { [0; 4] })
        });
        let bone = |name: &str, parent: Option<&str>, head: f64, tail: f64| Bone {
            name: name.into(),
            parent: parent.map(Into::into),
            head: Point::new(head, 20.0),
            tail: Point::new(tail, 20.0),
        };
        let mut handles = Handles {
            bones: vec![
                bone("root", None, 12.0, 70.0),
                bone("tip", Some("root"), 70.0, 128.0),
            ],
            ..Default::default()
        };
        if !momentum {
            handles.physics = vec![serde_json::from_value::<PhysicsConstraint>(
                serde_json::json!({"name": "sway", "bone": "tip", "rotate": 1, "damping": 0.9}),
            )
            .unwrap()];
        }
        let dir = crate::test_scratch::scratch("steady-bar");
        let layer = Layer::whole("bar", dir.path().join("bar.png"), image.clone());
        let (mut doc, _) =
            build_rig(&[layer], dir.path(), &BuildOptions::default(), &handles).unwrap();
        if momentum {
            doc.options.ik.momentum.insert("tip".into(), 0.05);
        }
        Scene::new(doc, &[image]).unwrap()
    }

    /// The root swinging 0 → 25° → 0 over 0.55 s (not a whole number of 1/60 s steps).
    fn swing(looping: bool) -> Animation {
        let key = |time: f64, value: f64| Key {
            time,
            value,
            curve: Curve::Linear,
        };
        let mut animation = Animation {
            looping,
            ..Default::default()
        };
        animation.bones.insert(
            "root".into(),
            BoneTimelines {
                rotate: Some(vec![key(0.0, 0.0), key(0.275, 25.0), key(0.55, 0.0)]),
                ..Default::default()
            },
        );
        animation
    }

    /// The largest distance between where two frames put the bar's corners.
    fn apart(a: &Frame, b: &Frame) -> f64 {
        let corners = [Point::new(10.0, 12.0), Point::new(130.0, 28.0)];
        apart_px(
            std::slice::from_ref(&a.transforms),
            std::slice::from_ref(&b.transforms),
            &corners,
        )
    }

    #[test]
    fn a_cycle_has_one_grid_every_period() {
        let step = 1.0 / 60.0;
        let whole = Cycle::new(1.0, step).unwrap();
        assert_eq!(whole.updates, 60);
        assert!((whole.advance_s(0) - step).abs() < 1e-12);
        let cycle = Cycle::new(0.56, step).unwrap();
        assert_eq!(cycle.updates, 34);
        assert!((cycle.advance_s(0) - 0.01).abs() < 1e-12);
        assert_eq!(cycle.place(0.0), (0, true));
        assert_eq!(cycle.place(0.5), (30, true));
        assert_eq!(cycle.place(0.555), (33, false));
        assert_eq!(cycle.place(0.56), (34, true));
        assert!(Cycle::new(0.0, step).is_none());
    }

    #[test]
    fn a_looping_animations_physics_reaches_its_periodic_steady_state() {
        let scene = bar_scene(false);
        let (looping, once) = (swing(true), swing(false));
        let d = looping.duration_s();
        let held = PlayOptions::default();
        let mut head = Playhead::new(&scene, &looping, held);
        let (start, end) = (head.frame(0.0).unwrap(), head.frame(d).unwrap());
        let periods = head.steady_periods().unwrap();
        assert!((2..STEADY_MAX_PERIODS).contains(&periods), "{periods}");
        // The end runs into the start: the motion repeats.
        let seam = apart(&start, &end);
        assert!(seam < 10.0 * STEADY_TOLERANCE_PX, "seam {seam} px");
        // From rest, the end is far from the start: the tip still swings.
        let mut fresh = Playhead::new(&scene, &once, held);
        let restarted = apart(&fresh.frame(0.0).unwrap(), &fresh.frame(d).unwrap());
        assert!(restarted > 1.0, "the physics moved nothing: {restarted} px");
        // A function of t: any order, any playhead; wrapped times show the same frame.
        let later = head.frame(0.3).unwrap();
        let wrapped = PlayOptions {
            looping: true,
            ..held
        };
        let mut other = Playhead::new(&scene, &looping, wrapped);
        assert_eq!(
            other.frame(0.3 + 2.0 * d).unwrap().transforms,
            later.transforms
        );
        assert_eq!(other.frame(0.0).unwrap().transforms, start.transforms);
        let between = head.frame(0.123).unwrap();
        let again = frames(&scene, &looping, &[0.5, 0.123], held).unwrap();
        assert_eq!(again[1].transforms, between.transforms);
    }

    #[test]
    fn a_looping_animations_momentum_reaches_its_periodic_steady_state() {
        let scene = bar_scene(true);
        let (looping, once) = (swing(true), swing(false));
        let d = looping.duration_s();
        let mut head = Playhead::new(&scene, &looping, PlayOptions::default());
        let seam = apart(&head.frame(0.0).unwrap(), &head.frame(d).unwrap());
        assert!(head.steady_periods().is_some_and(|p| p >= 2));
        assert!(seam < 10.0 * STEADY_TOLERANCE_PX, "seam {seam} px");
        let mut fresh = Playhead::new(&scene, &once, PlayOptions::default());
        let restarted = apart(&fresh.frame(0.0).unwrap(), &fresh.frame(d).unwrap());
        assert!(
            restarted > 10.0 * seam,
            "momentum moved nothing: {restarted} px"
        );
    }

    #[test]
    fn animations_without_the_flag_play_as_before_bit_for_bit() {
        let scene = bar_scene(false);
        let once = swing(false);
        let times = [0.0, 0.1, 0.2345, 0.55, 0.9];
        let options = PlayOptions {
            looping: true,
            ..Default::default()
        };
        let played = frames(&scene, &once, &times, options).unwrap();
        // The simulation from rest at 0, as scene::physics runs it.
        let handles = &scene.doc.handles;
        let mut posed = |t: f64| {
            Ok(crate::rig::handle_transforms(
                handles,
                &once.sample(t, true),
            )?)
        };
        for (frame, &t) in played.iter().zip(&times) {
            let live = super::super::physics::transforms_at(&mut None, handles, t, &mut posed);
            assert_eq!(frame.transforms, live.unwrap(), "at {t} s");
        }
        // A flagged animation on a rig without physics or momentum is its static poses.
        let still = scene.without_physics();
        let flagged = frames(&still, &swing(true), &times, options).unwrap();
        let plain = frames(&still, &once, &times, options).unwrap();
        for (a, b) in flagged.iter().zip(&plain) {
            assert_eq!(a.transforms, b.transforms);
        }
    }
}
