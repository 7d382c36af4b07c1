//! The glTF export checked by its real consumers (tools/gltf-check, pinned in its
//! package-lock.json and installed by its run.sh): the Khronos glTF validator must report no
//! error and no warning, and three.js — GLTFLoader, AnimationMixer and SkinnedMesh's CPU
//! skinning with morph targets — must put every vertex of every mesh within 0.01 px of sinew's
//! pose path (skinned with the four influences the file keeps) at every bake time of every
//! animation, within 0.01 px of sinew's reproduction of the runtime
//! (`sinew::export::gltf::played`, what `--match-runtime gltf` plays) at every time, bake
//! times and between them, and the setup pose within 0.001 px of the rest meshes. Between bake
//! times the runtime interpolates the baked keys; that deviation from sinew's exact playback is
//! printed, as is the cost of keeping four influences.
//!
//! Rigs: the bundled character as `sinew demo` writes it (physics on the tail, a deform key
//! squashing the torso: morph targets; an attachment swap, which glTF does not carry), a
//! generated rig with two skeletons, points, a cage and a region, and a generated rig with bone
//! IK constraints (both from tests/spine_runtime/rigs.rs).

mod command;
#[path = "spine_runtime/rigs.rs"]
mod rigs;

use command::{s, scratch};
use serde::Deserialize;
use sinew::export::gltf::frame::GltfFrame;
use sinew::export::gltf::{export_gltf, played, GltfOptions, MAX_INFLUENCES};
use sinew::export::spine::bake::bake_times;
use sinew::geom::{Point, Vec2};
use sinew::io::{self, RigDocument};
use sinew::pipeline::Scene;
use sinew::scene::PlayOptions;
use sinew::skin::Blend;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// Runs sinew with `args`; it must succeed (the generated rigs are made through it).
fn sinew(args: &[&str]) {
    let out = command::sinew(args);
    assert!(
        out.status.success(),
        "sinew {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// three.js vs sinew at the bake times, px.
const TOLERANCE_PX: f64 = 0.01;
/// three.js's setup pose vs the rest meshes, px.
const SETUP_TOLERANCE_PX: f64 = 0.001;

#[derive(Deserialize)]
struct Validator {
    errors: u64,
    warnings: u64,
    messages: Vec<serde_json::Value>,
}

#[derive(Deserialize)]
struct Frame {
    time: f64,
    meshes: BTreeMap<String, Vec<f64>>,
}

#[derive(Deserialize)]
struct Played {
    frames: Vec<Frame>,
}

#[derive(Deserialize)]
struct Oracle {
    validator: Validator,
    meshes: Vec<String>,
    setup: BTreeMap<String, Vec<f64>>,
    animations: BTreeMap<String, Played>,
}

fn run_oracle(glb: &Path, times: &BTreeMap<String, Vec<f64>>) -> Oracle {
    let request = glb.with_extension("request.json");
    let out = glb.with_extension("oracle.json");
    std::fs::write(&request, serde_json::json!({ "times": times }).to_string()).unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tools/gltf-check/run.sh");
    let status = Command::new(script)
        .args([s(glb), s(&request), s(&out)])
        .status()
        .expect("run tools/gltf-check/run.sh (needs bash, node and npm, or root to install them)");
    assert!(status.success(), "three.js refused {}", glb.display());
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

/// Largest distance between three.js's vertices of `name` (glTF units) and `sinew`'s (px).
fn deviation(frame: &GltfFrame, runtime: &[f64], sinew: &[Point], name: &str) -> f64 {
    assert_eq!(runtime.len(), 3 * sinew.len(), "{name}: vertex count");
    runtime
        .chunks(3)
        .zip(sinew)
        .map(|(q, p)| (frame.canvas_from(Vec2::new(q[0], q[1])) - p).norm())
        .fold(0.0, f64::max)
}

/// The worst deviations of one rig: at bake times, between them, and sinew's four-influence
/// skinning against all influences.
struct Report {
    reproduced_px: f64,
    at_keys_px: f64,
    between_keys_px: f64,
    four_influences_px: f64,
    bytes: usize,
}

fn check_rig(rig: &Path, dir: &Path) -> Report {
    let glb = dir.join("rig.glb");
    sinew(&["export", "gltf", s(rig), "-o", s(&glb)]);
    let scene = Scene::load(rig).unwrap();
    let doc = scene.doc.clone();
    let images: Vec<_> = doc
        .parts
        .iter()
        .map(|p| io::load_png(&RigDocument::image_path(rig, p)).unwrap())
        .collect();
    let options = GltfOptions::default();
    let export = export_gltf(&scene, &images, &options).unwrap();
    assert!(
        std::fs::read(&glb).unwrap() == export.glb,
        "the CLI's export differs from the same export in-process"
    );
    let mut times = BTreeMap::new();
    for (name, animation) in &doc.animations {
        let keys = bake_times(animation.duration_s(), options.bake_fps);
        let mut all = keys.clone();
        all.extend(keys.windows(2).map(|w| w[0] + 0.37 * (w[1] - w[0])));
        all.sort_by(f64::total_cmp);
        times.insert(name.clone(), all);
    }
    let oracle = run_oracle(&glb, &times);
    let v = &oracle.validator;
    assert!(
        v.errors == 0 && v.warnings == 0,
        "the validator reports {} errors and {} warnings: {:#?}",
        v.errors,
        v.warnings,
        v.messages
    );
    assert_eq!(oracle.meshes, export.parts);
    let frame = GltfFrame::for_canvas(doc.canvas, options.px_per_unit);
    let part = |name: &str| doc.parts.iter().position(|p| p.name == name).unwrap();
    let rest = scene.rest_positions();
    for (name, xyz) in &oracle.setup {
        let d = deviation(&frame, xyz, &rest[part(name)], name);
        assert!(d <= SETUP_TOLERANCE_PX, "setup pose of {name}: {d} px");
    }
    let limited = scene.with_influences_limited(MAX_INFLUENCES);
    let mut report = Report {
        reproduced_px: 0.0,
        at_keys_px: 0.0,
        between_keys_px: 0.0,
        four_influences_px: 0.0,
        bytes: export.glb.len(),
    };
    for (name, played) in &oracle.animations {
        let animation = &doc.animations[name];
        let keys = bake_times(animation.duration_s(), options.bake_fps);
        let times: Vec<f64> = played.frames.iter().map(|f| f.time).collect();
        let frames =
            sinew::scene::frames(&scene, animation, &times, PlayOptions::default()).unwrap();
        let keyed = export.animations.iter().find(|a| &a.name == name).unwrap();
        for (runtime, f) in played.frames.iter().zip(&frames) {
            let four = limited
                .positions_from_transforms(&f.transforms, &f.pose, Blend::Linear)
                .unwrap();
            let (transforms, pose) = played::as_played(&export, keyed, runtime.time);
            let reproduced = limited
                .positions_from_transforms(&transforms, &pose, Blend::Linear)
                .unwrap();
            let all = scene
                .positions_from_transforms(&f.transforms, &f.pose, Blend::Linear)
                .unwrap();
            let at_key = keys.contains(&runtime.time);
            for (mesh, xyz) in &runtime.meshes {
                let i = part(mesh);
                let r = deviation(&frame, xyz, &reproduced[i], mesh);
                assert!(
                    r <= TOLERANCE_PX,
                    "{name} at {} s, {mesh}: three.js is {r} px from sinew's reproduction",
                    runtime.time
                );
                report.reproduced_px = report.reproduced_px.max(r);
                let d = deviation(&frame, xyz, &four[i], mesh);
                if at_key {
                    assert!(
                        d <= TOLERANCE_PX,
                        "{name} at {} s, {mesh}: three.js is {d} px from sinew",
                        runtime.time
                    );
                    report.at_keys_px = report.at_keys_px.max(d);
                    for (a, b) in four[i].iter().zip(&all[i]) {
                        report.four_influences_px = report.four_influences_px.max((a - b).norm());
                    }
                } else {
                    report.between_keys_px = report.between_keys_px.max(d);
                }
            }
        }
    }
    // `sinew pose --match-runtime gltf` poses through the same reproduction (every influence:
    // sinew draws its own meshes).
    if let Some(keyed) = export.animations.first() {
        let animation = &keyed.name;
        for t in [
            0.0,
            0.51 / options.bake_fps,
            0.5 * doc.animations[animation].duration_s(),
        ] {
            let (transforms, pose) = played::as_played(&export, keyed, t);
            let expected = scene
                .positions_from_transforms(&transforms, &pose, Blend::Linear)
                .unwrap();
            let d = farthest(&cli_pose(rig, dir, "gltf", animation, t), &expected);
            assert!(d < 1e-6, "sinew pose --match-runtime gltf at {t} s: {d} px");
        }
    }
    println!(
        "{}: {} KB; three.js vs sinew's reproduction max {:.2e} px; vs sinew at the bake times \
         max {:.2e} px, between them {:.3} px; four influences vs all {:.3} px",
        rig.display(),
        report.bytes / 1024,
        report.reproduced_px,
        report.at_keys_px,
        report.between_keys_px,
        report.four_influences_px
    );
    report
}

#[test]
fn the_demo_character_plays_in_three_js_where_sinew_draws_it() {
    let tmp = scratch("demo");
    let dir = tmp.path();
    sinew(&["demo", "-o", s(dir)]);
    let rig = dir.join("character.json");
    let doc = RigDocument::load(&rig).unwrap();
    assert!(!doc.handles.physics.is_empty() && !doc.animations["hop"].deform.is_empty());
    check_rig(&rig, dir);
}

#[test]
fn a_rig_with_every_handle_kind_plays_in_three_js() {
    let tmp = scratch("generated");
    let rig = rigs::generated_rig(tmp.path());
    check_rig(&rig, tmp.path());
}

#[test]
fn bone_ik_rigs_play_in_three_js_as_sinew_solves_them() {
    let tmp = scratch("ik");
    let rig = rigs::ik_rig(tmp.path());
    check_rig(&rig, tmp.path());
}

/// `sinew target` records the runtime in the rig; `sinew pose` then plays as it without being
/// told (the same vertices as `--match-runtime`), `--exact` plays exactly, and `none` forgets it.
#[test]
fn the_rig_remembers_its_target_runtime() {
    let tmp = scratch("target");
    let dir = tmp.path();
    sinew(&["demo", "-o", s(dir)]);
    let rig = dir.join("character.json");
    let pose = |extra: &[&str]| -> Vec<u8> {
        let v = dir.join("v.json");
        let mut args = vec![
            "pose",
            s(&rig),
            "--anim",
            "hop",
            "--time",
            "0.41",
            "--vertices",
            s(&v),
        ];
        args.extend_from_slice(extra);
        sinew(&args);
        std::fs::read(&v).unwrap()
    };
    let exact = pose(&[]);
    let target = |arg: Option<&str>| -> String {
        let mut args = vec!["target", s(&rig)];
        args.extend(arg);
        let out = command::sinew(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).trim().to_string()
    };
    assert_eq!(target(None), "none");
    for (runtime, flag) in [
        ("gltf", "gltf"),
        ("dragonbones", "dragonbones"),
        ("spine-4.2", "spine"),
    ] {
        target(Some(runtime));
        assert_eq!(target(None), runtime);
        let played = pose(&[]);
        assert_eq!(played, pose(&["--match-runtime", flag]), "{runtime}");
        assert_ne!(played, exact, "{runtime}: plays as exact");
        assert_eq!(pose(&["--exact"]), exact, "{runtime}: --exact");
    }
    target(Some("none"));
    assert_eq!(pose(&[]), exact);
    command::assert_bad_input(&["target", s(&rig), "godot"], "unknown runtime 'godot'");
}
