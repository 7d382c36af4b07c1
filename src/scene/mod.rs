//! The one path from a pose, or an animation and a time, to posed vertices and a drawn frame.
//!
//! Every consumer — `sinew pose`, `sinew render` and its GIF, sheet and frame writers, the Spine
//! export's bake and `--match-runtime`, the golden tests and the editor's canvas — goes through
//! here; nothing else poses or draws.
//!
//! - [`Scene`]: a rig document with its textures and its precomputed solvers.
//! - A static pose → handle transforms: [`Scene::handle_transforms`] (forward kinematics, bone
//!   IK constraints, then the skinning IK solved from the forward-kinematics pose with no warm
//!   start, so the answer is a function of the pose alone) → posed vertices:
//!   [`Scene::positions_from_transforms`].
//! - An animation and a time → [`Frame`]: [`Playhead`] (and [`frames`] for many times). The frame
//!   at time t is a function of (rig, animation, t) only: without momentum each frame is the
//!   static pose of the animation at t; with momentum ([`crate::ik::IkOptions::momentum`]) the
//!   motion is simulated at a fixed internal step ([`crate::ik::IkOptions::momentum_step_s`])
//!   from the animation's start, independent of the output frame rate; for an animation flagged
//!   `loop` ([`crate::anim::Animation::looping`]) momentum and physics are those of the periodic
//!   steady state (simulated period after period until one repeats the last), so the last frame
//!   flows into the first.
//! - Posed parts → a frame: [`draw_pose`] (the pose's draw order, tint and visibility).

pub mod physics;
pub mod play;
mod rig_scene;

pub use crate::playback::draw_pose;
pub use play::{frames, Frame, PlayOptions, Playhead, MAX_SIMULATED_S};
pub(crate) use rig_scene::texture_border_px;
pub use rig_scene::{load_part_images, Scene};
