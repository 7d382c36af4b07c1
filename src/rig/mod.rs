//! Handles: bones (a forest of skeletons), loose points, cages and regions.

pub mod handles;

pub use handles::{Bone, Cage, HandleError, Handles, PointHandle, Region};
