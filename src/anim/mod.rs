//! Keyframed animations: timelines of keys, curves, sampling into poses, crossfades.
//!
//! In: the rig document's `animations` map (name → animation JSON, see [`timeline`] for the
//! model; parsed once, where a document or an animations file is read, and held as
//! [`Animation`]s from then on), the rig's handles and part names. Out: checked [`Animation`]s, and for any time the
//! [`crate::rig::Pose`] they show — bone locals, point and cage poses, part tints, visibility and
//! draw order, IK drags. Units: seconds, degrees (counter-clockwise on screen), canvas px, color
//! multipliers in [0, 1].
//!
//! - [`curve`]: linear, stepped and Bézier interpolation (the exact cubic solve);
//! - [`timeline`]: keys, timelines, [`Animation`], parsing and per-animation checks;
//! - [`check`]: names and sizes against a rig;
//! - [`sample`]: an animation at a time, looping or clamped;
//! - [`mix`]: the crossfade from one animation into another;
//! - [`edit`]: keys edited per timeline (move, copy and paste, delete, curves).

pub mod attachment;
pub mod check;
pub mod curve;
pub mod deform;
pub mod edit;
pub mod event;
pub mod mix;
pub mod sample;
pub mod timeline;

pub use check::check_animations;
pub use curve::Curve;
pub use curve::CurveEvaluation;
pub use event::{
    events_from_json, frame_events, EventDef, EventDefs, EventKey, FiredAudio, FiredEvent,
};
pub use mix::{mix_poses, sample_mix, Playhead, STEPPED_MIX_THRESHOLD};
pub use sample::SampleOptions;
pub use timeline::{
    animations_from_json, parse_animations, Animation, BoneTimelines, IkTimeline, Key,
    PartTimelines, PointTimelines, Rgba, StepKey, TimelineError,
};

/// What is wrong with an animation, on its own or for a rig.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AnimError {
    #[error("animations: expected an object: name → animation")]
    NotAMap,
    #[error("animation '{animation}': {reason}")]
    Malformed { animation: String, reason: String },
    #[error("animation '{animation}', {timeline}: {problem}")]
    Timeline {
        animation: String,
        /// Where: `bones.arm.rotate`, `parts.head.color`, `draw_order`, `ik[0].to`, …
        timeline: String,
        problem: TimelineError,
    },
    #[error("animation '{animation}' names {kind} '{name}', which the rig does not have")]
    UnknownName {
        animation: String,
        kind: &'static str,
        name: String,
    },
    #[error(
        "animation '{animation}', cages.{cage}: key {key} has {got} vertices but the rig's cage \
         has {expected}"
    )]
    CageSize {
        animation: String,
        cage: String,
        key: usize,
        got: usize,
        expected: usize,
    },
    #[error(
        "animation '{animation}', deform.{part}: key {key} has {got} offsets but the part's mesh \
         has {expected} vertices"
    )]
    DeformSize {
        animation: String,
        part: String,
        key: usize,
        got: usize,
        expected: usize,
    },
    #[error(
        "animation '{animation}', draw_order: key {key} does not list part '{missing}' (each key \
         lists every part once)"
    )]
    DrawOrderIncomplete {
        animation: String,
        key: usize,
        missing: String,
    },
    /// `place`: `parts.SLOT.attachment: key K shows 'NAME', which slot 'SLOT' does not have (its
    /// attachments: …)` (one string, so the error stays small).
    #[error("animation '{animation}', {place}")]
    UnknownAttachment { animation: String, place: String },
    #[error(
        "animation '{animation}', parts.{slot}: keys both 'visible' and 'attachment' (one \
         timeline shows or hides a slot: key 'attachment' null to hide it)"
    )]
    VisibleAndAttachment { animation: String, slot: String },
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::rig::{Bone, Cage, Handles, PointHandle};
    use serde_json::json;

    fn parse(v: serde_json::Value) -> Result<Animation, AnimError> {
        Animation::from_json("walk", &v)
    }

    fn message(v: serde_json::Value) -> String {
        parse(v).unwrap_err().to_string()
    }

    #[test]
    fn a_full_animation_parses_and_round_trips() {
        let v = json!({
            "bones": {"leg": {
                "rotate": [{"time": 0, "value": 10, "curve": [0.2, 10, 0.3, -10]},
                           {"time": 0.5, "value": -10, "curve": "stepped"},
                           {"time": 1, "value": 10}],
                "translate": [{"time": 0, "value": [0, 2]}]}},
            "points": {"tip": {"rotate": [{"time": 0, "value": 5}]}},
            "cages": {"belly": [{"time": 0, "value": [[0, 0], [1, 0], [1, 1]]}]},
            "parts": {"head": {"color": [{"time": 0, "value": "ff8000cc"}],
                               "visible": [{"time": 0, "value": true}]}},
            "draw_order": [{"time": 0.5, "value": ["head", "body"]}],
            "ik": [{"at": [1, 2], "to": [{"time": 0, "value": [3, 4]}]}]
        });
        let anim = parse(v.clone()).unwrap();
        assert_eq!(anim.duration_s(), 1.0);
        let color = anim.parts["head"].color.as_ref().unwrap()[0].value.0;
        assert_eq!(color, [1.0, 128.0 / 255.0, 0.0, 0.8]);
        // Writing it back reads as the same animation; colors stay hex.
        let back = serde_json::to_value(&anim).unwrap();
        assert_eq!(parse(back.clone()).unwrap(), anim);
        assert_eq!(back["parts"]["head"]["color"][0]["value"], "ff8000cc");
        assert_eq!(back["bones"]["leg"]["rotate"][1]["curve"], "stepped");
        assert!(back["bones"]["leg"]["rotate"][2].get("curve").is_none());
    }

    #[test]
    fn parse_errors_name_the_animation_and_timeline() {
        let m = message(json!({"bones": {"leg": {"rotate": [
            {"time": 0, "value": 1}, {"time": 0, "value": 2}]}}}));
        assert_eq!(
            m,
            "animation 'walk', bones.leg.rotate: key 1 at 0 s does not come after the previous \
             key at 0 s"
        );
        let m = message(json!({"bones": {"leg": {"rotat": []}}}));
        assert!(
            m.starts_with("animation 'walk', bones.leg.rotat: unknown timeline"),
            "{m}"
        );
        let m = message(json!({"bones": {"leg": {"rotate": [
            {"time": 0, "value": 1}, {"time": 1, "value": "x"}]}}}));
        assert!(
            m.starts_with("animation 'walk', bones.leg.rotate key 1: invalid type"),
            "{m}"
        );
        let m = message(json!({"bones": {"leg": {"translate": [
            {"time": 0, "value": [0, 0], "curve": [0.1, 0, 0.2, 0]}, {"time": 1, "value": [1, 1]}]}}}));
        assert!(m.contains("curve of 4 numbers; expected 8"), "{m}");
        let m = message(json!({"bones": {"leg": {"rotate": [
            {"time": 0, "value": 0, "curve": [1.5, 0, 0.5, 1]}, {"time": 1, "value": 1}]}}}));
        assert!(
            m.contains("curve handle outside its segment's time span [0, 1]"),
            "{m}"
        );
        let m = message(json!({"parts": {"head": {"color": [{"time": 0, "value": "red"}]}}}));
        assert!(
            m.starts_with("animation 'walk', parts.head.color key 0: color \"red\""),
            "{m}"
        );
        let m = message(json!({"parts": {"head": {"visible": [
            {"time": 0, "value": true, "curve": "stepped"}]}}}));
        assert!(
            m.contains("parts.head.visible key 0: unknown field `curve`"),
            "{m}"
        );
        let m = message(
            json!({"cages": {"c": [{"time": 0, "value": [[0, 0], [1, 0], [1, 1]]},
                                               {"time": 1, "value": [[0, 0], [1, 0]]}]}}),
        );
        assert!(
            m.contains("cages.c: key 1 has 2 vertices but key 0 has 3"),
            "{m}"
        );
        let m = message(json!({"draw_order": [{"time": 0, "value": ["a", "a"]}]}));
        assert!(m.contains("draw_order: key 0 lists part 'a' twice"), "{m}");
        let m = message(json!({"ik": [{"at": [0, 0], "to": []}]}));
        assert_eq!(m, "animation 'walk', ik[0].to: has no keys");
        let m = message(json!({"ik": [{"to": [{"time": 0, "value": [0, 0]}]}]}));
        assert!(
            m.starts_with("animation 'walk', ik[0]: missing field `at`"),
            "{m}"
        );
        let m = message(json!({"bone": {}}));
        assert!(
            m.starts_with("animation 'walk': unknown section 'bone'"),
            "{m}"
        );
        let m = message(json!({"bones": [1]}));
        assert_eq!(
            m,
            "animation 'walk', bones: expected an object: name → timelines"
        );
        let m = message(json!([1, 2]));
        assert_eq!(m, "animation 'walk': expected an object: kind → timelines");
        // serde alone would read an empty array as an empty animation.
        let m = message(json!([]));
        assert_eq!(m, "animation 'walk': expected an object: kind → timelines");
        let m = message(json!({"points": {"p": {"rotate": [{"time": -1, "value": 0}]}}}));
        assert!(
            m.contains("key 0 has time -1, which is not a finite number ≥ 0"),
            "{m}"
        );
    }

    #[test]
    fn non_finite_values_built_in_code_are_rejected() {
        let anim = Animation {
            bones: [(
                "leg".to_string(),
                BoneTimelines {
                    scale: Some(vec![Key {
                        time: 0.0,
                        value: [1.0, f64::INFINITY],
                        curve: Curve::Linear,
                    }]),
                    ..Default::default()
                },
            )]
            .into(),
            ..Default::default()
        };
        assert_eq!(
            anim.validate("walk").unwrap_err().to_string(),
            "animation 'walk', bones.leg.scale: key 0 has a value that is not a finite number"
        );
        let mut nan_time = anim.clone();
        nan_time.bones.get_mut("leg").unwrap().scale = Some(vec![Key {
            time: f64::NAN,
            value: [1.0, 1.0],
            curve: Curve::Linear,
        }]);
        assert!(matches!(
            nan_time.validate("walk"),
            Err(AnimError::Timeline {
                problem: TimelineError::BadTime { .. },
                ..
            })
        ));
    }

    #[test]
    fn rig_check_uses_the_pose_error_style() {
        let handles = Handles {
            bones: vec![Bone {
                name: "leg".into(),
                parent: None,
                head: Point::new(0.0, 0.0),
                tail: Point::new(0.0, 10.0),
            }],
            points: vec![PointHandle {
                name: "tip".into(),
                at: Point::new(0.0, 0.0),
                parent: None,
            }],
            cages: vec![Cage {
                name: "belly".into(),
                polygon: vec![
                    Point::new(0.0, 0.0),
                    Point::new(1.0, 0.0),
                    Point::new(1.0, 1.0),
                    Point::new(0.0, 1.0),
                ],
            }],
            ..Default::default()
        };
        let parts = ["body", "head"];
        let check = |v: serde_json::Value| {
            parse(v)
                .unwrap()
                .check_rig("walk", &handles, &parts, &EventDefs::new())
                .map_err(|e| e.to_string())
        };
        let key = json!([{"time": 0, "value": 1}]);
        assert_eq!(check(json!({"bones": {"leg": {"rotate": key}}})), Ok(()));
        assert_eq!(
            check(json!({"bones": {"arm": {"rotate": key}}})),
            Err("animation 'walk' names bone 'arm', which the rig does not have".into())
        );
        assert_eq!(
            check(json!({"points": {"nose": {"rotate": key}}})),
            Err("animation 'walk' names point 'nose', which the rig does not have".into())
        );
        assert_eq!(
            check(json!({"parts": {"tail": {"visible": [{"time": 0, "value": false}]}}})),
            Err("animation 'walk' names part 'tail', which the rig does not have".into())
        );
        assert_eq!(
            check(json!({"cages": {"belly": [{"time": 0, "value": [[0, 0], [1, 0], [1, 1]]}]}})),
            Err(
                "animation 'walk', cages.belly: key 0 has 3 vertices but the rig's cage has 4"
                    .into()
            )
        );
        assert_eq!(
            check(
                json!({"draw_order": [{"time": 0, "value": ["head", "body"]},
                                        {"time": 1, "value": ["head"]}]})
            ),
            Err(
                "animation 'walk', draw_order: key 1 does not list part 'body' (each key lists \
                 every part once)"
                    .into()
            )
        );
        assert_eq!(
            check(json!({"draw_order": [{"time": 0, "value": ["head", "body", "hat"]}]})),
            Err("animation 'walk' names part 'hat', which the rig does not have".into())
        );
    }

    #[test]
    fn the_bundled_animations_fit_the_character_and_loop_seamlessly() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/character");
        let read = |file: &str| -> serde_json::Value {
            serde_json::from_str(&std::fs::read_to_string(format!("{dir}/{file}")).unwrap())
                .unwrap()
        };
        let handles: Handles = serde_json::from_value(read("handles.json")).unwrap();
        let layers = read("layers.json");
        let parts: Vec<&str> = layers["layers"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| l.as_str().unwrap())
            .collect();
        let raw: std::collections::BTreeMap<String, serde_json::Value> =
            serde_json::from_value(read("animations.json")).unwrap();
        let events = events_from_json(&read("events.json")).unwrap();
        assert!(
            animations_from_json(&read("animations.json")).unwrap()["walk"]
                .events
                .iter()
                .any(|k| k.name == "footstep")
        );
        let animations = parse_animations(&raw).unwrap();
        assert_eq!(
            animations_from_json(&read("animations.json")),
            Ok(animations.clone())
        );
        assert_eq!(
            animations_from_json(&serde_json::json!([])),
            Err(AnimError::NotAMap)
        );
        assert_eq!(
            animations.keys().collect::<Vec<_>>(),
            ["hop", "lift", "walk", "wave"].iter().collect::<Vec<_>>()
        );
        for (name, anim) in &animations {
            anim.check_rig(name, &handles, &parts, &events).unwrap();
            let duration = anim.duration_s();
            // The end of the cycle runs into its start: no jump when it wraps.
            let end = anim.sample(duration, false);
            let start = anim.sample(0.0, false);
            for (bone, pose) in &end.bones {
                let other = &start.bones[bone];
                assert!((pose.rotate - other.rotate).abs() < 1e-9, "{name} {bone}");
                assert_eq!(pose.translate, other.translate, "{name} {bone}");
            }
            assert_eq!(end.points, start.points, "{name}");
            assert_eq!(end.ik, start.ik, "{name}");
            // Every frame poses the rig.
            for k in 0..24 {
                let pose = anim.sample(duration * k as f64 / 24.0, true);
                crate::rig::handle_transforms(&handles, &pose).unwrap();
            }
        }
    }
}
