//! The generated rigs the Spine runtime plays (see the test file's documentation): their
//! layers drawn with tiny-skia on a 160×120 canvas, rigged by `sinew rig`, and their
//! animations and events written into the rig file.

use super::command::s;
use super::sinew;
use std::path::{Path, PathBuf};

/// A filled shape on a transparent 160×120 canvas.
fn layer(path: &Path, fill: impl Fn(&mut tiny_skia::PathBuilder), rgb: [u8; 3]) {
    let mut pixmap = tiny_skia::Pixmap::new(160, 120).unwrap();
    let mut pb = tiny_skia::PathBuilder::new();
    fill(&mut pb);
    let mut paint = tiny_skia::Paint::default();
    paint.set_color_rgba8(rgb[0], rgb[1], rgb[2], 255);
    paint.anti_alias = true;
    pixmap.fill_path(
        &pb.finish().unwrap(),
        &paint,
        tiny_skia::FillRule::Winding,
        tiny_skia::Transform::identity(),
        None,
    );
    sinew::io::save_png(path, &sinew::render::rgba_from_pixmap(&pixmap)).unwrap();
}

/// `sinew rig` of the layers `DIR/NAME.png` with `handles`, into `DIR/rig.json`.
fn rig_of(dir: &Path, layers: &[&str], handles: &serde_json::Value) -> PathBuf {
    std::fs::write(dir.join("handles.json"), handles.to_string()).unwrap();
    let rig = dir.join("rig.json");
    let images: Vec<String> = layers
        .iter()
        .map(|n| s(&dir.join(format!("{n}.png"))).to_string())
        .collect();
    let mut args: Vec<&str> = vec!["rig"];
    args.extend(images.iter().map(String::as_str));
    let handles_path = s(&dir.join("handles.json")).to_string();
    let rig_path = s(&rig).to_string();
    args.extend(["--handles", handles_path.as_str(), "-o", rig_path.as_str()]);
    sinew(&args);
    rig
}

/// Writes `animations` into the rig file at `rig`; returns its path.
fn with_animations(rig: PathBuf, animations: serde_json::Value) -> PathBuf {
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&rig).unwrap()).unwrap();
    doc["animations"] = animations;
    std::fs::write(&rig, doc.to_string()).unwrap();
    rig
}

/// A layer shape: the rectangle at (x, y) of size w × h, px.
fn rect(x: f32, y: f32, w: f32, h: f32) -> impl Fn(&mut tiny_skia::PathBuilder) {
    move |pb: &mut tiny_skia::PathBuilder| {
        pb.push_rect(tiny_skia::Rect::from_xywh(x, y, w, h).unwrap())
    }
}

/// Two skeletons, three points (two carried by bones), a cage and a region over three
/// layers, and animations that use every kind of timeline the export writes.
pub fn generated_rig(dir: &Path) -> PathBuf {
    layer(
        &dir.join("body.png"),
        rect(20.0, 25.0, 80.0, 70.0),
        [230, 120, 40],
    );
    layer(
        &dir.join("arm.png"),
        rect(95.0, 48.0, 55.0, 18.0),
        [60, 120, 220],
    );
    layer(
        &dir.join("blob.png"),
        |pb| pb.push_circle(130.0, 98.0, 13.0),
        [90, 200, 90],
    );
    let handles = serde_json::json!({
        "bones": [
            {"name": "arm_b", "parent": "spine_b", "head": [100, 57], "tail": [145, 50]},
            {"name": "spine_b", "head": [60, 88], "tail": [60, 32]},
            {"name": "blob_b", "head": [122, 98], "tail": [138, 98]}
        ],
        "points": [{"name": "nose", "at": [35, 40]},
                   {"name": "knuckle", "at": [135, 58], "parent": "arm_b"},
                   {"name": "tip", "at": [60, 45], "parent": "spine_b"}],
        "cages": [{"name": "belly", "polygon": [[45, 62], [78, 62], [78, 84], [45, 84]]}],
        "regions": [{"name": "patch", "polygon": [[82, 30], [94, 30], [94, 42], [82, 42]]}],
        "bind": {"blob_b": ["blob"], "arm_b": ["arm", "body"]}
    });
    let rig = rig_of(dir, &["body", "arm", "blob"], &handles);
    let animations = serde_json::json!({
        "move": {
            "bones": {
                "spine_b": {"rotate": [
                    {"time": 0.2, "value": 0, "curve": [0.3, 0, 0.5, 25]},
                    {"time": 0.8, "value": 20, "curve": "stepped"},
                    {"time": 1.0, "value": -10}]},
                "arm_b": {
                    "translate": [{"time": 0, "value": [0, 0], "curve": [0.1, 3, 0.4, 5, 0.2, -4, 0.3, 2]},
                                  {"time": 0.5, "value": [4, -6]}],
                    "scale": [{"time": 0, "value": [1, 1]}, {"time": 1, "value": [1.2, 0.8]}],
                    "shear": [{"time": 0.1, "value": [0, 0]}, {"time": 0.9, "value": [5, -8]}]},
                "blob_b": {"rotate": [{"time": 0, "value": 0}, {"time": 1.0, "value": 350}]}
            },
            "points": {"nose": {
                "translate": [{"time": 0, "value": [0, 0], "curve": [0.2, 4, 0.3, 6, 0.2, 0, 0.3, -3]},
                              {"time": 0.6, "value": [6, -5]}],
                "rotate": [{"time": 0, "value": 0}, {"time": 0.6, "value": 30}],
                "scale": [{"time": 0.3, "value": [1, 1]}, {"time": 0.9, "value": [1.3, 0.7]}],
                "shear": [{"time": 0, "value": [0, 0]}, {"time": 0.7, "value": [-8, 12]}]},
                // Carried by a turned bone: offsets turned into its axes, Bézier handles too.
                "knuckle": {
                "translate": [{"time": 0, "value": [0, 0], "curve": [0.25, 3, 0.5, 5, 0.25, -2, 0.5, -6]},
                              {"time": 0.7, "value": [5, -7]}],
                "rotate": [{"time": 0.1, "value": 0}, {"time": 0.8, "value": -40}],
                "shear": [{"time": 0.2, "value": [0, 0]}, {"time": 0.9, "value": [10, -6]}]},
                // Its channels' time handles differ: no turned Bézier says that, so it is baked.
                "tip": {
                "translate": [{"time": 0, "value": [0, 0], "curve": [0.1, 2, 0.6, 4, 0.4, 0, 0.5, 3]},
                              {"time": 0.9, "value": [4, 6]}]}},
            "cages": {"belly": [
                {"time": 0, "value": [[45, 62], [78, 62], [78, 84], [45, 84]], "curve": [0.2, 0, 0.3, 1]},
                {"time": 0.7, "value": [[43, 60], [82, 63], [80, 88], [44, 86]]}]},
            "parts": {
                "arm": {"color": [{"time": 0, "value": "ffffffff", "curve": [0.2, 1, 0.3, 0.5, 0.2, 1, 0.3, 0.5, 0.2, 1, 0.3, 1, 0.2, 1, 0.3, 0.8]},
                                  {"time": 0.6, "value": "ff8040cc"}]},
                "blob": {"visible": [{"time": 0.1, "value": true}, {"time": 0.5, "value": false},
                                     {"time": 0.9, "value": true}]}
            },
            "draw_order": [{"time": 0.3, "value": ["arm", "body", "blob"]},
                           {"time": 0.75, "value": ["body", "arm", "blob"]}],
            // Several at one time, one on a frame time (0.3 s at 30 fps, stored by the runtime
            // as 0.30000001 s), one at the end (fired as the loop wraps), overrides of each
            // payload field.
            "events": [
                {"time": 0, "name": "step", "string": "left"},
                {"time": 0.3, "name": "hit", "int": 7, "float": 2.5},
                {"time": 0.3, "name": "step", "volume": 0.5},
                {"time": 0.55, "name": "step", "string": "right", "balance": -0.25},
                {"time": 0.61, "name": "cue"},
                {"time": 1.0, "name": "hit"}
            ]
        },
        "idle": {"bones": {"spine_b": {"rotate": [{"time": 0.5, "value": 12}]}},
                 "events": [{"time": 0.25, "name": "cue", "string": "blink"}]}
    });
    let rig = with_animations(rig, animations);
    with_events(
        rig,
        serde_json::json!({
            "step": {"int": 1, "string": "foot", "audio": "sfx/step.ogg", "volume": 0.9},
            "hit": {"float": 1.25},
            "cue": {}
        }),
    )
}

/// Writes the event definitions `events` into the rig file at `rig`; returns its path.
fn with_events(rig: PathBuf, events: serde_json::Value) -> PathBuf {
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&rig).unwrap()).unwrap();
    doc["events"] = events;
    std::fs::write(&rig, doc.to_string()).unwrap();
    rig
}

/// Three layers: an arm with a two-bone constraint, a flag on a pole that a one-bone constraint
/// aims, both at the target `reach`; a tail of three bones reaching for `tail_goal` (FABRIK).
/// `reach` moves on Bézier keys while the arm's own bones are keyed too (the constraint's mix
/// blends from those keys); `tail_goal` moves on linear keys.
pub fn ik_rig(dir: &Path) -> PathBuf {
    layer(
        &dir.join("arm.png"),
        rect(15.0, 20.0, 135.0, 12.0),
        [60, 120, 220],
    );
    layer(
        &dir.join("flag.png"),
        rect(84.0, 40.0, 46.0, 40.0),
        [230, 120, 40],
    );
    // An oval (a rectangle here once met a mesh bug, since fixed: collinear outline vertices).
    layer(
        &dir.join("tail.png"),
        |pb| pb.push_oval(tiny_skia::Rect::from_xywh(12.0, 84.0, 142.0, 22.0).unwrap()),
        [90, 200, 90],
    );
    let handles = serde_json::json!({
        "bones": [
            {"name": "upper", "head": [20, 26], "tail": [80, 26]},
            {"name": "lower", "parent": "upper", "head": [80, 26], "tail": [140, 26]},
            {"name": "pole", "head": [90, 78], "tail": [90, 50]},
            {"name": "reach", "head": [120, 45], "tail": [128, 45]},
            {"name": "t1", "head": [20, 95], "tail": [60, 95]},
            {"name": "t2", "parent": "t1", "head": [60, 95], "tail": [100, 95]},
            {"name": "t3", "parent": "t2", "head": [100, 95], "tail": [145, 95]},
            {"name": "tail_goal", "head": [145, 95], "tail": [150, 95]}
        ],
        "bind": {
            "upper": ["arm"], "lower": ["arm"], "pole": ["flag"], "reach": ["flag"],
            "t1": ["tail"], "t2": ["tail"], "t3": ["tail"], "tail_goal": ["tail"]
        },
        "ik": [
            {"name": "arm_ik", "bones": ["upper", "lower"], "target": "reach",
             "bend_positive": false, "mix": 0.85, "softness_px": 8},
            {"name": "look", "bones": ["pole"], "target": "reach"},
            {"name": "tail_ik", "bones": ["t1", "t2", "t3"], "target": "tail_goal"}
        ]
    });
    let rig = rig_of(dir, &["arm", "flag", "tail"], &handles);
    let animations = serde_json::json!({
        "reach": {
            "bones": {
                "reach": {"translate": [
                    {"time": 0, "value": [0, 0], "curve": [0.2, -10, 0.35, -40, 0.1, 5, 0.3, 20]},
                    {"time": 0.5, "value": [-45, 25], "curve": [0.6, -45, 0.8, 10, 0.6, 25, 0.9, -20]},
                    {"time": 1.0, "value": [15, -30]}]},
                "upper": {"rotate": [{"time": 0, "value": 0}, {"time": 1.0, "value": 40}],
                          "scale": [{"time": 0.3, "value": [1, 1]}, {"time": 0.9, "value": [1.15, 0.85]}]},
                "lower": {"rotate": [{"time": 0.2, "value": 0, "curve": [0.3, 10, 0.5, -30]},
                                     {"time": 0.7, "value": -25}]}
            }
        },
        "curl": {
            "bones": {
                "tail_goal": {"translate": [{"time": 0, "value": [0, 0]},
                                            {"time": 1.0, "value": [-25, -40]}]}
            }
        }
    });
    with_animations(rig, animations)
}
