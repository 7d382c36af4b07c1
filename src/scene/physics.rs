//! Physics constraints over time: the skeleton updated at a fixed rate from the animation's
//! start.
//!
//! In: the rig's [`Handles`] (its `physics` constraints) and a way to pose the animation at a
//! time (one transform per handle column, from the one path: forward kinematics, bone IK,
//! skinning IK). Out: the transforms at a time with the physics constraints applied: each
//! constrained bone's world frame moved by [`PhysicsState::update`] and its descendant bones
//! and the points they carry taken along (as Spine's children inherit their parent's world
//! transform), constraints in
//! list order (list a constrained ancestor first).
//!
//! The skeleton is updated at [`UPDATE_HZ`] from time 0 (its clock advancing by 1/[`UPDATE_HZ`]
//! s per update, summed as spine-core's `Skeleton.update` sums it) with the pose at that grid
//! time ([`PhysicsMode::Update`]; each constraint steps at its own fixed step inside); a time
//! between grid times shows the pose at that time with the simulation as it stood at the last
//! grid time ([`PhysicsMode::Pose`]). So the frame at t is a function of (rig, animation, t),
//! never of the output frame rate. Static poses (pose files, the editor's pose mode) show no
//! physics, as spine-core's `Physics.none`.
//!
//! That is the simulation from rest ([`transforms_at`]): an animation played once, and what
//! Spine 4.2's runtime plays. An animation flagged `loop` is shown in its periodic steady state
//! instead: [`crate::scene::play`] runs [`PhysicsRun`] period after period on one period's grid
//! ([`PhysicsRun::update_after`] advances the clock by the grid's step, shorter across the loop
//! when the duration is not a whole number of updates) until the motion repeats.

use crate::pipeline::PipelineError;
use crate::rig::physics::{PhysicsMode, PhysicsState, SpineWorld};
use crate::rig::pose::bone_rest_frame;
use crate::rig::{Affine, Handles};

pub use crate::rig::physics::UPDATE_HZ;

/// The skeleton update step, s.
pub fn update_step_s() -> f64 {
    1.0 / UPDATE_HZ
}

/// A constrained bone: its index, rest frame and length, and the columns it carries (itself,
/// its descendant bones and the points they carry).
#[derive(Clone, Debug)]
struct Constrained {
    bone: usize,
    rest: Affine,
    length_px: f64,
    carried: Vec<usize>,
}

/// The physics simulation of a rig after some whole updates.
#[derive(Clone, Debug)]
pub struct PhysicsRun {
    states: Vec<PhysicsState>,
    bones: Vec<Constrained>,
    /// Updates done so far (the first is at time 0).
    pub updates: u64,
    /// The skeleton's clock, s, summed as spine-core sums it.
    clock_s: f64,
    /// The transforms of the last update.
    last: Vec<Affine>,
}

impl PhysicsRun {
    /// A fresh simulation of `handles`' physics constraints (validated handles: every
    /// constrained bone exists).
    pub fn new(handles: &Handles) -> Self {
        let bones = handles
            .physics
            .iter()
            .filter_map(|c| {
                let bone = handles.bones.iter().position(|b| b.name == c.bone)?;
                let b = &handles.bones[bone];
                let length_px = (b.tail - b.head).norm();
                let mut carried = vec![bone];
                // Parents are acyclic: grow the set until no bone joins.
                loop {
                    let before = carried.len();
                    for (j, other) in handles.bones.iter().enumerate() {
                        let parent = other
                            .parent
                            .as_deref()
                            .and_then(|p| handles.bones.iter().position(|b| b.name == p));
                        if parent.is_some_and(|p| carried.contains(&p)) && !carried.contains(&j) {
                            carried.push(j);
                        }
                    }
                    if carried.len() == before {
                        break;
                    }
                }
                // And the points those bones carry (columns after the bones').
                let points = (0..handles.points.len()).filter(|&i| {
                    handles
                        .point_parent(i)
                        .is_some_and(|p| carried.contains(&p))
                });
                let points: Vec<usize> = points.map(|i| handles.bones.len() + i).collect();
                carried.extend(points);
                Some(Constrained {
                    bone,
                    rest: bone_rest_frame(b.head, b.tail),
                    length_px,
                    carried,
                })
            })
            .collect();
        PhysicsRun {
            states: vec![PhysicsState::default(); handles.physics.len()],
            bones,
            updates: 0,
            clock_s: 0.0,
            last: Vec::new(),
        }
    }

    /// The next skeleton update (at time `updates / UPDATE_HZ`) on `transforms`, the pose there.
    pub fn update(&mut self, handles: &Handles, transforms: Vec<Affine>) -> Vec<Affine> {
        self.update_after(handles, transforms, update_step_s())
    }

    /// The next skeleton update on `transforms`, the pose there, the clock advanced by
    /// `advance_s` since the last update (the first update advances nothing). A looping
    /// animation's grid ([`crate::scene::play::Cycle`]) advances by a shorter step across the
    /// loop when its duration is not a whole number of steps.
    pub fn update_after(
        &mut self,
        handles: &Handles,
        transforms: Vec<Affine>,
        advance_s: f64,
    ) -> Vec<Affine> {
        if self.updates > 0 {
            self.clock_s += advance_s;
        }
        self.updates += 1;
        let clock = self.clock_s;
        let out = apply(
            handles,
            transforms,
            &self.bones,
            &mut self.states,
            clock,
            PhysicsMode::Update,
        );
        self.last.clone_from(&out);
        out
    }

    /// `transforms` (the pose at a time after the last update, before the next) with the
    /// simulation as it stands.
    pub fn pose(&self, handles: &Handles, transforms: Vec<Affine>) -> Vec<Affine> {
        let mut states = self.states.clone();
        apply(
            handles,
            transforms,
            &self.bones,
            &mut states,
            self.clock_s,
            PhysicsMode::Pose,
        )
    }
}

/// Each constraint on its bone's world frame (`transform · rest`), the change carried to the
/// bone and its descendants.
fn apply(
    handles: &Handles,
    mut transforms: Vec<Affine>,
    bones: &[Constrained],
    states: &mut [PhysicsState],
    clock_s: f64,
    mode: PhysicsMode,
) -> Vec<Affine> {
    for ((data, c), state) in handles.physics.iter().zip(bones).zip(states.iter_mut()) {
        let Some(transform) = transforms.get(c.bone) else {
            continue;
        };
        let world = transform.then_after(&c.rest);
        let mut spine = SpineWorld::from_canvas(&world);
        state.update(data, c.length_px, &mut spine, clock_s, mode);
        let Some(world_inverse) = world.inverse() else {
            continue;
        };
        let change = spine.to_canvas().then_after(&world_inverse);
        for &j in &c.carried {
            transforms[j] = change.then_after(&transforms[j]);
        }
    }
    transforms
}

/// The whole updates at or before `time_s` (a time within a billionth of a step of a grid time
/// is that grid time), and whether `time_s` is a grid time.
pub fn updates_until(time_s: f64) -> (u64, bool) {
    let step = update_step_s();
    let whole = (time_s / step + 1e-9).floor().max(0.0) as u64;
    let on_grid = time_s - whole as f64 * step <= 1e-9 * step;
    (whole + 1, on_grid)
}

/// The transforms at `time_s` of an animation posed at any time by `posed`, simulated in `run`
/// (advanced as far as needed; restarted when it is already past `time_s`).
pub fn transforms_at(
    run: &mut Option<PhysicsRun>,
    handles: &Handles,
    time_s: f64,
    posed: &mut dyn FnMut(f64) -> Result<Vec<Affine>, PipelineError>,
) -> Result<Vec<Affine>, PipelineError> {
    if !(time_s.is_finite() && (0.0..=super::MAX_SIMULATED_S).contains(&time_s)) {
        return Err(PipelineError::SimulatedTime(time_s));
    }
    let (needed, on_grid) = updates_until(time_s);
    if run.as_ref().is_none_or(|r| r.updates > needed) {
        *run = Some(PhysicsRun::new(handles));
    }
    let run = run.get_or_insert_with(|| PhysicsRun::new(handles));
    while run.updates < needed {
        let k = run.updates;
        let transforms = posed(k as f64 * update_step_s())?;
        run.update(handles, transforms);
    }
    if on_grid {
        return Ok(run.last.clone());
    }
    Ok(run.pose(handles, posed(time_s)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::rig::physics::PhysicsConstraint;
    use crate::rig::pose::BonePose;
    use crate::rig::{handle_transforms, Bone, PointHandle, Pose};

    #[test]
    fn a_point_carried_by_a_constrained_bone_moves_with_it() {
        let handles = Handles {
            bones: vec![Bone {
                name: "b".into(),
                parent: None,
                head: Point::new(0.0, 0.0),
                tail: Point::new(40.0, 0.0),
            }],
            points: vec![
                PointHandle {
                    name: "on".into(),
                    at: Point::new(30.0, 5.0),
                    parent: Some("b".into()),
                },
                PointHandle {
                    name: "loose".into(),
                    at: Point::new(30.0, 5.0),
                    parent: None,
                },
            ],
            physics: vec![
                serde_json::from_value::<PhysicsConstraint>(serde_json::json!(
                    {"name": "sway", "bone": "b", "x": 1, "rotate": 1}
                ))
                .unwrap(),
            ],
            ..Default::default()
        };
        // The bone jumps 50 px right after the first update: the simulation holds it back.
        let mut pose = Pose::default();
        pose.bones.insert(
            "b".into(),
            BonePose {
                translate: [50.0, 0.0],
                ..Default::default()
            },
        );
        let posed = handle_transforms(&handles, &pose).unwrap();
        let rest = handle_transforms(&handles, &Pose::default()).unwrap();
        let mut run = PhysicsRun::new(&handles);
        run.update(&handles, rest);
        let mut out = Vec::new();
        for _ in 0..3 {
            out = run.update(&handles, posed.clone());
        }
        let at = Point::new(30.0, 5.0);
        let held_back = (out[0].apply(at) - posed[0].apply(at)).norm();
        assert!(held_back > 1.0, "the physics moved nothing: {held_back}");
        assert_eq!(out[1], out[0], "the carried point stayed behind");
        assert_eq!(out[2], posed[2], "the loose point moved");
    }
}
