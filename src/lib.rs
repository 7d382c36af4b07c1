//! sinew: 2D cutout animation.
//!
//! The pipeline, stage by stage (see `ARCHITECTURE.md`):
//! RGBA image → [`trace`] → outlines → [`mesh`] → triangle mesh → weights → skin → [`render`].
//! [`io`] reads and writes the native rig document and images; [`pipeline`] wires the stages
//! together. The `sinew` command and its argument parsing live in the binary (feature `cli`);
//! the library knows no shell. The files sinew reads and writes: `docs/formats.md`.

pub mod anim;
pub mod art;
pub mod autorig;
pub mod batch;
pub mod budget;
pub mod colorize;
pub mod document;
#[cfg(feature = "editor")]
pub mod editor;
pub mod export;
pub mod geom;
pub mod ik;
pub mod io;
pub mod jobs;
pub mod mesh;
pub mod motion;
pub mod names;
pub mod pipeline;
pub mod playback;
pub mod render;
pub mod rig;
pub mod scene;
pub mod schema;
pub mod shown;
pub mod skin;
pub mod trace;
pub mod weights;

/// Scratch folders for the tests, removed when a test ends (also included by the integration
/// tests' `tests/command`).
#[cfg(test)]
pub(crate) mod test_scratch;
