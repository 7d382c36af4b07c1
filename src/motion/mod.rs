//! Motion capture: clips read from BVH files and their forward kinematics.
//!
//! - [`bvh`]: the reader. Bytes or a path + [`BvhLimits`] → [`Clip`] (joints with typed
//!   [`JointId`]s, channels in file order, end sites, the frame time, one row of channel values
//!   per frame), or one [`BvhError`] naming the line.
//! - [`fk`]: a clip and a frame → world transforms and positions of joints and end sites.
//!
//! Units and frame are the file's (BVH is y-up and right-handed; lengths in the file's unit,
//! angles in degrees, times in seconds); nothing here converts them. The bundled motion library
//! (`assets/motions/`, its sources in `assets/motions/SOURCES.md`) is read with these.

pub mod bvh;
pub mod fk;

pub use bvh::{parse, read, BvhError, BvhLimits, Channel, Clip, Joint, JointId};
pub use fk::{frame_positions, joint_poses, rest_positions, FramePositions, JointPose};
