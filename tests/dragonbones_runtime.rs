//! The DragonBones export played by the official runtime (tools/dragonbones-check: the
//! DragonBonesJS core from npm `@cocos/dragonbones-js` and the official PixiSlot, pinned; see
//! its check.mjs): on every frame of every animation and between frames, the runtime's world
//! vertices of every mesh must lie within 0.01 px of sinew's reproduction of the runtime
//! (`sinew::export::dragonbones::played`, what `--match-runtime dragonbones` plays), its setup
//! pose within 0.001 px of the rest meshes, the displays it shows and their draw order must be
//! sinew's, the events it fires the export's, and its loader must find nothing it would ignore.
//! The deviation from sinew's exact playback is printed.
//!
//! Rigs: the bundled character as `sinew demo` writes it (physics, a deform key, an attachment
//! swap, events), a generated rig with two skeletons, points, a cage, a region, colour,
//! visibility and draw-order keys and an event, and a generated rig with bone IK constraints
//! (both from tests/spine_runtime/rigs.rs).

mod command;
#[path = "spine_runtime/rigs.rs"]
mod rigs;

use command::{s, scratch};
use serde::Deserialize;
use sinew::export::dragonbones::{
    export_dragonbones, played, DragonBonesExport, DragonBonesOptions,
};
use sinew::geom::{Point, Vec2};
use sinew::io::{self, RigDocument};
use sinew::pipeline::Scene;
use sinew::scene::PlayOptions;
use sinew::skin::Blend;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// The runtime vs sinew's reproduction of it, px.
const TOLERANCE_PX: f64 = 0.01;
/// The runtime's setup pose vs the rest meshes, px (f32 numbers in the file).
const SETUP_TOLERANCE_PX: f64 = 0.001;
/// Times sampled between frames per frame interval.
const BETWEEN: [f64; 2] = [0.25, 0.7];

fn sinew(args: &[&str]) {
    let out = command::sinew(args);
    assert!(
        out.status.success(),
        "sinew {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[derive(Deserialize)]
struct SlotState {
    name: String,
    display: Option<String>,
    visible: bool,
    vertices: Option<Vec<f64>>,
}

#[derive(Deserialize)]
struct Frame {
    time: f64,
    slots: Vec<SlotState>,
}

#[derive(Deserialize)]
struct Played {
    frames: Vec<Frame>,
}

#[derive(Deserialize)]
struct Event {
    name: Option<String>,
    #[serde(rename = "type")]
    kind: String,
    time: f64,
    int: Option<i64>,
    float: Option<f64>,
    string: Option<String>,
}

#[derive(Deserialize)]
struct Oracle {
    setup: Vec<SlotState>,
    animations: BTreeMap<String, Played>,
    events: BTreeMap<String, Vec<Vec<Event>>>,
    warnings: Vec<String>,
}

fn run_oracle(dir: &Path, request: serde_json::Value) -> Oracle {
    let request_path = dir.join("request.json");
    let out = dir.join("oracle.json");
    std::fs::write(&request_path, request.to_string()).unwrap();
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tools/dragonbones-check/run.sh"
    );
    let status = Command::new(script)
        .args([
            s(&dir.join("rig_ske.json")),
            s(&dir.join("rig_tex.json")),
            s(&request_path),
            s(&out),
        ])
        .status()
        .expect("run tools/dragonbones-check/run.sh (needs bash, node and npm)");
    assert!(
        status.success(),
        "the DragonBones runtime refused {}",
        dir.display()
    );
    serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap()
}

/// `sinew pose RIG --anim NAME --time T --match-runtime RUNTIME --vertices V.json`: the posed
/// vertices the CLI writes.
fn cli_pose(rig: &Path, dir: &Path, runtime: &str, name: &str, time_s: f64) -> Vec<Vec<Point>> {
    #[derive(Deserialize)]
    struct Part {
        vertices: Vec<[f64; 2]>,
    }
    #[derive(Deserialize)]
    struct Posed {
        parts: Vec<Part>,
    }
    let v = dir.join(format!("{runtime}-{name}-{time_s}.json"));
    let t = time_s.to_string();
    sinew(&[
        "pose",
        s(rig),
        "--anim",
        name,
        "--time",
        &t,
        "--match-runtime",
        runtime,
        "--vertices",
        s(&v),
    ]);
    let posed: Posed = serde_json::from_str(&std::fs::read_to_string(&v).unwrap()).unwrap();
    posed
        .parts
        .iter()
        .map(|p| p.vertices.iter().map(|v| Point::new(v[0], v[1])).collect())
        .collect()
}

/// Largest distance between two posings of every part, px.
fn farthest(a: &[Vec<Point>], b: &[Vec<Point>]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| p.iter().zip(q).map(|(u, v)| (u - v).norm()))
        .fold(0.0, f64::max)
}

/// Largest distance between the runtime's vertices of each visible mesh (armature space) and
/// `sinew`'s (canvas px).
fn deviation(
    export: &DragonBonesExport,
    doc: &RigDocument,
    slots: &[SlotState],
    sinew: &[Vec<Point>],
) -> f64 {
    let mut worst: f64 = 0.0;
    for slot in slots {
        let (Some(display), Some(vertices)) = (&slot.display, &slot.vertices) else {
            continue;
        };
        let part = doc.parts.iter().position(|p| &p.name == display).unwrap();
        assert_eq!(
            slot.name,
            doc.slot_of(part),
            "{display} shown in another slot"
        );
        // The runtime's mesh is the decimated one: each vertex a fine-mesh vertex.
        let source = &export.vertex_source[part];
        assert_eq!(vertices.len(), 2 * source.len(), "{display}");
        for (q, &v) in vertices.chunks(2).zip(source) {
            let c = export.frame.canvas_from(Vec2::new(q[0], q[1]));
            worst = worst.max((c - sinew[part][v]).norm());
        }
    }
    worst
}

/// Exports `rig` into `dir` and holds the runtime to sinew; returns (worst vs the reproduction,
/// worst vs sinew's exact playback, the skeleton file's bytes).
fn check_rig(rig: &Path, dir: &Path) -> (f64, f64, usize) {
    sinew(&[
        "export",
        "dragonbones",
        s(rig),
        "-o",
        s(dir),
        "--name",
        "rig",
    ]);
    let scene = Scene::load(rig).unwrap();
    let doc = scene.doc.clone();
    let images: Vec<_> = doc
        .parts
        .iter()
        .map(|p| io::load_png(&RigDocument::image_path(rig, p)).unwrap())
        .collect();
    let options = DragonBonesOptions::default();
    let export = export_dragonbones(&scene, &images, "rig", &options).unwrap();
    assert!(
        std::fs::read_to_string(dir.join("rig_ske.json")).unwrap() == export.ske,
        "the CLI's export differs from the same export in-process"
    );
    let fps = f64::from(export.frame_rate);
    let mut times = BTreeMap::new();
    let mut steps = BTreeMap::new();
    for baked in &export.animations {
        let n = baked.frame_count;
        let mut t: Vec<f64> = (0..=n).map(|k| f64::from(k) / fps).collect();
        for k in 0..n {
            t.extend(BETWEEN.map(|u| (f64::from(k) + u) / fps));
        }
        t.sort_by(f64::total_cmp);
        times.insert(baked.name.clone(), t);
        // From the start as a game plays it, to the end.
        steps.insert(baked.name.clone(), vec![(None::<f64>, f64::from(n) / fps)]);
    }
    let oracle = run_oracle(dir, serde_json::json!({ "times": times, "events": steps }));
    assert!(oracle.warnings.is_empty(), "{:#?}", oracle.warnings);

    // What the runtime skins with: the strongest influences the export kept.
    let limited = scene.with_influences_limited(options.max_influences.unwrap_or(usize::MAX));
    let rest = scene.rest_positions();
    let d = deviation(&export, &doc, &oracle.setup, &rest);
    assert!(d <= SETUP_TOLERANCE_PX, "setup pose: {d} px");

    let slots = doc.slot_names();
    let attachments = |slot: &str| -> Vec<String> {
        doc.attachments_of(slot)
            .into_iter()
            .map(|i| doc.parts[i].name.clone())
            .collect()
    };
    let (mut worst, mut exact_worst) = (0.0_f64, 0.0_f64);
    for baked in &export.animations {
        let name = &baked.name;
        let animation = &doc.animations[name];
        let frames = &oracle.animations[name].frames;
        let times: Vec<f64> = frames
            .iter()
            .map(|f| f.time.min(animation.duration_s()))
            .collect();
        let exact =
            sinew::scene::frames(&scene, animation, &times, PlayOptions::default()).unwrap();
        for (frame, exact) in frames.iter().zip(&exact) {
            let t = frame.time;
            let (transforms, pose) = played::as_played(&export, baked, &slots, &attachments, t);
            let positions = limited
                .positions_from_transforms(&transforms, &pose, Blend::Linear)
                .unwrap();
            let d = deviation(&export, &doc, &frame.slots, &positions);
            assert!(
                d <= TOLERANCE_PX,
                "{name} at {t} s: the runtime is {d} px from sinew"
            );
            worst = worst.max(d);
            let exact_positions = scene
                .positions_from_transforms(&exact.transforms, &exact.pose, Blend::Linear)
                .unwrap();
            exact_worst = exact_worst.max(deviation(&export, &doc, &frame.slots, &exact_positions));
            // What is drawn, back to front: the same displays in the same order.
            let draws = sinew::playback::pose_draws(&scene, &positions, &pose);
            let sinew_shown: Vec<&str> = draws
                .iter()
                .filter(|d| d.visible)
                .map(|d| doc.parts[d.part].name.as_str())
                .collect();
            let runtime_shown: Vec<&str> = frame
                .slots
                .iter()
                .filter(|s| s.visible)
                .filter_map(|s| s.display.as_deref())
                .collect();
            assert_eq!(
                runtime_shown, sinew_shown,
                "{name} at {t} s: displays or draw order"
            );
        }
        // Events: the export's, on their frames, with their payloads.
        let fired: Vec<&Event> = oracle.events[name][0]
            .iter()
            .filter(|e| e.kind == "frameEvent")
            .collect();
        let mut expected: Vec<_> = animation
            .events
            .iter()
            .map(|k| {
                let def = doc.events.get(&k.name).cloned().unwrap_or_default();
                let e = k.fired(&def, sinew::anim::CurveEvaluation::Exact);
                let frame = ((k.time * fps).round() / fps).min(f64::from(baked.frame_count) / fps);
                (e.name, frame, i64::from(e.int), e.float, e.string)
            })
            .collect();
        expected.sort_by(|a, b| a.1.total_cmp(&b.1));
        assert_eq!(
            fired.len(),
            expected.len(),
            "{name}: events fired {:?}, expected {expected:?}",
            fired.iter().map(|e| (&e.name, e.time)).collect::<Vec<_>>()
        );
        for (got, want) in fired.iter().zip(&expected) {
            assert_eq!(got.name.as_deref(), Some(want.0.as_str()), "{name}");
            assert!(
                (got.time - want.1).abs() < 1e-6,
                "{name}: {} at {} s, not {} s",
                want.0,
                got.time,
                want.1
            );
            assert_eq!(got.int, Some(want.2));
            assert!((got.float.unwrap_or(f64::NAN) - want.3).abs() < 1e-6);
            assert_eq!(got.string.as_deref(), Some(want.4.as_str()));
        }
    }
    // `sinew pose --match-runtime dragonbones` poses through the same reproduction (its own
    // meshes, every influence).
    if let Some(baked) = export.animations.first() {
        let name = &baked.name;
        for t in [0.0, 0.51 / fps, 0.5 * doc.animations[name].duration_s()] {
            let (transforms, pose) = played::as_played(&export, baked, &slots, &attachments, t);
            let expected = scene
                .positions_from_transforms(&transforms, &pose, Blend::Linear)
                .unwrap();
            let d = farthest(&cli_pose(rig, dir, "dragonbones", name, t), &expected);
            assert!(
                d < 1e-6,
                "sinew pose --match-runtime dragonbones at {t} s: {d} px"
            );
        }
    }
    println!(
        "{}: {} KB; runtime vs sinew's reproduction max {worst:.2e} px; vs sinew's exact \
         playback {exact_worst:.3} px",
        rig.display(),
        export.ske.len() / 1024
    );
    (worst, exact_worst, export.ske.len())
}

#[test]
fn the_demo_character_plays_in_dragonbones_where_sinew_draws_it() {
    let tmp = scratch("demo");
    let dir = tmp.path();
    sinew(&["demo", "-o", s(dir)]);
    check_rig(&dir.join("character.json"), dir);
}

#[test]
fn a_rig_with_every_handle_kind_and_timeline_plays_in_dragonbones() {
    let tmp = scratch("generated");
    let rig = rigs::generated_rig(tmp.path());
    check_rig(&rig, tmp.path());
}

#[test]
fn bone_ik_rigs_play_in_dragonbones_as_sinew_solves_them() {
    let tmp = scratch("ik");
    let rig = rigs::ik_rig(tmp.path());
    check_rig(&rig, tmp.path());
}
