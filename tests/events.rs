//! Events end to end through the binary: `sinew render --events` prints what each frame fires,
//! the sprite sheet's JSON lists them per frame, the Spine export carries them (played in
//! spine-core by `tests/spine_runtime.rs`), and bad events are refused in one line, exit 2,
//! with nothing written.

mod command;
mod common;

use command::{assert_bad_input, s, scratch, sinew};
use std::path::Path;

/// A one-bone rig of the critter at `dir/rig.json` with `events` defined and `animation` as
/// `go`; returns its JSON.
fn rig_with(dir: &Path, events: serde_json::Value, animation: serde_json::Value) -> String {
    let sprite = dir.join("critter.png");
    common::critter(64).save(&sprite).unwrap();
    let (mut doc, rig) = command::rig_cli(
        dir,
        &[&sprite],
        r#"{"bones":[{"name":"a","head":[32,45],"tail":[32,20]}]}"#,
        &[],
    );
    doc["events"] = events;
    doc["animations"] = serde_json::json!({ "go": animation });
    let text = doc.to_string();
    std::fs::write(&rig, &text).unwrap();
    text
}

#[test]
fn render_prints_and_the_sheet_lists_each_frames_events() {
    let tmp = scratch("render");
    let dir = tmp.path();
    rig_with(
        dir,
        serde_json::json!({
            "step": {"int": 1, "audio": "sfx/step.wav", "volume": 0.8},
            "land": {"float": 2.5, "string": "thud"}
        }),
        serde_json::json!({
            "bones": {"a": {"rotate": [{"time": 0, "value": 0}, {"time": 1, "value": 0}]}},
            "events": [
                {"time": 0, "name": "step", "string": "left"},
                {"time": 0.3, "name": "land"},
                {"time": 0.5, "name": "step", "string": "right", "balance": 0.5},
                {"time": 1, "name": "land", "int": 3}
            ]
        }),
    );
    let sheet = dir.join("go.png");
    let rig = dir.join("rig.json");
    let out = sinew(&[
        "render",
        s(&rig),
        "--anim",
        "go",
        "--fps",
        "10",
        "--events",
        "-o",
        s(&sheet),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    // stdout: only the event lines; the summary went to stderr.
    let lines: Vec<serde_json::Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert!(stderr.contains("10 frames"), "{stderr}");
    let seen: Vec<(u64, &str, f64)> = lines
        .iter()
        .map(|l| {
            (
                l["frame"].as_u64().unwrap(),
                l["event"]["name"].as_str().unwrap(),
                l["event"]["time"].as_f64().unwrap(),
            )
        })
        .collect();
    // Frames at 0, 0.1, …, 0.9: the key at 1 s (the loop's end) fires as frame 0 comes round
    // again, before the key at 0; 0.3 fires on the frame at 0.3 (0.3 is 3/10 s exactly).
    assert_eq!(
        seen,
        [
            (0, "land", 1.0),
            (0, "step", 0.0),
            (3, "land", 0.3),
            (5, "step", 0.5)
        ]
    );
    assert_eq!(lines[0]["frame_time"], 0.0);
    let right = &lines[3]["event"];
    assert_eq!(right["int"], 1);
    assert_eq!(right["string"], "right");
    assert_eq!(
        right["audio"],
        serde_json::json!({"path": "sfx/step.wav", "volume": 0.8, "balance": 0.5})
    );
    assert_eq!(lines[0]["event"]["int"], 3);
    assert_eq!(lines[0]["event"]["float"], 2.5);
    assert_eq!(lines[0]["event"]["string"], "thud");
    assert!(lines[0]["event"].get("audio").is_none());

    // The sheet's JSON: the same events on the same frames; frames without any carry none.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("go.json")).unwrap()).unwrap();
    let frames = json["frames"].as_object().unwrap();
    let names: Vec<&String> = frames.keys().collect();
    assert_eq!(names.len(), 10);
    for (k, name) in names.iter().enumerate() {
        let listed = frames[*name]
            .get("events")
            .map_or(vec![], |e| e.as_array().unwrap().clone());
        let expected: Vec<&serde_json::Value> = lines
            .iter()
            .filter(|l| l["frame"] == k)
            .map(|l| &l["event"])
            .collect();
        assert_eq!(listed.iter().collect::<Vec<_>>(), expected, "frame {k}");
        if expected.is_empty() {
            assert!(frames[*name].get("events").is_none());
        }
    }

    // The Spine export: the definitions and the keys.
    let export = dir.join("spine");
    let out = sinew(&[
        "export",
        "spine",
        s(&rig),
        "-o",
        s(&export),
        "--name",
        "rig",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let spine: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(export.join("rig.json")).unwrap()).unwrap();
    assert_eq!(
        spine["events"]["step"],
        serde_json::json!({"int": 1, "audio": "sfx/step.wav", "volume": 0.8, "balance": 0.0})
    );
    assert_eq!(
        spine["animations"]["go"]["events"]
            .as_array()
            .unwrap()
            .len(),
        4
    );
}

#[test]
fn bad_events_are_refused_in_one_line() {
    let tmp = scratch("bad");
    let dir = tmp.path();
    let anim = |name: &str| {
        serde_json::json!({"bones": {"a": {"rotate": [{"time": 0, "value": 0}]}},
                           "events": [{"time": 0.5, "name": name}]})
    };
    let cases = [
        (
            serde_json::json!({"step": {}}),
            anim("jump"),
            "animation 'go' names event 'jump', which the rig does not have",
        ),
        (
            serde_json::json!({"step": {"audio": "a.wav", "volume": 3}}),
            anim("step"),
            "event 'step': volume must be a finite number in [0, 1] (got 3)",
        ),
        (
            serde_json::json!({"step": {"balance": 0.5}}),
            anim("step"),
            "event 'step': volume and balance are for an event with audio",
        ),
        (
            serde_json::json!({"step": {}}),
            serde_json::json!({"events": [{"time": 1, "name": "step"}, {"time": 0.5, "name": "step"}]}),
            "events: key 1 at 0.5 s does not come after the previous key at 1 s",
        ),
        (
            serde_json::json!({"step": {"int": 1.5}}),
            anim("step"),
            "not a valid rig document",
        ),
    ];
    let rig = dir.join("rig.json");
    for (events, animation, message) in cases {
        rig_with(dir, events, animation);
        let gif = dir.join("out.gif");
        assert_bad_input(&["render", s(&rig), "--anim", "go", "-o", s(&gif)], message);
        assert!(!gif.exists());
        let export = dir.join("spine");
        assert_bad_input(&["export", "spine", s(&rig), "-o", s(&export)], message);
        assert!(!export.exists());
    }
}
