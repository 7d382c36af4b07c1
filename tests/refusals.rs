//! Input that used to be accepted (exit 0, a blank or invalid output) or ran for minutes is
//! refused up front: one line naming what is wrong and what to change, exit code 2, no output.

mod command;
mod common;

use command::{assert_bad_input, s, scratch};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// A one-bone rig of a 64 px critter; its document and path.
fn rig(dir: &Path) -> (Value, PathBuf) {
    let sprite = dir.join("critter.png");
    common::critter(64).save(&sprite).unwrap();
    let (mut doc, rig) = command::rig_cli(
        dir,
        &[&sprite],
        r#"{"bones":[{"name":"a","head":[32,45],"tail":[32,20]}]}"#,
        &[],
    );
    doc["animations"] = json!({"go": {"bones": {"a": {"rotate": [
        {"time": 0, "value": 0}, {"time": 0.25, "value": 30}
    ]}}}});
    std::fs::write(&rig, doc.to_string()).unwrap();
    (doc, rig)
}

fn write(dir: &Path, name: &str, value: &Value) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, value.to_string()).unwrap();
    path
}

#[test]
fn export_names_that_make_hidden_files_are_refused() {
    let tmp = scratch("name");
    let dir = tmp.path();
    let (_, rig) = rig(dir);
    let out = dir.join("export");
    for name in [".", "..", ".hidden"] {
        assert_bad_input(
            &["export", "spine", s(&rig), "-o", s(&out), "--name", name],
            "a name starting with '.'",
        );
    }
    assert!(!out.exists());
}

#[test]
fn ik_drag_targets_have_one_limit_in_pose_render_and_export() {
    let tmp = scratch("drag");
    let dir = tmp.path();
    let (mut doc, _) = rig(dir);
    let pose = write(
        dir,
        "far.json",
        &json!({"ik": [{"at": [32, 30], "to": [1e7, 0]}]}),
    );
    let rig_path = write(dir, "r.json", &doc);
    let png = dir.join("out.png");
    assert_bad_input(
        &["pose", s(&rig_path), "--pose", s(&pose), "-o", s(&png)],
        "beyond ±1000000 px",
    );
    // The same target keyed in an animation: refused when the document is read, whichever
    // command reads it (render used to take it from a cached grip).
    doc["animations"]["far"] = json!({"ik": [{"at": [32, 30], "to": [
        {"time": 0, "value": [32, 30]}, {"time": 0.5, "value": [1e7, 0]}
    ]}]});
    let rig_path = write(dir, "far-rig.json", &doc);
    let gif = dir.join("out.gif");
    for args in [
        vec!["render", s(&rig_path), "--anim", "far", "-o", s(&gif)],
        vec!["pose", s(&rig_path), "--anim", "far", "-o", s(&png)],
        vec!["export", "spine", s(&rig_path), "-o", s(&dir.join("e"))],
    ] {
        assert_bad_input(&args, "beyond ±1000000");
    }
    assert!(!gif.exists() && !png.exists());
}

#[test]
fn a_rig_without_parts_is_refused_on_load() {
    let tmp = scratch("parts");
    let dir = tmp.path();
    let (mut doc, _) = rig(dir);
    doc["parts"] = json!([]);
    let rig_path = write(dir, "empty.json", &doc);
    assert_bad_input(
        &["pose", s(&rig_path), "-o", s(&dir.join("p.png"))],
        "the rig has no parts",
    );
}

#[test]
fn a_scale_that_rounds_the_frame_to_nothing_is_refused() {
    let tmp = scratch("scale");
    let dir = tmp.path();
    let (_, rig_path) = rig(dir);
    let gif = dir.join("tiny.gif");
    assert_bad_input(
        &[
            "render",
            s(&rig_path),
            "--anim",
            "go",
            "--scale",
            "1e-9",
            "-o",
            s(&gif),
        ],
        "smaller than 1 px a side: use a scale of at least 0.015625",
    );
    assert!(!gif.exists());
}

#[test]
fn absurd_magnitudes_are_refused_with_their_limit() {
    let tmp = scratch("magnitudes");
    let dir = tmp.path();
    let (doc, rig_path) = rig(dir);
    let png = dir.join("p.png");
    // A rotation of 1e300 degrees in a pose, and in an animation's key.
    let pose = write(
        dir,
        "spin.json",
        &json!({"bones": {"a": {"rotate": 1e300}}}),
    );
    assert_bad_input(
        &["pose", s(&rig_path), "--pose", s(&pose), "-o", s(&png)],
        "the pose of 'a' has the value 1e300, beyond ±1000000",
    );
    let mut spin = doc.clone();
    spin["animations"]["go"]["bones"]["a"]["rotate"][1]["value"] = json!(1e300);
    let spin_rig = write(dir, "spin-rig.json", &spin);
    assert_bad_input(
        &["pose", s(&spin_rig), "-o", s(&png)],
        "key 1 has a value beyond ±1000000",
    );
    // A Bézier handle's value of ±1e300.
    let mut curve = doc.clone();
    curve["animations"]["go"]["bones"]["a"]["rotate"][0]["curve"] =
        json!([0.1, 1e300, 0.2, -1e300]);
    let curve_rig = write(dir, "curve-rig.json", &curve);
    assert_bad_input(
        &[
            "render",
            s(&curve_rig),
            "--anim",
            "go",
            "-o",
            s(&dir.join("c.gif")),
        ],
        "curve value beyond ±1000000",
    );
    // A bone tail at 1e200 px and at 1.7e308 px (whose length overflowed to null in Spine JSON).
    let sprite = dir.join("critter.png");
    for tail in [1e200, 1.7e308] {
        let handles = write(
            dir,
            "far-bone.json",
            &json!({"bones": [{"name": "a", "head": [32, 45], "tail": [32, tail]}]}),
        );
        assert_bad_input(
            &[
                "rig",
                s(&sprite),
                "--handles",
                s(&handles),
                "-o",
                s(&dir.join("x.json")),
            ],
            "handle 'a' has a coordinate beyond ±1000000 px",
        );
        let mut far = doc.clone();
        far["handles"]["bones"][0]["tail"] = json!([32, tail]);
        let far_rig = write(dir, "far-rig.json", &far);
        assert_bad_input(
            &["export", "spine", s(&far_rig), "-o", s(&dir.join("e"))],
            "beyond ±1000000 px",
        );
    }
    assert!(!dir.join("x.json").exists() && !dir.join("e").exists());
}

#[test]
fn self_intersecting_cages_and_regions_name_the_handle_and_the_edges() {
    let tmp = scratch("bowtie");
    let dir = tmp.path();
    let sprite = dir.join("critter.png");
    common::critter(64).save(&sprite).unwrap();
    let out = dir.join("r.json");
    let bow_tie = json!([[10, 10], [50, 50], [50, 10], [10, 50]]);
    for kind in ["regions", "cages"] {
        let handles = write(
            dir,
            "h.json",
            &json!({"bones": [{"name": "a", "head": [32, 45], "tail": [32, 20]}],
                    kind: [{"name": "tie", "polygon": bow_tie}]}),
        );
        let message = assert_bad_input(
            &["rig", s(&sprite), "--handles", s(&handles), "-o", s(&out)],
            "'tie': edge 0 (vertices 0–1) crosses edge 2 (vertices 2–3)",
        );
        assert!(!message.contains("IMAGE"), "{message}");
    }
    let collinear = write(
        dir,
        "h.json",
        &json!({"cages": [{"name": "line", "polygon": [[10, 10], [20, 20], [30, 30], [40, 40]]}]}),
    );
    assert_bad_input(
        &["rig", s(&sprite), "--handles", s(&collinear), "-o", s(&out)],
        "cage 'line'",
    );
    assert!(!out.exists());
}

#[test]
fn handles_that_make_too_many_weight_columns_are_refused_before_any_work() {
    let tmp = scratch("columns");
    let dir = tmp.path();
    let sprite = dir.join("critter.png");
    common::critter(64).save(&sprite).unwrap();
    let out = dir.join("r.json");
    // A 1000-bone chain, and a 500-vertex circular cage.
    let bones: Vec<Value> = (0..1000)
        .map(|i| {
            let y = 60.0 - f64::from(i) * 0.05;
            let mut bone =
                json!({"name": format!("b{i}"), "head": [32, y], "tail": [32, y - 0.05]});
            if i > 0 {
                bone["parent"] = json!(format!("b{}", i - 1));
            }
            bone
        })
        .collect();
    let chain = write(dir, "chain.json", &json!({ "bones": bones }));
    let t = std::time::Instant::now();
    assert_bad_input(
        &["rig", s(&sprite), "--handles", s(&chain), "-o", s(&out)],
        "1000 weight columns",
    );
    let polygon: Vec<Value> = (0..500)
        .map(|i| {
            let a = f64::from(i) * std::f64::consts::TAU / 500.0;
            json!([32.0 + 40.0 * a.cos(), 32.0 + 40.0 * a.sin()])
        })
        .collect();
    let cage = write(
        dir,
        "cage.json",
        &json!({"cages": [{"name": "c", "polygon": polygon}]}),
    );
    assert_bad_input(
        &[
            "rig",
            s(&sprite),
            "--handles",
            s(&cage),
            "-o",
            s(&out),
            "--monotone",
        ],
        "use fewer handles or cages of fewer vertices",
    );
    assert!(
        t.elapsed().as_secs_f64() < 10.0,
        "refusing took {:?}",
        t.elapsed()
    );
    assert!(!out.exists());
}

/// A cage may cross the drawing's outline (that is what cages are for): the weight domain is
/// the union of the shape and the cage's inside. Cages that cross each other are refused, named.
#[test]
fn a_cage_crossing_the_outline_is_rigged_and_crossing_cages_are_named() {
    let tmp = scratch("cage-outline");
    let dir = tmp.path();
    let sprite = dir.join("critter.png");
    common::critter(64).save(&sprite).unwrap();
    let out = dir.join("r.json");
    // Half inside the drawing, half outside the canvas.
    let handles = write(
        dir,
        "h.json",
        &json!({"cages": [{"name": "belly", "polygon": [[30, 28], [120, 28], [120, 36], [30, 36]]}]}),
    );
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_sinew"))
        .args(["rig", s(&sprite), "--handles", s(&handles), "-o", s(&out)])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let rigged = std::fs::read(&out).unwrap();
    let rig: Value = serde_json::from_slice(&rigged).unwrap();
    let part = &rig["parts"][0];
    let columns: Vec<&str> = part["weights"]["handles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    // Drawn vertices on the cage's top edge, where it cuts into the drawing: each is weighted
    // by that edge's two cage vertices only, linearly along the edge.
    let on_top_edge: Vec<usize> = part["mesh"]["vertices"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
        .filter(|(_, v)| v[1].as_f64() == Some(28.0) && v[0].as_f64().unwrap() > 30.0)
        .map(|(i, _)| i)
        .collect();
    assert!(
        !on_top_edge.is_empty(),
        "no drawn vertex on the cage's edge"
    );
    for &i in &on_top_edge {
        let x = part["mesh"]["vertices"][i][0].as_f64().unwrap();
        let mut by_name = std::collections::BTreeMap::new();
        for entry in part["weights"]["rows"][i].as_array().unwrap() {
            let column = columns[entry[0].as_u64().unwrap() as usize];
            by_name.insert(column.to_string(), entry[1].as_f64().unwrap());
        }
        let expected = (x - 30.0) / 90.0;
        let w1 = by_name.remove("belly.1").unwrap_or(0.0);
        let w0 = by_name.remove("belly.0").unwrap_or(0.0);
        assert!(
            (w1 - expected).abs() < 1e-6,
            "vertex at x = {x}: {w1} for belly.1"
        );
        assert!((w0 + w1 - 1.0).abs() < 1e-6 && by_name.values().all(|&w| w < 1e-9));
    }
    let two = write(
        dir,
        "two.json",
        &json!({"cages": [
            {"name": "a", "polygon": [[-10, -10], [80, -10], [80, 80], [-10, 80]]},
            {"name": "b", "polygon": [[-20, 30], [90, 30], [90, 34], [-20, 34]]}
        ]}),
    );
    assert_bad_input(
        &["rig", s(&sprite), "--handles", s(&two), "-o", s(&out)],
        "cage 'a': it crosses cage 'b'",
    );
    // The refused run left the first rig as it was.
    assert_eq!(std::fs::read(&out).unwrap(), rigged);
}

#[test]
fn the_export_that_match_runtime_reproduces_must_be_one_sinew_writes() {
    let tmp = scratch("match");
    let dir = tmp.path();
    let (_, rig) = rig(dir);
    let png = dir.join("out.png");
    let pose = |extra: &[&str]| {
        let mut args = vec!["pose", s(&rig), "--anim", "go", "--time", "0.1"];
        args.extend(["--match-runtime", "spine", "-o", s(&png)]);
        args.extend_from_slice(extra);
        args.into_iter().map(String::from).collect::<Vec<_>>()
    };
    let args = pose(&["--spine-version", "5.0"]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    assert_bad_input(&args, "5.0");
    let args = pose(&["--bake-fps", "0"]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    assert_bad_input(&args, "bake");
    assert!(!png.exists());
    // The export's options mean nothing without --match-runtime.
    let out = command::sinew(&["pose", s(&rig), "--spine-version", "4.1", "-o", s(&png)]);
    assert_eq!(out.status.code(), Some(2));
    assert!(!png.exists());
}

/// The glTF and DragonBones exports refuse bad options and a rig without weights with one line,
/// and write nothing: an existing output is left as it was.
#[test]
fn gltf_and_dragonbones_exports_refuse_bad_input_and_keep_what_was_there() {
    let tmp = scratch("free-exports");
    let dir = tmp.path();
    let (mut doc, rig) = rig(dir);
    let glb = dir.join("out.glb");
    std::fs::write(&glb, b"earlier").unwrap();
    let db = dir.join("db");
    for (args, message) in [
        (vec!["--fps", "0"], "bake rate"),
        (vec!["--px-per-unit", "0"], "--px-per-unit"),
        (vec!["--layer-spacing=-1"], "layer spacing"),
    ] {
        let mut full = vec!["export", "gltf", s(&rig), "-o", s(&glb)];
        full.extend(args);
        assert_bad_input(&full, message);
    }
    for (args, message) in [
        (vec!["--fps", "0"], "frame rate"),
        (vec!["--max-vertices", "2"], "--max-vertices"),
        (vec!["--max-influences", "0"], "--max-influences"),
    ] {
        let mut full = vec!["export", "dragonbones", s(&rig), "-o", s(&db)];
        full.extend(args);
        assert_bad_input(&full, message);
    }
    // Weights removed: both say what to do.
    doc["parts"][0]["weights"] = Value::Null;
    let unweighted = write(dir, "unweighted.json", &doc);
    assert_bad_input(
        &["export", "gltf", s(&unweighted), "-o", s(&glb)],
        "sinew rig --handles",
    );
    assert_bad_input(
        &["export", "dragonbones", s(&unweighted), "-o", s(&db)],
        "sinew rig --handles",
    );
    // Over its own rig: refused.
    assert_bad_input(&["export", "gltf", s(&rig), "-o", s(&rig)], "");
    assert_eq!(std::fs::read(&glb).unwrap(), b"earlier");
    assert!(!db.exists());
}
