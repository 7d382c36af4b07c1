//! Checking an animation against the rig it animates.
//!
//! In: an [`Animation`] (already checked on its own), the rig's [`Handles`] and its part names.
//! Out: `Ok` when every name a timeline uses exists in the rig, every cage key has the rig cage's
//! vertex count, every draw-order key lists each part exactly once, and every event key names
//! an event the rig defines.

use super::event::EventDefs;
use super::timeline::Animation;
use super::AnimError;
use crate::rig::Handles;
use std::collections::BTreeMap;

impl Animation {
    /// Fails on the first name the rig lacks, cage of the wrong size or incomplete draw order.
    pub fn check_rig(
        &self,
        name: &str,
        handles: &Handles,
        parts: &[&str],
        events: &EventDefs,
    ) -> Result<(), AnimError> {
        let unknown = |kind: &'static str, what: &str| AnimError::UnknownName {
            animation: name.into(),
            kind,
            name: what.into(),
        };
        for bone in self.bones.keys() {
            if !handles.bones.iter().any(|b| &b.name == bone) {
                return Err(unknown("bone", bone));
            }
        }
        for point in self.points.keys() {
            if !handles.points.iter().any(|p| &p.name == point) {
                return Err(unknown("point", point));
            }
        }
        for (cage, keys) in &self.cages {
            let rest = handles
                .cages
                .iter()
                .find(|c| &c.name == cage)
                .ok_or_else(|| unknown("cage", cage))?;
            if let Some((key, k)) = keys
                .iter()
                .enumerate()
                .find(|(_, k)| k.value.len() != rest.polygon.len())
            {
                return Err(AnimError::CageSize {
                    animation: name.into(),
                    cage: cage.clone(),
                    key,
                    got: k.value.len(),
                    expected: rest.polygon.len(),
                });
            }
        }
        for part in self.parts.keys() {
            if !parts.contains(&part.as_str()) {
                return Err(unknown("part", part));
            }
        }
        for (key, k) in self.draw_order.iter().flatten().enumerate() {
            if let Some(part) = k.value.iter().find(|p| !parts.contains(&p.as_str())) {
                return Err(unknown("part", part));
            }
            if let Some(missing) = parts.iter().find(|p| !k.value.iter().any(|q| q == *p)) {
                return Err(AnimError::DrawOrderIncomplete {
                    animation: name.into(),
                    key,
                    missing: missing.to_string(),
                });
            }
        }
        if let Some(k) = self.events.iter().find(|k| !events.contains_key(&k.name)) {
            return Err(unknown("event", &k.name));
        }
        Ok(())
    }
}

/// Checks each of `animations` against the rig's handles and part names (see
/// [`Animation::check_rig`]); the first failure names its animation.
pub fn check_animations(
    animations: &BTreeMap<String, Animation>,
    handles: &Handles,
    parts: &[&str],
    events: &EventDefs,
) -> Result<(), AnimError> {
    animations
        .iter()
        .try_for_each(|(name, animation)| animation.check_rig(name, handles, parts, events))
}
