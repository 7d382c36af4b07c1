//! Skinning IK: drag a few points of the drawing and every handle the pose leaves free follows.
//!
//! In: a rig's skinned meshes and handles, and a [`Pose`](crate::rig::pose::Pose) whose `ik`
//! drags say where material points (given by their rest positions) must go. Out: one affine map
//! per handle column, ready for skinning, chosen to keep the whole skinned shape as rigid as
//! possible (Jacobson, Baran, Kavan, Popović & Sorkine 2012, "Fast Automatic Skinning
//! Transformations").
//!
//! - [`arap`]: the per-vertex ARAP energy (Sorkine & Alexa 2007), the yardstick.
//! - [`cluster`]: rotation clusters by k-means in weight space.
//! - [`subspace`]: the energy reduced to the handles' affine parameters (precomputed per rig).
//! - [`fold`]: the orientation guard: triangles about to fold over are held near rigid.
//! - [`fast`]: the local/global solver over the reduced energy (factorized per constraint set,
//!   solved per frame).
//! - [`rigid`]: its global step when bones are rigid (rotations exactly, a Gauss–Newton step).
//! - [`rig`]: a rig and a pose → which handles are free, fixed or following, joints, drags,
//!   momentum (secondary motion across the frames of a sequence).
//! - [`reference`]: the full per-vertex ARAP deformation, the quality bound tests compare with.

pub mod arap;
pub mod cluster;
pub mod fast;
pub mod fold;
pub mod reference;
pub mod rig;
pub mod rigid;
pub mod subspace;

pub use fast::{ColumnDofs, DragRow, FastIk, IkSolution, Joint, Problem};
pub use rig::RigIk;
pub use subspace::SkinnedMesh;

use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};

/// How a free bone may move under the skinning IK.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum BoneDofs {
    /// Rotation and translation, exactly: a bone keeps its length, as in Spine, so exports
    /// carry no accidental scale or shear (bones named in [`IkOptions::stretch`] may also scale
    /// uniformly).
    #[default]
    Rigid,
    /// Rotation, translation and uniform scale, for every bone.
    Uniform,
    /// Any affine map, kept close to rigid only by the ARAP energy (and
    /// [`IkOptions::rigidity`]): the handles of Fast Automatic Skinning Transformations.
    Affine,
}

/// How a free handle that is not a bone may move.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum HandleDofs {
    /// Any affine map: translation, rotation, scale and shear.
    #[default]
    Affine,
    /// Rotation and translation (held near rigid, [`IkOptions::region_rigidity`]).
    Rigid,
    /// Translation only.
    Translation,
}

/// Skinning-IK parameters. Every field has a default; the rig file, the CLI and the editor share
/// them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IkOptions {
    /// Rotation clusters per handle column (k-means in weight space). 0: one rotation per
    /// vertex, the exact reduced energy (slow; for reference). Default 4.
    pub clusters_per_handle: usize,
    /// Lloyd iterations of the clustering. Default 4.
    pub cluster_iterations: usize,
    /// Local/global iterations per solve at most, when warm-started from the previous solve
    /// (dragging, animation frames). Default 8.
    pub iterations: usize,
    /// Iterations at most for a solve with no previous solution to start from (a single
    /// pose): it starts from the forward-kinematics pose, further away; with rigid bones the
    /// problem is not convex, and it runs from two starts (the relaxed affine solution and the
    /// forward-kinematics pose), keeping the better result. Default 64.
    pub cold_iterations: usize,
    /// Stop when no skinned point moves more than this between two iterations, px. Default 0.01.
    pub tolerance_px: f64,
    /// How free bones move. Default rigid.
    pub bones: BoneDofs,
    /// Bones (by name) that may scale uniformly when `bones` is rigid, like Spine's IK
    /// `stretch`. Default: none.
    #[serde(skip_serializing_if = "BTreeSet::is_empty")]
    pub stretch: BTreeSet<String>,
    /// With `bones` affine: how strongly free bones are held near rotations by a penalty,
    /// relative to their own share of the energy. Default 0 (the ARAP energy alone). Measured
    /// on the bundled character's quality drags: 0 gives bones stretched by 10–13%, 1 by
    /// 1.2–1.6%, 100 by 1.1–1.5%, and a penalty slows the local/global iterations; bones that
    /// keep their length exactly are `bones: rigid`, the default.
    pub rigidity: f64,
    /// How strongly regions (and points or cage vertices set to `rigid`) are held to rotations,
    /// in the same units as `rigidity`. Default 100.
    pub region_rigidity: f64,
    /// Near-rigid handles (regions, points or cage vertices set to `rigid`) may also scale
    /// uniformly. Default false.
    pub allow_uniform_scale: bool,
    /// Free point handles. Default affine.
    pub points: HandleDofs,
    /// Free cage vertices. Default translation.
    pub cage_vertices: HandleDofs,
    /// Joints of a connected skeleton stay connected (hard constraints). Default true.
    pub connect_joints: bool,
    /// Pull toward the forward-kinematics pose, relative to the ARAP energy; it only decides
    /// motions that nothing else decides (a rig with no drag stays in its FK pose). Default 1e-6.
    pub anchor: f64,
    /// Secondary motion: handle column name (as `handle_columns` lists them) → inertia, s. A
    /// handle named here and not keyed by the pose is left free in every frame of a sequence
    /// and carries momentum: each frame minimizes the ARAP energy plus (inertia / frame time)²
    /// times its mass-weighted distance from where its motion would carry it (implicit Euler),
    /// so it lags, swings and settles when the driven parts move. Default: none.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub momentum: BTreeMap<String, f64>,
    /// How fast a momentum handle's velocity decays, 1/s: over a frame of h seconds it keeps
    /// exp(−rate · h) of it, whatever the frame rate. Default 3.16 (10% lost per frame at
    /// 30 fps).
    pub momentum_damping_per_s: f64,
    /// Local/global iterations per frame when momentum is in play: the balance of inertia and
    /// elasticity needs a converged frame, or the motion comes out overdamped. Default 32.
    pub momentum_iterations: usize,
    /// The fixed time step at which momentum is simulated, s: a frame at time t of an
    /// animation is the simulation from the animation's start to t in steps of this length
    /// (and one shorter step to reach t), so the motion does not depend on the output frame
    /// rate. Default 1/60 s.
    pub momentum_step_s: f64,
    /// How far outside every part an ik drag's `at` may lie and still grip the nearest
    /// triangle, px. Default 2.
    pub grip_tolerance_px: f64,
    /// Fold guard ([`fold`]): how many blended triangles (besides one per handle) are checked
    /// for orientation after each solve, those where the weights change fastest first; 0 turns
    /// the guard off. Default 4096.
    pub fold_check_triangles: usize,
    /// A checked triangle whose posed area falls below this share of its rest area (negative:
    /// folded over) is guarded: held near its cluster's rotation. Default 0.1.
    pub fold_area_ratio: f64,
    /// A guarded triangle's weight, per px² of its rest area, relative to the ARAP energy; it
    /// grows tenfold in each round that finds the triangle still below `fold_area_ratio`.
    /// Default 100.
    pub fold_stiffness: f64,
    /// Rounds of checking, guarding and iterating again per solve. Default 6.
    pub fold_rounds: usize,
}

impl Default for IkOptions {
    fn default() -> Self {
        IkOptions {
            clusters_per_handle: 4,
            cluster_iterations: 4,
            iterations: 8,
            cold_iterations: 64,
            tolerance_px: 0.01,
            bones: BoneDofs::Rigid,
            stretch: BTreeSet::new(),
            rigidity: 0.0,
            region_rigidity: 100.0,
            allow_uniform_scale: false,
            points: HandleDofs::Affine,
            cage_vertices: HandleDofs::Translation,
            connect_joints: true,
            anchor: 1e-6,
            grip_tolerance_px: 2.0,
            fold_check_triangles: 4096,
            fold_area_ratio: 0.1,
            fold_stiffness: 100.0,
            fold_rounds: 6,
            momentum: BTreeMap::new(),
            momentum_damping_per_s: 3.16,
            momentum_iterations: 32,
            momentum_step_s: 1.0 / 60.0,
        }
    }
}

/// Shortest momentum step accepted, s: a step of 1e-4 s simulates 10,000 solves per second of
/// animation.
pub const MIN_MOMENTUM_STEP_S: f64 = 1e-4;
/// Longest momentum step accepted, s.
pub const MAX_MOMENTUM_STEP_S: f64 = 0.1;

/// What is wrong with an IK request.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum IkError {
    #[error(
        "ik drag at ({0:.1}, {1:.1}) does not grip the drawing: no part covers that point at rest"
    )]
    DragOutside(f64, f64),
    #[error(
        "no part has skinning weights; compute them (sinew rig --handles) before using ik drags"
    )]
    NoWeights,
    #[error("an ik drag or a handle transform is not a finite number")]
    NonFinite,
    #[error("ik drag target ({}, {}) lies beyond ±{max} px", crate::shown::Shown(*.0), crate::shown::Shown(*.1), max = crate::rig::pose::MAX_POSED_PX)]
    TargetTooFar(f64, f64),
    #[error(transparent)]
    Pose(#[from] crate::rig::pose::PoseError),
    #[error("the problem has {got} handle columns but the rig has {expected}")]
    ColumnCount { expected: usize, got: usize },
    #[error("handle column {column} follows column {parent}, which is not a free affine handle")]
    BadFollow { column: usize, parent: usize },
    #[error("the skinning IK system is singular (a handle that moves no vertex?)")]
    Singular,
    #[error("momentum names '{0}', which is not a handle column of the rig")]
    UnknownMomentumHandle(String),
    #[error("ik stretch names '{0}', which is not a bone of the rig")]
    UnknownStretchBone(String),
    #[error("momentum of '{0}' must be a finite number ≥ 0 s")]
    BadMomentum(String),
    #[error("momentum_step_s must be a number of seconds in [{min}, {max}], not {}", crate::shown::Shown(*.0), min = MIN_MOMENTUM_STEP_S, max = MAX_MOMENTUM_STEP_S)]
    BadMomentumStep(f64),
}
