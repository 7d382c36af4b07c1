//! The `sinew` command end to end: it rigs and poses, and bad input ends in one line on stderr,
//! exit code 2, no panic and no output file (an existing one left as it was).

mod command;
mod common;

use command::{assert_bad_input, s, scratch, sinew};

use std::path::PathBuf;

#[test]
fn rig_then_pose_writes_rig_preview_image_and_vertices() {
    let tmp = scratch("ok");
    let dir = tmp.path();
    let sprite = dir.join("critter.png");
    common::critter(128).save(&sprite).unwrap();
    let (rig, preview, posed, vertices) = (
        dir.join("rig.json"),
        dir.join("preview.png"),
        dir.join("rest.png"),
        dir.join("v.json"),
    );
    let out = sinew(&["rig", s(&sprite), "-o", s(&rig), "--preview", s(&preview)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("critter:"),
        "reports counts"
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&rig).unwrap()).unwrap();
    assert_eq!(doc["parts"][0]["image"], "critter.png");
    assert!(image::open(&preview).is_ok());

    let out = sinew(&["pose", s(&rig), "-o", s(&posed), "--vertices", s(&vertices)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&vertices).unwrap()).unwrap();
    assert_eq!(
        v["parts"][0]["vertices"],
        doc["parts"][0]["mesh"]["vertices"]
    );
    assert_eq!(image::open(&posed).unwrap().width(), 128);
    // Same inputs, byte-identical outputs.
    let rig2 = dir.join("rig2.json");
    assert!(sinew(&["rig", s(&sprite), "-o", s(&rig2)]).status.success());
    assert_eq!(std::fs::read(&rig).unwrap(), std::fs::read(&rig2).unwrap());
}

#[test]
fn bad_images_fail_cleanly_without_output() {
    let tmp = scratch("bad-images");
    let dir = tmp.path();
    let good = dir.join("good.png");
    common::critter(64).save(&good).unwrap();
    let not_png = dir.join("not.png");
    std::fs::write(&not_png, b"this is text").unwrap();
    let bytes = std::fs::read(&good).unwrap();
    let truncated = dir.join("truncated.png");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let empty = dir.join("empty.png");
    image::RgbaImage::new(32, 32).save(&empty).unwrap();
    let tiny = dir.join("tiny.png");
    image::RgbaImage::from_pixel(1, 1, image::Rgba([255, 0, 0, 255]))
        .save(&tiny)
        .unwrap();
    let other_size = dir.join("other.png");
    common::critter(32).save(&other_size).unwrap();
    let out = dir.join("rig.json");

    assert_bad_input(&["rig", s(&not_png), "-o", s(&out)], "not a PNG");
    assert_bad_input(&["rig", s(&truncated), "-o", s(&out)], "cannot decode PNG");
    assert_bad_input(&["rig", s(&empty), "-o", s(&out)], "no pixel with alpha");
    assert_bad_input(&["rig", s(&tiny), "-o", s(&out)], "too small to rig");
    assert_bad_input(
        &["rig", s(&dir.join("missing.png")), "-o", s(&out)],
        "cannot read",
    );
    assert_bad_input(
        &["rig", s(&good), s(&other_size), "-o", s(&out)],
        "share one canvas",
    );
    assert_bad_input(
        &["rig", s(&good), s(&good), "-o", s(&out)],
        "already exists",
    );
    assert_bad_input(
        &["rig", s(&good), "-o", s(&out), "--padding", "NaN"],
        "padding",
    );
    assert!(!out.exists(), "a failed run wrote {}", out.display());

    // A failure leaves an existing output untouched.
    std::fs::write(&out, b"previous").unwrap();
    assert_bad_input(&["rig", s(&empty), "-o", s(&out)], "no pixel with alpha");
    assert_eq!(std::fs::read(&out).unwrap(), b"previous");
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left behind");
}

#[test]
fn bad_rig_documents_fail_cleanly_without_output() {
    let tmp = scratch("bad-rigs");
    let dir = tmp.path();
    let sprite = dir.join("critter.png");
    common::critter(64).save(&sprite).unwrap();
    let rig = dir.join("rig.json");
    assert!(sinew(&["rig", s(&sprite), "-o", s(&rig)]).status.success());
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&rig).unwrap()).unwrap();
    let out = dir.join("out.png");

    let mut wrong_version = doc.clone();
    wrong_version["version"] = 99.into();
    let p = dir.join("v99.json");
    std::fs::write(&p, wrong_version.to_string()).unwrap();
    assert_bad_input(
        &["pose", s(&p), "-o", s(&out)],
        "unsupported rig version 99",
    );

    let mut bad_index = doc.clone();
    bad_index["parts"][0]["mesh"]["triangles"][0][1] = 100000.into();
    let p = dir.join("index.json");
    std::fs::write(&p, bad_index.to_string()).unwrap();
    assert_bad_input(&["pose", s(&p), "-o", s(&out)], "uses vertex 100000");

    let mut missing_image = doc.clone();
    missing_image["parts"][0]["image"] = "nowhere.png".into();
    let p = dir.join("missing-image.json");
    std::fs::write(&p, missing_image.to_string()).unwrap();
    assert_bad_input(&["pose", s(&p), "-o", s(&out)], "nowhere.png");

    let p = dir.join("garbage.json");
    std::fs::write(&p, b"{\"format\": ").unwrap();
    assert_bad_input(&["pose", s(&p), "-o", s(&out)], "not valid JSON");
    assert_bad_input(
        &["pose", s(&dir.join("none.json")), "-o", s(&out)],
        "cannot read",
    );
    assert!(!out.exists());
}

/// Rigs `sprite` with one bone into `rig` and returns the rig document's JSON.
fn one_bone_rig(
    dir: &std::path::Path,
    sprite: &std::path::Path,
    rig: &std::path::Path,
) -> serde_json::Value {
    let handles = dir.join("handles.json");
    std::fs::write(
        &handles,
        r#"{"bones":[{"name":"a","head":[32,45],"tail":[32,20]}]}"#,
    )
    .unwrap();
    let out = sinew(&["rig", s(sprite), "--handles", s(&handles), "-o", s(rig)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(rig).unwrap()).unwrap()
}

#[test]
fn absurd_sizes_and_durations_fail_cleanly_without_output() {
    let tmp = scratch("absurd");
    let dir = tmp.path();
    let sprite = dir.join("critter.png");
    common::critter(64).save(&sprite).unwrap();
    let rig = dir.join("rig.json");
    assert_bad_input(
        &[
            "rig",
            s(&sprite),
            "--max-area-fraction",
            "1e-30",
            "-o",
            s(&rig),
        ],
        "raise max_area_fraction",
    );
    assert!(!rig.exists());

    let mut doc = one_bone_rig(dir, &sprite, &rig);
    // One key at a typo'd time: 1e6 s of animation.
    doc["animations"] = serde_json::json!({"go": {"bones": {"a": {"rotate": [
        {"time": 0, "value": 0}, {"time": 1e6, "value": 30}
    ]}}}});
    let long = dir.join("long.json");
    std::fs::write(&long, doc.to_string()).unwrap();
    let gif = dir.join("out.gif");
    assert_bad_input(
        &["render", s(&long), "--anim", "go", "-o", s(&gif)],
        "frames (duration × frame rate)",
    );
    doc["animations"]["go"]["bones"]["a"]["rotate"][1]["time"] = 1.0.into();
    let short = dir.join("short.json");
    std::fs::write(&short, doc.to_string()).unwrap();
    assert_bad_input(
        &[
            "render",
            s(&short),
            "--anim",
            "go",
            "--scale",
            "1000",
            "-o",
            s(&gif),
        ],
        "px a side",
    );
    assert_bad_input(
        &[
            "render",
            s(&short),
            "--anim",
            "go",
            "--fps",
            "0.001",
            "-o",
            s(&gif),
        ],
        "frame rate",
    );
    assert!(!gif.exists());
    // A second output in a missing folder fails before the first is written.
    let nowhere = dir.join("missing/preview.png");
    let other = dir.join("other.json");
    assert_bad_input(
        &["rig", s(&sprite), "-o", s(&other), "--preview", s(&nowhere)],
        "does not exist",
    );
    assert!(!other.exists());
    let export = dir.join("export");
    assert_bad_input(
        &["export", "spine", s(&long), "-o", s(&export)],
        "duration × bake fps",
    );
}

#[test]
fn argument_errors_are_one_line() {
    assert_bad_input(&["rig"], "required arguments were not provided: --output");
    assert_bad_input(
        &["autorig", "x.png", "--template", "robot", "-o", "x.json"],
        "[possible values: auto, none, humanoid, quadruped]",
    );
    assert_bad_input(
        &["render", "r.json", "--fps", "abc", "-o", "x.gif"],
        "'abc'",
    );
    let help = sinew(&["--help"]);
    assert!(help.status.success());
    assert!(String::from_utf8_lossy(&help.stdout).contains("Usage"));
}

#[test]
fn a_failed_demo_leaves_no_empty_folder() {
    let tmp = scratch("demo-fail");
    let dir = tmp.path();
    let assets = dir.join("assets");
    std::fs::create_dir_all(&assets).unwrap();
    common::critter(64).save(assets.join("body.png")).unwrap();
    std::fs::write(assets.join("layers.json"), r#"{"layers": ["body"]}"#).unwrap();
    std::fs::write(
        assets.join("handles.json"),
        r#"{"bones": [{"name": "a", "parent": "a", "head": [10, 10], "tail": [20, 20]}]}"#,
    )
    .unwrap();
    let out = dir.join("out");
    assert_bad_input(&["demo", "--assets", s(&assets), "-o", s(&out)], "cyclic");
    assert!(!out.exists());
}

#[test]
fn outputs_never_write_over_inputs_and_output_folders_are_made() {
    let tmp = scratch("overwrite");
    let dir = tmp.path();
    let sprite = dir.join("critter.png");
    common::critter(64).save(&sprite).unwrap();
    let sprite_bytes = std::fs::read(&sprite).unwrap();
    let rig = dir.join("critter.json");
    let mut doc = one_bone_rig(dir, &sprite, &rig);
    let handles = dir.join("handles.json");
    doc["animations"] = serde_json::json!({"go": {"bones": {"a": {"rotate": [
        {"time": 0, "value": 0}, {"time": 0.25, "value": 30}
    ]}}}});
    std::fs::write(&rig, doc.to_string()).unwrap();
    let rig_bytes = std::fs::read(&rig).unwrap();
    // Exporting beside the rig would write critter.json over it and critter.png over the sprite.
    assert_bad_input(
        &["export", "spine", s(&rig), "-o", s(dir)],
        "would overwrite an input",
    );
    // A sprite sheet writes its JSON beside it: critter.png -> critter.json, the rig.
    assert_bad_input(
        &["render", s(&rig), "--anim", "go", "-o", s(&sprite)],
        "would overwrite an input",
    );
    assert_eq!(std::fs::read(&rig).unwrap(), rig_bytes);
    assert_eq!(std::fs::read(&sprite).unwrap(), sprite_bytes);
    // Output folders are made where missing.
    let frames = dir.join("new/nested/frames");
    let out = sinew(&["render", s(&rig), "--anim", "go", "-o", s(&frames)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(frames.join("frame_0000.png").is_file());
    // A misspelt option keeps clap's tip on the one line.
    assert_bad_input(&["rig", s(&sprite), "--handle", s(&handles)], "'--handles'");
}

#[test]
fn bad_handles_fail_cleanly_without_output() {
    let tmp = scratch("bad-handles");
    let dir = tmp.path();
    let sprite = dir.join("critter.png");
    common::critter(64).save(&sprite).unwrap();
    let out = dir.join("rig.json");
    let write = |name: &str, json: &str| {
        let p = dir.join(name);
        std::fs::write(&p, json).unwrap();
        p
    };
    let cyclic = write(
        "cyclic.json",
        r#"{"bones": [{"name": "a", "parent": "b", "head": [10, 10], "tail": [20, 20]}, {"name": "b", "parent": "a", "head": [20, 20], "tail": [30, 30]}]}"#,
    );
    assert_bad_input(
        &["rig", s(&sprite), "--handles", s(&cyclic), "-o", s(&out)],
        "cyclic",
    );
    let array = write("array.json", "[]");
    assert_bad_input(
        &["rig", s(&sprite), "--handles", s(&array), "-o", s(&out)],
        "expected a JSON object",
    );
    // An output that names an input is refused before the input is read over.
    assert_bad_input(&["rig", s(&sprite), "-o", s(&sprite)], "would overwrite");
    assert!(image::open(&sprite).is_ok());
    let unknown = write(
        "unknown.json",
        r#"{"bones": [{"name": "a", "parent": "zz", "head": [10, 10], "tail": [20, 20]}]}"#,
    );
    assert_bad_input(
        &["rig", s(&sprite), "--handles", s(&unknown), "-o", s(&out)],
        "unknown parent 'zz'",
    );
    let outside = write(
        "outside.json",
        r#"{"bones": [{"name": "a", "head": [20, 30], "tail": [40, 30]}], "points": [{"name": "far", "at": [500, 500]}]}"#,
    );
    assert_bad_input(
        &["rig", s(&sprite), "--handles", s(&outside), "-o", s(&out)],
        "'far' lies outside every part",
    );
    let nan = write(
        "nan.json",
        r#"{"points": [{"name": "p", "at": [1e999, 3]}]}"#,
    );
    assert_bad_input(
        &["rig", s(&sprite), "--handles", s(&nan), "-o", s(&out)],
        "nan.json",
    );
    let typo = write("typo.json", r#"{"bone": []}"#);
    assert_bad_input(
        &["rig", s(&sprite), "--handles", s(&typo), "-o", s(&out)],
        "typo.json",
    );
    assert!(!out.exists());

    let good = write(
        "good.json",
        r#"{"bones": [{"name": "a", "head": [20, 30], "tail": [40, 30]}]}"#,
    );
    assert!(
        sinew(&["rig", s(&sprite), "--handles", s(&good), "-o", s(&out)])
            .status
            .success()
    );
    let pose = write("pose.json", r#"{"bones": {"nope": {"rotate": 10}}}"#);
    let png = dir.join("posed.png");
    assert_bad_input(
        &["pose", s(&out), "--pose", s(&pose), "-o", s(&png)],
        "bone 'nope'",
    );
    let ik = write("ik.json", r#"{"ik": [{"at": [30, 30], "to": [35, f]}]}"#);
    assert_bad_input(
        &["pose", s(&out), "--pose", s(&ik), "-o", s(&png)],
        "ik.json",
    );
    let outside = write(
        "outside.json",
        r#"{"ik": [{"at": [1, 1], "to": [35, 30]}]}"#,
    );
    assert_bad_input(
        &["pose", s(&out), "--pose", s(&outside), "-o", s(&png)],
        "does not grip the drawing",
    );
    assert!(!png.exists());
}

#[test]
fn demo_writes_rig_animations_gifs_and_sheets_and_render_and_pose_play_them() {
    let tmp = scratch("demo");
    let dir = tmp.path();
    let out = sinew(&["demo", "-o", s(dir)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for name in [
        "character.json",
        "rest.png",
        "rest_pail.png",
        "walk.gif",
        "walk.png",
        "walk.json",
        "wave.gif",
    ] {
        assert!(
            dir.join(name).is_file(),
            "demo did not write {name}: {stdout}"
        );
    }
    // The walk lasts 1 s: 24 frames at the demo's 24 fps, in the GIF, the sheet and the folder.
    let gif = std::fs::File::open(dir.join("walk.gif")).unwrap();
    let mut decoder = gif::DecodeOptions::new().read_info(gif).unwrap();
    let mut frames = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        frames += 1;
    }
    assert_eq!(frames, 24);
    let sheet: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("walk.json")).unwrap()).unwrap();
    assert_eq!(sheet["frames"].as_object().unwrap().len(), 24);
    assert_eq!(std::fs::read_dir(dir.join("walk")).unwrap().count(), 24);

    // The rig document carries the animations: render and pose play them.
    let rig = dir.join("character.json");
    let gif_out = dir.join("again.gif");
    let out = sinew(&[
        "render",
        s(&rig),
        "--anim",
        "wave",
        "--fps",
        "8",
        "-o",
        s(&gif_out),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(gif_out.is_file());
    let frame = dir.join("walk_quarter.png");
    let out = sinew(&[
        "pose",
        s(&rig),
        "--anim",
        "walk",
        "--time",
        "0.25",
        "-o",
        s(&frame),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rest = image::open(dir.join("rest.png")).unwrap().to_rgba8();
    let posed = image::open(&frame).unwrap().to_rgba8();
    assert_eq!(rest.dimensions(), posed.dimensions());
    assert_ne!(
        rest.as_raw(),
        posed.as_raw(),
        "a walk frame must differ from rest"
    );

    // A pose with skinning-IK drags: the pinned feet stay, the dragged hand arrives.
    let lift = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/character/poses/lift.json");
    let vertices = dir.join("lift_vertices.json");
    let out = sinew(&[
        "pose",
        s(&rig),
        "--pose",
        s(&lift),
        "--vertices",
        s(&vertices),
        "-o",
        s(&dir.join("lift.png")),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.join("lift.png").is_file() && vertices.is_file());
    let bad_drag = dir.join("bad_drag.json");
    std::fs::write(&bad_drag, r#"{"ik": [{"at": [2, 2], "to": [50, 50]}]}"#).unwrap();
    assert_bad_input(
        &[
            "pose",
            s(&rig),
            "--pose",
            s(&bad_drag),
            "-o",
            s(&dir.join("no.png")),
        ],
        "does not grip the drawing",
    );
    assert!(!dir.join("no.png").exists());

    // Bad requests: one line, exit 2, nothing written.
    assert_bad_input(
        &[
            "render",
            s(&rig),
            "--anim",
            "moonwalk",
            "-o",
            s(&dir.join("x.gif")),
        ],
        "no animation 'moonwalk'",
    );
    assert_bad_input(
        &[
            "render",
            s(&rig),
            "--anim",
            "walk",
            "--fps",
            "0",
            "-o",
            s(&dir.join("y.gif")),
        ],
        "frame rate",
    );
    assert_bad_input(
        &[
            "render",
            s(&rig),
            "--anim",
            "walk",
            "-o",
            s(&dir.join("z.txt")),
        ],
        "z.txt",
    );
    assert_bad_input(
        &[
            "render",
            s(&rig),
            "--anim",
            "walk",
            "--background",
            "#zzz",
            "-o",
            s(&dir.join("w.gif")),
        ],
        "zzz",
    );
    for name in ["x.gif", "y.gif", "z.txt", "w.gif"] {
        assert!(!dir.join(name).exists(), "{name} was written");
    }
}
