//! `sinew export spine` on bad input: one line on stderr, exit code 2, no panic, and nothing
//! new (or half-written) in the output folder. The runtime checks of good exports are in
//! tests/spine_runtime.rs.

mod command;

use command::{assert_bad_input, s, scratch, sinew};
use std::path::{Path, PathBuf};

/// A 64×64 layer with an opaque rectangle, saved as `dir/name.png`.
fn layer(dir: &Path, name: &str) -> PathBuf {
    let mut image = image::RgbaImage::new(64, 64);
    for y in 12..52 {
        for x in 8..56 {
            image.put_pixel(x, y, image::Rgba([200, 100, 50, 255]));
        }
    }
    let path = dir.join(format!("{name}.png"));
    image.save(&path).unwrap();
    path
}

/// Rigs `layers` with one bone (and `extra` handles JSON fields), and returns the rig path.
fn rig(dir: &Path, layers: &[PathBuf], extra: serde_json::Value) -> PathBuf {
    let mut handles = serde_json::json!({
        "bones": [{"name": "b", "head": [16, 32], "tail": [48, 32]}]
    });
    if let (Some(h), Some(e)) = (handles.as_object_mut(), extra.as_object()) {
        h.extend(e.clone());
    }
    let handles_path = dir.join("h.json");
    std::fs::write(&handles_path, handles.to_string()).unwrap();
    let rig = dir.join("rig.json");
    let mut args: Vec<&str> = vec!["rig"];
    args.extend(layers.iter().map(|p| s(p)));
    args.extend(["--handles", s(&handles_path), "-o", s(&rig)]);
    let out = sinew(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    rig
}

/// Runs an export that must fail, checks how, and that `out` holds exactly what it held.
fn assert_refused(args: &[&str], out: &Path, expect_in_message: &str) {
    let before: Vec<_> = std::fs::read_dir(out)
        .map(|d| d.map(|e| e.unwrap().file_name()).collect())
        .unwrap_or_default();
    assert_bad_input(args, expect_in_message);
    let after: Vec<_> = std::fs::read_dir(out)
        .map(|d| d.map(|e| e.unwrap().file_name()).collect())
        .unwrap_or_default();
    assert_eq!(before, after, "{args:?} changed {}", out.display());
}

#[test]
fn bad_rigs_and_flags_are_refused_without_touching_the_output_folder() {
    let tmp = scratch("rigs");
    let dir = tmp.path();
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("keep.txt"), "an earlier file").unwrap();

    // No weights: rigged without handles.
    let plain = dir.join("plain.json");
    let body = layer(dir, "body");
    assert!(sinew(&["rig", s(&body), "-o", s(&plain)]).status.success());
    assert_refused(
        &["export", "spine", s(&plain), "-o", s(&out)],
        &out,
        "has no weights",
    );

    // A part name the atlas format cannot hold.
    let named_tmp = scratch("names");
    let named = named_tmp.path();
    let colon = layer(named, "arm:left");
    let rig_colon = rig(named, &[colon], serde_json::json!({}));
    assert_refused(
        &["export", "spine", s(&rig_colon), "-o", s(&out)],
        &out,
        "cannot be used in Spine",
    );

    // A handle named like the export's root bone.
    let rooted_tmp = scratch("root");
    let rooted = rooted_tmp.path();
    let body_r = layer(rooted, "body");
    let rig_root = rig(
        rooted,
        &[body_r],
        serde_json::json!({"points": [{"name": "root", "at": [30, 30]}]}),
    );
    assert_refused(
        &["export", "spine", s(&rig_root), "-o", s(&out)],
        &out,
        "'root'",
    );

    // A part whose image is missing.
    let good_tmp = scratch("good");
    let good = good_tmp.path();
    let arm = layer(good, "arm");
    let rig_good = rig(good, std::slice::from_ref(&arm), serde_json::json!({}));
    std::fs::rename(&arm, good.join("moved.png")).unwrap();
    assert_refused(
        &["export", "spine", s(&rig_good), "-o", s(&out)],
        &out,
        "arm.png",
    );
    std::fs::rename(good.join("moved.png"), &arm).unwrap();

    // Flags.
    for (flags, message) in [
        (vec!["--spine-version", "4.4"], "not supported"),
        (vec!["--fps", "0"], "bake rate"),
        (vec!["--max-influences", "0"], "at least 1"),
        (vec!["--max-vertices", "2"], "at least 3"),
    ] {
        let mut args = vec!["export", "spine", s(&rig_good), "-o", s(&out)];
        args.extend(flags);
        assert_refused(&args, &out, message);
    }

    // An IK drag that grips nothing: the pose path's error surfaces.
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&rig_good).unwrap()).unwrap();
    doc["animations"] = serde_json::json!({"drag": {"ik": [
        {"at": [-50, -50], "to": [{"time": 0, "value": [-50, -50]}, {"time": 1, "value": [40, 20]}]}]}});
    let rig_ik = good.join("ik.json");
    std::fs::write(&rig_ik, doc.to_string()).unwrap();
    assert_refused(
        &["export", "spine", s(&rig_ik), "-o", s(&out)],
        &out,
        "does not grip the drawing",
    );

    // Bone IK constraints export as Spine IK constraints, under names Spine can use.
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&rig_good).unwrap()).unwrap();
    doc["handles"]["bones"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"name": "goal", "head": [40, 20], "tail": [44, 20]}));
    doc["handles"]["ik"] =
        serde_json::json!([{"name": "aim\nleft", "bones": ["b"], "target": "goal"}]);
    let rig_constrained = good.join("constrained.json");
    std::fs::write(&rig_constrained, doc.to_string()).unwrap();
    assert_refused(
        &["export", "spine", s(&rig_constrained), "-o", s(&out)],
        &out,
        "IK constraint name \"aim\\nleft\" cannot be used in Spine",
    );

    // An output path that is a file.
    let file = dir.join("file.txt");
    std::fs::write(&file, "x").unwrap();
    assert_refused(
        &["export", "spine", s(&rig_good), "-o", s(&file)],
        &out,
        "file.txt",
    );

    // And the good rig exports: JSON, atlas, page; the earlier file is still there.
    let result = sinew(&["export", "spine", s(&rig_good), "-o", s(&out)]);
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["keep.txt", "rig.atlas", "rig.json", "rig.png"]);
}
