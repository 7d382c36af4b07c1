//! Handles and posing: bones (a forest of skeletons), loose points, cages and regions; the pose
//! file and forward kinematics.

pub mod handles;
pub mod pose;

pub use handles::{Bone, Cage, HandleError, Handles, PointHandle, Region};
pub use pose::{handle_columns, handle_transforms, Affine, Pose, PoseError};
