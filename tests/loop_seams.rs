//! The seam of a looping animation, measured in the real runtimes (issue 43): the bundled
//! character's walk (flagged `loop`; its tail carries a physics constraint) exported as Spine
//! 4.1 and 4.3 (physics baked into keys), Spine 4.2 (physics simulated live by the runtime),
//! glTF and DragonBones (everything baked), played by spine-core (tools/spine-check), three.js
//! (tools/gltf-check) and DragonBonesJS looping the animation for ever (tools/dragonbones-check)
//! at every bake frame (30 fps).
//!
//! The seam is the step from the last frame of the loop (the last bake time before the end) to
//! the first frame of the next loop (time 0 again); a step inside the loop is the step between
//! two consecutive frames before the end. A step is the largest displacement of any vertex of a
//! part. For the baked exports, every part's seam must be no larger than its largest step
//! inside the loop: the bake is the periodic steady state (`scene::play`), not a simulation
//! restarted at each loop. Spine 4.2 simulates physics itself: what it does at the boundary is
//! the runtime's, measured (on a copy of the walk played twice in a row, as a looping track
//! plays it) and printed, not bounded.

mod command;

use command::{s, scratch};
use serde::Deserialize;
use sinew::export::gltf::frame::GltfFrame;
use sinew::export::spine::bake::bake_times;
use sinew::export::spine::SpineFrame;
use sinew::geom::{Point, Vec2};
use sinew::io::RigDocument;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// The rate the exports bake at and the runtimes are sampled at, frames per second.
const BAKE_FPS: f64 = 30.0;
/// Rounding allowed on top of the largest step inside the loop, px (the runtimes store f32).
const SLACK_PX: f64 = 1e-3;
/// The animation measured.
const ANIMATION: &str = "walk";

fn sinew(args: &[&str]) {
    let out = command::sinew(args);
    assert!(
        out.status.success(),
        "sinew {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Each part's vertices (canvas px) at each sampled time, in time order.
type Track = BTreeMap<String, Vec<Vec<Point>>>;

/// One part's seam and its largest step inside the loop, px.
#[derive(Debug)]
struct Seam {
    part: String,
    seam_px: f64,
    inside_px: f64,
}

/// Largest distance between the vertices of two frames of a part.
fn step(a: &[Point], b: &[Point]) -> f64 {
    assert_eq!(a.len(), b.len(), "the vertex count changed between frames");
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max)
}

/// Per part: the step from frame `last` to frame `next` (the seam) and the largest step between
/// consecutive frames over `inside` (pairs k → k + 1 for k in the range).
fn seams(track: &Track, last: usize, next: usize, inside: std::ops::Range<usize>) -> Vec<Seam> {
    track
        .iter()
        .map(|(part, frames)| Seam {
            part: part.clone(),
            seam_px: step(&frames[last], &frames[next]),
            inside_px: inside
                .clone()
                .map(|k| step(&frames[k], &frames[k + 1]))
                .fold(0.0, f64::max),
        })
        .collect()
}

/// Prints the seams of `runtime` and returns the parts whose seam exceeds their inside steps.
fn report(runtime: &str, seams: &[Seam]) -> Vec<String> {
    let tail = seams
        .iter()
        .find(|s| s.part == "tail")
        .expect("a tail part");
    let worst = seams
        .iter()
        .filter(|s| s.part != "tail")
        .max_by(|a, b| (a.seam_px - a.inside_px).total_cmp(&(b.seam_px - b.inside_px)))
        .expect("other parts");
    println!(
        "{runtime}: tail seam {:.3} px (largest step inside the loop {:.3} px); other parts: \
         worst seam - inside step {:+.3} px ({}: seam {:.3}, inside {:.3})",
        tail.seam_px,
        tail.inside_px,
        worst.seam_px - worst.inside_px,
        worst.part,
        worst.seam_px,
        worst.inside_px
    );
    seams
        .iter()
        .filter(|s| s.seam_px > s.inside_px + SLACK_PX)
        .map(|s| {
            format!(
                "{runtime} {}: seam {:.3} px > {:.3} px inside",
                s.part, s.seam_px, s.inside_px
            )
        })
        .collect()
}

/// Prints how far the frame at the end (the track's last) is from the frame at 0, over all
/// parts: the steady state's drift over one period as the bake keyed it.
fn print_end_gap(track: &Track) {
    let gap = track
        .values()
        .map(|frames| step(&frames[frames.len() - 1], &frames[0]))
        .fold(0.0, f64::max);
    println!("  the end vs time 0: {gap:.2e} px");
}

#[derive(Deserialize)]
struct SpineSlot {
    name: String,
    vertices: Option<Vec<f64>>,
}

#[derive(Deserialize)]
struct SpineFrameOut {
    time: f64,
    slots: Vec<SpineSlot>,
}

#[derive(Deserialize)]
struct SpinePlayed {
    frames: Vec<SpineFrameOut>,
}

#[derive(Deserialize)]
struct SpineOracle {
    animations: BTreeMap<String, SpinePlayed>,
}

/// `dir/rig.json` + `.atlas` played by spine-core: `animation` at `times`, mesh vertices in
/// canvas px by slot.
fn spine_track(dir: &Path, doc: &RigDocument, animation: &str, times: &[f64]) -> Track {
    let request = dir.join("request.json");
    let out = dir.join("oracle.json");
    let json = serde_json::json!({ "times": { animation: times } });
    std::fs::write(&request, json.to_string()).unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tools/spine-check/run.sh");
    let status = Command::new(script)
        .args([
            s(&dir.join("rig.json")),
            s(&dir.join("rig.atlas")),
            s(&request),
            s(&out),
        ])
        .status()
        .expect("run tools/spine-check/run.sh (needs bash, node and npm, or root to install them)");
    assert!(status.success(), "spine-core refused {}", dir.display());
    let oracle: SpineOracle =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let frame = SpineFrame::for_canvas(doc.canvas);
    let mut track = Track::new();
    for (k, f) in oracle.animations[animation].frames.iter().enumerate() {
        assert!((f.time - times[k]).abs() < 1e-12);
        for slot in &f.slots {
            let Some(v) = &slot.vertices else { continue };
            let points = v
                .chunks(2)
                .map(|q| frame.canvas_from_spine(Point::new(q[0], q[1])))
                .collect();
            track.entry(slot.name.clone()).or_default().push(points);
        }
    }
    track
}

#[derive(Deserialize)]
struct GltfFrameOut {
    meshes: BTreeMap<String, Vec<f64>>,
}

#[derive(Deserialize)]
struct GltfPlayed {
    frames: Vec<GltfFrameOut>,
}

#[derive(Deserialize)]
struct GltfOracle {
    animations: BTreeMap<String, GltfPlayed>,
}

/// `glb` played by three.js: `animation` at `times`, vertices in canvas px by mesh.
fn gltf_track(glb: &Path, doc: &RigDocument, animation: &str, times: &[f64]) -> Track {
    let request = glb.with_extension("request.json");
    let out = glb.with_extension("oracle.json");
    let json = serde_json::json!({ "times": { animation: times } });
    std::fs::write(&request, json.to_string()).unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tools/gltf-check/run.sh");
    let status = Command::new(script)
        .args([s(glb), s(&request), s(&out)])
        .status()
        .expect("run tools/gltf-check/run.sh (needs bash, node and npm, or root to install them)");
    assert!(status.success(), "three.js refused {}", glb.display());
    let oracle: GltfOracle = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let frame = GltfFrame::for_canvas(doc.canvas, 100.0);
    let mut track = Track::new();
    for f in &oracle.animations[animation].frames {
        for (mesh, v) in &f.meshes {
            let points = v
                .chunks(3)
                .map(|q| frame.canvas_from(Vec2::new(q[0], q[1])))
                .collect();
            track.entry(mesh.clone()).or_default().push(points);
        }
    }
    track
}

#[derive(Deserialize)]
struct DbSlot {
    display: Option<String>,
    vertices: Option<Vec<f64>>,
}

#[derive(Deserialize)]
struct DbFrameOut {
    slots: Vec<DbSlot>,
}

#[derive(Deserialize)]
struct DbPlayed {
    frames: Vec<DbFrameOut>,
}

#[derive(Deserialize)]
struct DbOracle {
    animations: BTreeMap<String, DbPlayed>,
}

/// `dir/rig_ske.json` looped for ever by the DragonBones runtime (advanced in small steps from
/// the start), `animation` at `times`; vertices in canvas px by display.
fn dragonbones_track(dir: &Path, doc: &RigDocument, animation: &str, times: &[f64]) -> Track {
    let request = dir.join("request.json");
    let out = dir.join("oracle.json");
    let json =
        serde_json::json!({ "times": { animation: times }, "loop": true, "step": 1.0 / 240.0 });
    std::fs::write(&request, json.to_string()).unwrap();
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tools/dragonbones-check/run.sh"
    );
    let status = Command::new(script)
        .args([
            s(&dir.join("rig_ske.json")),
            s(&dir.join("rig_tex.json")),
            s(&request),
            s(&out),
        ])
        .status()
        .expect("run tools/dragonbones-check/run.sh (needs bash, node and npm)");
    assert!(
        status.success(),
        "the DragonBones runtime refused {}",
        dir.display()
    );
    let oracle: DbOracle = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    // DragonBones' origin is the canvas' bottom centre, y down.
    let origin = Vec2::new(f64::from(doc.canvas[0]) / 2.0, f64::from(doc.canvas[1]));
    let mut track = Track::new();
    for f in &oracle.animations[animation].frames {
        for slot in &f.slots {
            if let (Some(display), Some(v)) = (&slot.display, &slot.vertices) {
                let points = v
                    .chunks(2)
                    .map(|q| Point::new(q[0] + origin.x, q[1] + origin.y))
                    .collect();
                track.entry(display.clone()).or_default().push(points);
            }
        }
    }
    track
}

/// A key list of a Spine animation played twice in a row: the keys, then the same keys
/// `duration` later (Bézier handle times too). The first copy's key at the end is dropped
/// where the second copy keys time 0, as the loop would show that key's time as 0.
fn twice(keys: &[serde_json::Value], duration: f64) -> Vec<serde_json::Value> {
    let time = |k: &serde_json::Value| k.get("time").and_then(|t| t.as_f64()).unwrap_or(0.0);
    let mut out = keys.to_vec();
    if keys.len() > 1
        && time(&keys[0]) == 0.0
        && (time(&keys[keys.len() - 1]) - duration).abs() < 1e-9
    {
        out.pop();
    }
    for key in keys {
        let mut key = key.clone();
        let t = time(&key) + duration;
        key["time"] = serde_json::json!(t);
        if let Some(curve) = key.get_mut("curve").and_then(|c| c.as_array_mut()) {
            for (i, n) in curve.iter_mut().enumerate() {
                if i % 2 == 0 {
                    *n = serde_json::json!(n.as_f64().unwrap() + duration);
                }
            }
        }
        out.push(key);
    }
    out
}

/// Every key list inside a Spine animation (timelines by bone, slot, attachment, constraint;
/// events and draw order), played twice in a row.
fn play_twice(value: &mut serde_json::Value, duration: f64) {
    match value {
        serde_json::Value::Object(map) => {
            for v in map.values_mut() {
                match v {
                    serde_json::Value::Array(keys) if keys.iter().all(|k| k.is_object()) => {
                        *keys = twice(keys, duration);
                    }
                    _ => play_twice(v, duration),
                }
            }
        }
        serde_json::Value::Array(keys) => *keys = twice(keys, duration),
        _ => {}
    }
}

#[test]
fn the_looping_walk_has_no_seam_in_spine_gltf_and_dragonbones() {
    let tmp = scratch("walk");
    let dir = tmp.path();
    sinew(&["demo", "-o", s(dir)]);
    let rig = dir.join("character.json");
    let doc = RigDocument::load(&rig).unwrap();
    let walk = &doc.animations[ANIMATION];
    assert!(walk.looping, "the demo's walk is flagged as a loop");
    assert!(!doc.handles.physics.is_empty(), "the tail has physics");
    let duration = walk.duration_s();
    let times = bake_times(duration, BAKE_FPS);
    // The last frame inside the loop, and the first of the next loop: time 0 again.
    let last = times.iter().rposition(|&t| t < duration - 1e-9).unwrap();
    let mut failures = Vec::new();

    for version in ["4.1", "4.3"] {
        let out = dir.join(format!("spine-{version}"));
        sinew(&[
            "export",
            "spine",
            s(&rig),
            "-o",
            s(&out),
            "--name",
            "rig",
            "--spine-version",
            version,
        ]);
        let track = spine_track(&out, &doc, ANIMATION, &times);
        failures.extend(report(
            &format!("Spine {version} (baked)"),
            &seams(&track, last, 0, 0..last),
        ));
        print_end_gap(&track);
    }

    // Spine 4.2: the runtime simulates the tail; the walk played twice in a row, the frames
    // across the first loop's end.
    let out = dir.join("spine-4.2");
    sinew(&["export", "spine", s(&rig), "-o", s(&out), "--name", "rig"]);
    let path = out.join("rig.json");
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let mut doubled = json["animations"][ANIMATION].clone();
    play_twice(&mut doubled, duration);
    json["animations"]["walk_twice"] = doubled;
    std::fs::write(&path, json.to_string()).unwrap();
    let frames = (2.0 * duration * BAKE_FPS).round() as usize;
    let twice_times: Vec<f64> = (0..=frames).map(|k| k as f64 / BAKE_FPS).collect();
    let next = twice_times
        .iter()
        .position(|&t| t >= duration - 1e-9)
        .unwrap();
    let track = spine_track(&out, &doc, "walk_twice", &twice_times);
    report(
        "Spine 4.2 (live physics, measured only)",
        &seams(&track, next - 1, next, 0..next - 1),
    );

    let glb = dir.join("walk.glb");
    sinew(&["export", "gltf", s(&rig), "-o", s(&glb)]);
    let track = gltf_track(&glb, &doc, ANIMATION, &times);
    failures.extend(report("glTF (baked)", &seams(&track, last, 0, 0..last)));
    print_end_gap(&track);

    // DragonBones: playTimes 0, the runtime loops; its frames on whole frames of 30 fps, the
    // last one the start of the next loop.
    let out = dir.join("dragonbones");
    sinew(&[
        "export",
        "dragonbones",
        s(&rig),
        "-o",
        s(&out),
        "--name",
        "rig",
    ]);
    let n = (duration * BAKE_FPS).round() as usize;
    let frame_times: Vec<f64> = (0..=n).map(|k| k as f64 / BAKE_FPS).collect();
    let track = dragonbones_track(&out, &doc, ANIMATION, &frame_times);
    failures.extend(report(
        "DragonBones (baked, looping)",
        &seams(&track, n - 1, n, 0..n - 1),
    ));

    assert!(
        failures.is_empty(),
        "seams at the loop boundary:\n{}",
        failures.join("\n")
    );
}
