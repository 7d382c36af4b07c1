//! Physics values mean what the outputs need (issue 44, item 4): every value just outside a
//! range is refused by render and every export alike (one line naming the file, the
//! constraint and the field as written, exit 2, nothing written), and every value just inside
//! is rendered with finite output and exported with the numbers the runtime reads (a mass that
//! is not 0 in f32), and played: sinew's simulation and spine-core's (tools/spine-check) of the
//! export stay finite and agree. Physics together with momentum is refused by the exports as
//! by render.

mod command;
mod common;

use command::{assert_bad_input, s, scratch, sinew};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// A two-bone rig of a 64 px critter (`a`, and `b`, 12 px long, hanging from it) with an
/// animation `swing` that turns `a` back and forth: its document and path.
fn rig(dir: &Path) -> (Value, PathBuf) {
    let sprite = dir.join("critter.png");
    common::critter(64).save(&sprite).unwrap();
    let (mut doc, rig) = command::rig_cli(
        dir,
        &[&sprite],
        r#"{"bones":[{"name":"a","head":[32,45],"tail":[32,30]},
                     {"name":"b","parent":"a","head":[32,30],"tail":[32,18]}]}"#,
        &[],
    );
    doc["animations"] = json!({"swing": {"bones": {"a": {
        "rotate": [{"time": 0, "value": 0}, {"time": 0.25, "value": 30},
                   {"time": 0.5, "value": -30}, {"time": 0.75, "value": 0}],
        "translate": [{"time": 0, "value": [0, 0]}, {"time": 0.4, "value": [6, -4]},
                      {"time": 0.75, "value": [0, 0]}]}}}});
    (doc, rig)
}

fn with_physics(doc: &Value, constraint: Value) -> Value {
    let mut doc = doc.clone();
    let mut c = json!({"name": "tail", "bone": "b", "x": 1, "y": 1, "rotate": 1});
    for (k, v) in constraint.as_object().unwrap() {
        c[k] = v.clone();
    }
    doc["handles"]["physics"] = json!([c]);
    doc
}

/// The commands that must refuse or accept a rig alike: render, and the three exports.
fn commands<'a>(rig: &'a Path, out: &'a Path) -> Vec<Vec<String>> {
    let o = |name: &str| out.join(name).to_string_lossy().into_owned();
    let r = s(rig).to_string();
    vec![
        vec![
            "render".into(),
            r.clone(),
            "--anim".into(),
            "swing".into(),
            "--fps".into(),
            "12".into(),
            "-o".into(),
            o("swing.gif"),
        ],
        vec![
            "export".into(),
            "spine".into(),
            r.clone(),
            "-o".into(),
            o("spine"),
        ],
        vec![
            "export".into(),
            "gltf".into(),
            r.clone(),
            "-o".into(),
            o("rig.glb"),
        ],
        vec![
            "export".into(),
            "dragonbones".into(),
            r,
            "-o".into(),
            o("db"),
        ],
    ]
}

/// Just outside each range: (the constraint's fields, the message's field and reason).
fn outside() -> Vec<(Value, &'static str)> {
    vec![
        (
            json!({"mass": 1e-300}),
            "\"mass\" is 1e-300: at least 1.1754944e-38",
        ),
        (json!({"mass": 0}), "\"mass\" is 0: at least"),
        (json!({"damping": 1e6}), "\"damping\" is 1e6: in [0, 1]"),
        (
            json!({"damping": 1.0001}),
            "\"damping\" is 1.0001: in [0, 1]",
        ),
        (json!({"damping": -0.1}), "\"damping\" is -0.1: in [0, 1]"),
        (json!({"inertia": 1.5}), "\"inertia\" is 1.5: in [0, 1]"),
        (json!({"mix": -0.5}), "\"mix\" is -0.5: in [0, 1]"),
        (json!({"rotate": 2}), "\"rotate\" is 2: in [0, 1]"),
        (json!({"shear_x": 1.01}), "\"shear_x\" is 1.01: in [0, 1]"),
        (json!({"strength": -1}), "\"strength\" is -1: at least 0"),
        (json!({"fps": 0}), "\"fps\" is 0: in (0, 1000]"),
        (json!({"fps": 1001}), "\"fps\" is 1001: in (0, 1000]"),
        (json!({"limit": -1}), "\"limit\" is -1: at least 0"),
        // strength 100 / mass 1 at 60 fps, undamped: K = 100/3600 < 4 (fine); at 5 fps K = 4.
        (json!({"fps": 5}), "the runtime's spring step diverges"),
        (
            json!({"strength": 14400.1}),
            "the runtime's spring step diverges",
        ),
        (
            json!({"mass": 0.0069}),
            "the runtime's spring step diverges",
        ),
        (json!({"gravity": 1, "strength": 0}), "without \"strength\""),
        (json!({"gravity": 2.5001e3, "strength": 1}), "px away"),
    ]
}

/// Just inside each range, and the spring at its stability bound's edge.
fn inside() -> Vec<Value> {
    vec![
        json!({"mass": 1.2e-38, "strength": 0}),
        json!({"damping": 1}),
        json!({"damping": 0}),
        json!({"inertia": 1, "mix": 1, "rotate": 1, "shear_x": 1}),
        json!({"inertia": 0, "mix": 0}),
        json!({"strength": 0}),
        json!({"fps": 1000}),
        json!({"fps": 5.001}),
        json!({"strength": 14399, "damping": 1}),
        json!({"mass": 0.00695, "damping": 1}),
        json!({"gravity": 2.5e3, "strength": 1, "mass": 1}),
        json!({"gravity": 5, "wind": 3, "rotate": 1, "x": 0, "y": 0, "strength": 0, "mass": 1}),
        json!({"limit": 0}),
    ]
}

#[test]
fn values_just_outside_a_range_are_refused_by_render_and_every_export_alike() {
    let tmp = scratch("physics-outside");
    let dir = tmp.path();
    let (doc, rig) = rig(dir);
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    for (constraint, message) in outside() {
        std::fs::write(&rig, with_physics(&doc, constraint.clone()).to_string()).unwrap();
        for args in commands(&rig, &out) {
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let stderr = assert_bad_input(&args, message);
            assert!(
                stderr.contains(&format!("{}: ", rig.display()))
                    && stderr.contains("physics constraint 'tail': "),
                "names the file and the constraint: {stderr}"
            );
        }
        assert!(
            std::fs::read_dir(&out).unwrap().next().is_none(),
            "{constraint}: nothing written"
        );
    }
}

#[test]
fn values_just_inside_are_rendered_finite_and_exported_as_the_runtime_reads_them() {
    let tmp = scratch("physics-inside");
    let dir = tmp.path();
    let (doc, rig) = rig(dir);
    for constraint in inside() {
        std::fs::write(&rig, with_physics(&doc, constraint.clone()).to_string()).unwrap();
        let out = dir.join("out");
        let _ = std::fs::remove_dir_all(&out);
        std::fs::create_dir_all(&out).unwrap();
        for args in commands(&rig, &out) {
            let run = sinew(&args.iter().map(String::as_str).collect::<Vec<_>>());
            assert!(
                run.status.success(),
                "{constraint}: {args:?}: {}",
                String::from_utf8_lossy(&run.stderr)
            );
        }
        // The posed vertices at every frame time are finite.
        for t in ["0.1", "0.4", "0.75"] {
            let vertices = out.join("v.json");
            let run = sinew(&[
                "pose",
                s(&rig),
                "--anim",
                "swing",
                "--time",
                t,
                "--vertices",
                s(&vertices),
                "-o",
                s(&out.join("p.png")),
            ]);
            assert!(
                run.status.success(),
                "{constraint} at {t}: {}",
                String::from_utf8_lossy(&run.stderr)
            );
            let v: Value =
                serde_json::from_str(&std::fs::read_to_string(&vertices).unwrap()).unwrap();
            for p in v["parts"][0]["vertices"].as_array().unwrap() {
                assert!(
                    p[0].as_f64().is_some_and(f64::is_finite)
                        && p[1].as_f64().is_some_and(f64::is_finite)
                );
            }
        }
        // The Spine JSON carries a mass the runtime can divide by (f32, not 0) and the values.
        let spine: Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("spine/rig.json")).unwrap())
                .unwrap();
        let physics = &spine["physics"][0];
        let mass = physics["mass"].as_f64().unwrap();
        assert!(
            mass > 0.0 && (1.0 / mass as f32).is_finite(),
            "{constraint}: mass {mass}"
        );
        let damping = physics["damping"].as_f64().unwrap();
        assert!(
            (0.0..=1.0).contains(&damping),
            "{constraint}: damping {damping}"
        );
    }
}

/// Runtime vs sinew's runtime-matching playback, px (as tests/spine_runtime.rs).
const ANIMATION_TOLERANCE_PX: f64 = 0.01;
/// Where positions are large, the tolerance is this many f32 roundings of the coordinate.
const F32_ULPS: f64 = 16.0;
/// The rate games update physics at (spine-check's UPDATE_HZ), and how long it is played: past
/// the animation's end (0.75 s), where only the spring still moves.
const PHYSICS_HZ: f64 = 60.0;
const PHYSICS_SECONDS: f64 = 2.0;

/// The world vertices spine-core (tools/spine-check, pinned) gives every mesh of the export
/// `dir/rig.json` playing `swing` at `times`, as a game updates physics at 60 Hz: per time, per
/// slot, its attachment's name and vertices (Spine's axes).
fn spine_core_plays(dir: &Path, times: &[f64]) -> Vec<(f64, Vec<(String, Vec<f64>)>)> {
    let request = dir.join("request.json");
    let out = dir.join("oracle.json");
    std::fs::write(&request, json!({"times": {"swing": times}}).to_string()).unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tools/spine-check/run.sh");
    let status = std::process::Command::new(script)
        .args([
            s(&dir.join("rig.json")),
            s(&dir.join("rig.atlas")),
            s(&request),
            s(&out),
        ])
        .status()
        .expect("run tools/spine-check/run.sh (needs bash, node and npm, or root to install them)");
    assert!(status.success(), "spine-core refused {}", dir.display());
    let oracle: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(oracle["warnings"], json!([]), "spine-core's loader warns");
    let frames = oracle["animations"]["swing"]["frames"].as_array().unwrap();
    frames
        .iter()
        .map(|f| {
            let slots = f["slots"].as_array().unwrap();
            let meshes = slots
                .iter()
                .filter(|slot| slot["vertices"].is_array())
                .map(|slot| {
                    let name = slot["attachment"]
                        .as_str()
                        .or(slot["name"].as_str())
                        .unwrap()
                        .to_string();
                    // A non-finite number arrives as JSON null: kept as NaN, and refused below.
                    let v = slot["vertices"].as_array().unwrap();
                    (
                        name,
                        v.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect(),
                    )
                })
                .collect();
            (f["time"].as_f64().unwrap(), meshes)
        })
        .collect()
}

/// Every value just inside the ranges, played: sinew's own simulation (the render's and
/// `--match-runtime spine`'s, `export::spine::played`) is finite at every 60 Hz update for 2 s,
/// the Spine export of it plays finitely in spine-core (the runtime's PhysicsConstraint), and the
/// two agree within 0.01 px (or 16 f32 roundings of the coordinate, where it is far out) at every update — so a value the check lets through is one the
/// runtime can step, not just one that exports.
#[test]
fn values_just_inside_play_in_spine_core_as_sinew_simulates_them() {
    use sinew::export::spine::played::as_played;
    use sinew::export::spine::{export_spine, SpineOptions};
    use sinew::pipeline::Scene;
    use sinew::skin::Blend;
    let tmp = scratch("physics-played");
    let dir = tmp.path();
    let (doc, rig) = rig(dir);
    let n = (PHYSICS_SECONDS * PHYSICS_HZ) as usize;
    let times: Vec<f64> = (0..=n).map(|k| k as f64 / PHYSICS_HZ).collect();
    let mut moved_most: f64 = 0.0;
    for constraint in inside() {
        std::fs::write(&rig, with_physics(&doc, constraint.clone()).to_string()).unwrap();
        let out = dir.join("spine");
        let _ = std::fs::remove_dir_all(&out);
        let run = sinew(&["export", "spine", s(&rig), "-o", s(&out), "--name", "rig"]);
        assert!(
            run.status.success(),
            "{constraint}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        let scene = Scene::load(&rig).unwrap();
        let images: Vec<_> = scene
            .doc
            .parts
            .iter()
            .map(|p| sinew::io::load_png(&sinew::io::RigDocument::image_path(&rig, p)).unwrap())
            .collect();
        let options = SpineOptions::default();
        let export = export_spine(&scene, &images, "rig", &options).unwrap();
        let played = as_played(&scene, "swing", &scene.doc.animations["swing"], &options).unwrap();
        let runtime = spine_core_plays(&out, &times);
        assert_eq!(runtime.len(), times.len());
        let (mut worst, mut moved, mut far) = (0.0_f64, 0.0_f64, 0.0_f64);
        for (t, meshes) in &runtime {
            let f = played.frame(*t, false).unwrap();
            let ours = scene
                .positions_from_transforms(&f.transforms, &f.pose, Blend::Linear)
                .unwrap();
            let still = scene.without_physics().pose_positions(&f.pose).unwrap();
            for (name, vertices) in meshes {
                let part = scene
                    .doc
                    .parts
                    .iter()
                    .position(|p| &p.name == name)
                    .unwrap();
                let mesh = &export.parts[part].mesh;
                assert_eq!(vertices.len(), 2 * mesh.vertex_source.len(), "{name}");
                for (k, &v) in mesh.vertex_source.iter().enumerate() {
                    let (x, y) = (vertices[2 * k], vertices[2 * k + 1]);
                    let ours = ours[part][v];
                    assert!(
                        x.is_finite() && y.is_finite() && ours.x.is_finite() && ours.y.is_finite(),
                        "{constraint} at {t} s: spine-core [{x}, {y}], sinew {ours:?}"
                    );
                    let c = export.frame.canvas_from_spine([x, y].into());
                    let d = (sinew::geom::Point::new(c[0], c[1]) - ours).norm();
                    // The runtime computes in f32: far out (a strong gravity on a weak spring
                    // holds the bone thousands of px away), its rounding exceeds 0.01 px.
                    let f32_rounding = F32_ULPS * f64::from(f32::EPSILON) * ours.coords.abs().max();
                    assert!(
                        d <= ANIMATION_TOLERANCE_PX.max(f32_rounding),
                        "{constraint} at {t} s: spine-core and sinew {d} px apart"
                    );
                    worst = worst.max(d);
                    far = far.max(ours.coords.abs().max());
                    moved = moved.max((ours - still[part][v]).norm());
                }
            }
        }
        println!(
            "{constraint}: {} updates, spine-core vs sinew max {worst:.2e} px (at most {far:.0} px from the origin), physics moves up to {moved:.2} px",
            times.len()
        );
        moved_most = moved_most.max(moved);
    }
    // The simulation matters: some of the values swing the bone away from its pose.
    assert!(
        moved_most > 1.0,
        "physics moved the mesh only {moved_most} px"
    );
}

#[test]
fn physics_with_momentum_is_refused_by_every_export_as_by_render() {
    let tmp = scratch("physics-momentum");
    let dir = tmp.path();
    let (doc, rig) = rig(dir);
    let mut doc = with_physics(&doc, json!({}));
    doc["options"]["ik"]["momentum"] = json!({"a": 0.2});
    // No animation: the exports used to write this with exit 0.
    doc.as_object_mut().unwrap().remove("animations");
    std::fs::write(&rig, doc.to_string()).unwrap();
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    for args in commands(&rig, &out).into_iter().skip(1) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_bad_input(&args, "cannot be combined with the skinning IK's momentum");
    }
    assert!(std::fs::read_dir(&out).unwrap().next().is_none());
}
