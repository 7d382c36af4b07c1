//! Physics constraints as Spine 4.2 physics constraints.
//!
//! In: the rig's [`Handles`] (their `physics` constraints, see [`crate::rig::physics`]). Out:
//! one `physics` entry per constraint (spine-format.md §8): `bone`, what it moves (`x`, `y`,
//! `rotate`, `scaleX`, `shearX`) and the model's parameters (`limit`, `fps`, `inertia`,
//! `strength`, `damping`, `mass`, `wind`, `gravity`, `mix`), all carried over unchanged since
//! sinew simulates spine-core 4.2's model (`crate::rig::physics`) in Spine's axes. `order`
//! follows the IK constraints', as sinew applies physics after bone IK. Spine 4.1 has no
//! physics and 4.3 changed the model (it interpolates between steps), so for those the
//! constraints are not written and their motion is baked into keys instead ([`super::bake`]):
//! from rest at 0, or, for an animation flagged `loop`, in its periodic steady state. The 4.2
//! runtime's own simulation starts from rest and runs on across loops (measured on the demo's
//! walk: a 4.4 px step of the tail at the seam, its largest inside the loop 9.6 px).

use super::timelines::num;
use super::SpineVersion;
use crate::rig::Handles;
use serde_json::{json, Value};

/// Whether `version`'s runtime simulates sinew's physics model (4.2's) itself.
pub fn native(version: SpineVersion) -> bool {
    version == SpineVersion::V4_2
}

/// The `physics` entries of `handles`, updated after `ik_count` IK constraints; none for a
/// version without this physics model (the bake carries the motion there).
pub fn physics_entries(handles: &Handles, ik_count: usize, version: SpineVersion) -> Vec<Value> {
    if handles.physics.is_empty() || !native(version) {
        return Vec::new();
    }
    handles
        .physics
        .iter()
        .enumerate()
        .map(|(k, c)| {
            json!({
                "name": c.name,
                "order": ik_count + k,
                "bone": c.bone,
                "x": num(c.x),
                "y": num(c.y),
                "rotate": num(c.rotate),
                "scaleX": num(c.scale_x),
                "shearX": num(c.shear_x),
                "limit": num(c.limit),
                "fps": num(c.fps),
                "inertia": num(c.inertia),
                "strength": num(c.strength),
                "damping": num(c.damping),
                "mass": num(c.mass),
                "wind": num(c.wind),
                "gravity": num(c.gravity),
                "mix": num(c.mix),
            })
        })
        .collect()
}
