//! Deform keys (free-form deformation): per-vertex offsets of one part's mesh keyed over time.
//!
//! In: an animation's `deform` section, part name → keys whose value lists one offset per vertex
//! of the part's mesh (canvas px, in the rest frame, in the mesh's vertex order), with the same
//! curves as other keys (one 0..1 Bézier for all vertices, as Spine's deform timeline and
//! sinew's cage keys). Out: at any time, the offsets the pose carries
//! ([`crate::rig::Pose::deform`]); posing adds them to the rest vertices *before* skinning, so
//! a deformed vertex is carried by its handles like any other (Spine's deform timeline on a
//! weighted mesh adds the offset to each influence's bind position, which is the same map under
//! linear blend skinning).
//!
//! Checks: on their own (in [`super::timeline`]) every key of one timeline lists the same
//! number of offsets; against the rig ([`check_deform_sizes`]) that number is the part's
//! vertex count and the part exists.

use super::timeline::{Animation, Key};
use super::AnimError;
use std::collections::BTreeMap;

/// One part's deform keys: per key, one offset per mesh vertex (canvas px).
pub type DeformKeys = Vec<Key<Vec<crate::geom::Vec2>>>;

/// Fails on the first deform timeline naming a part the rig lacks, or whose keys list a number
/// of offsets other than the part's vertex count. `parts` lists each part's name and vertex
/// count.
pub fn check_deform_sizes(
    animations: &BTreeMap<String, Animation>,
    parts: &[(&str, usize)],
) -> Result<(), AnimError> {
    for (name, animation) in animations {
        for (part, keys) in &animation.deform {
            let Some(&(_, expected)) = parts.iter().find(|(p, _)| p == part) else {
                return Err(AnimError::UnknownName {
                    animation: name.clone(),
                    kind: "part",
                    name: part.clone(),
                });
            };
            if let Some((key, k)) = keys
                .iter()
                .enumerate()
                .find(|(_, k)| k.value.len() != expected)
            {
                return Err(AnimError::DeformSize {
                    animation: name.clone(),
                    part: part.clone(),
                    key,
                    got: k.value.len(),
                    expected,
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn parsed(v: serde_json::Value) -> Result<Animation, AnimError> {
        Animation::from_json("hop", &v)
    }

    #[test]
    fn deform_keys_parse_sample_and_check_sizes() {
        let anim = parsed(json!({"deform": {"body": [
            {"time": 0, "value": [[0, 0], [0, 0]], "curve": [0.25, 0, 0.75, 1]},
            {"time": 1, "value": [[2, -4], [0, 8]]}]}}))
        .unwrap();
        assert_eq!(anim.duration_s(), 1.0);
        let mid = anim.sample(0.5, false);
        // A symmetric ease is half way at half time.
        let offsets = &mid.deform["body"];
        assert!((offsets[0][0] - 1.0).abs() < 1e-9 && (offsets[1][1] - 4.0).abs() < 1e-9);
        let back = serde_json::to_value(&anim).unwrap();
        assert_eq!(parsed(back).unwrap(), anim);
        let animations = BTreeMap::from([("hop".to_string(), anim)]);
        assert!(check_deform_sizes(&animations, &[("body", 2)]).is_ok());
        assert_eq!(
            check_deform_sizes(&animations, &[("body", 3)])
                .unwrap_err()
                .to_string(),
            "animation 'hop', deform.body: key 0 has 2 offsets but the part's mesh has 3 vertices"
        );
        assert_eq!(
            check_deform_sizes(&animations, &[("head", 2)])
                .unwrap_err()
                .to_string(),
            "animation 'hop' names part 'body', which the rig does not have"
        );
    }

    #[test]
    fn bad_deform_keys_name_their_timeline() {
        let m = parsed(json!({"deform": {"body": [
            {"time": 0, "value": [[0, 0], [0, 0]]}, {"time": 1, "value": [[0, 0]]}]}}))
        .unwrap_err()
        .to_string();
        assert_eq!(
            m,
            "animation 'hop', deform.body: key 1 has 1 vertices but key 0 has 2"
        );
        let m = parsed(json!({"deform": {"body": [{"time": 0, "value": [[0, "x"]]}]}}))
            .unwrap_err()
            .to_string();
        assert!(
            m.starts_with("animation 'hop', deform.body key 0: invalid type"),
            "{m}"
        );
    }
}
