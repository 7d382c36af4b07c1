//! sinew: 2D cutout animation.
//!
//! The pipeline, stage by stage (see `ARCHITECTURE.md`):
//! RGBA image → [`trace`] → outlines → [`mesh`] → triangle mesh → weights → skin → [`render`].
//! [`io`] reads and writes the native rig document and images; [`pipeline`] wires the stages
//! together; [`cli`] is the `sinew` command.

pub mod anim;
pub mod autorig;
pub mod cli;
pub mod colorize;
pub mod document;
#[cfg(feature = "editor")]
pub mod editor;
pub mod export;
pub mod geom;
pub mod ik;
pub mod io;
pub mod mesh;
pub mod pipeline;
pub mod playback;
pub mod render;
pub mod rig;
pub mod scene;
pub mod skin;
pub mod trace;
pub mod weights;
