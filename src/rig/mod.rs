//! Handles and posing: bones (a forest of skeletons), points (loose or carried by a bone), cages
//! and regions; the pose
//! file and forward kinematics, with classic bone IK constraints ([`bone_ik`]).
//!
//! Imports go one way: [`handles`] ← [`frames`] (the pose model, bone frames) ← [`bone_ik`] ←
//! [`pose`] (skinning transformations, constraints applied) ← [`fk_edit`].

pub mod bone_ik;
pub mod fk_edit;
pub mod frames;
pub mod handles;
pub mod physics;
pub mod pose;

pub use handles::{Bone, Cage, HandleError, Handles, PointHandle, Region};
pub use physics::PhysicsConstraint;
pub use pose::{handle_columns, handle_transforms, Affine, Pose, PoseError};
