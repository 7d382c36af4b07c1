//! Motion capture: clips read from BVH files and their forward kinematics.
//!
//! - [`bvh`]: the reader. Bytes or a path + [`BvhLimits`] → [`Clip`] (joints with typed
//!   [`JointId`]s, channels in file order, end sites, the frame time, one row of channel values
//!   per frame), or one [`BvhError`] naming the line.
//! - [`fk`]: a clip and a frame → world transforms and positions of joints and end sites.
//! - [`library`]: the bundled clips (idle, walk, run, jump, jump_forward, wave).
//! - [`apply`]: a clip retargeted into a rig document as a named animation.
//! - [`map`]: which capture segment drives which rig bone (naming schemes, map files).
//! - [`retarget`]: a clip played by a 2D rig: an animation with planted feet and seamless
//!   loops, as editable Bézier keys ([`keys`]).
//!
//! Units and frame are the file's (BVH is y-up and right-handed; lengths in the file's unit,
//! angles in degrees, times in seconds); nothing here converts them. The bundled motion library
//! (`assets/motions/`, its sources in `assets/motions/SOURCES.md`) is read with these.

pub mod apply;
pub mod bvh;
pub mod fk;
pub mod keys;
pub mod library;
pub mod map;
pub mod retarget;

pub use apply::{apply_motion, ApplyError};
pub use bvh::{parse, read, BvhError, BvhLimits, Channel, Clip, Joint, JointId};
pub use fk::{frame_positions, joint_poses, rest_positions, FramePositions, JointPose};
pub use map::{JointMap, MapError, MapFile};
pub use retarget::{
    retarget, Facing, LoopMode, RetargetError, RetargetOptions, RetargetReport, Retargeted, View,
};
