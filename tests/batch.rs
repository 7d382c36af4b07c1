//! `sinew batch` end to end on this machine: a manifest of colorize jobs over generated line
//! art (`sinew::colorize::synthetic`), rigs of generated sprites and of the bundled character,
//! a render and an export of the character; outputs byte-identical to the commands';
//! incremental reruns; a failing job that does not stop the others; bad manifests refused in
//! one line before any work. The same batch on a Ray cluster: `tools/ray/run.sh`.

mod command;

use command::{assert_bad_input, s, scratch, sinew};
use serde_json::{json, Value};
use sinew::colorize::synthetic::{scene, SceneSpec};
use sinew::io::save_png;
use std::path::{Path, PathBuf};

const CHARACTER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/character");

/// Copies the bundled character's layers, handles and layer list into `dir/character/`: a
/// manifest names only files inside its folder.
fn character_in(dir: &Path) {
    let to = dir.join("character");
    std::fs::create_dir_all(&to).unwrap();
    for entry in std::fs::read_dir(CHARACTER).unwrap() {
        let path = entry.unwrap().path();
        if path.is_file() {
            std::fs::copy(&path, to.join(path.file_name().unwrap())).unwrap();
        }
    }
}

/// Writes `count` generated line drawings with their scribbles into `dir/in/`.
fn line_art(dir: &Path, count: usize) {
    std::fs::create_dir_all(dir.join("in")).unwrap();
    for k in 0..count {
        let sc = scene(&SceneSpec {
            size: 48 + 8 * k as u32,
            ..Default::default()
        });
        save_png(&dir.join(format!("in/art{k}.png")), &sc.lineart).unwrap();
        let strokes = json!({ "strokes": sc.strokes });
        std::fs::write(dir.join(format!("in/art{k}.json")), strokes.to_string()).unwrap();
    }
}

fn colorize_job(k: usize) -> Value {
    json!({
        "kind": "colorize", "name": format!("colorize-{k}"),
        "inputs": {"lineart": format!("in/art{k}.png"), "scribbles": format!("in/art{k}.json")},
        "options": {"fill": if k.is_multiple_of(2) { "flat" } else { "soft" }},
        "outputs": {"image": format!("out/art{k}.png")}
    })
}

fn write_manifest(dir: &Path, jobs: &[Value]) -> PathBuf {
    let path = dir.join("batch.json");
    std::fs::write(&path, json!({ "jobs": jobs }).to_string()).unwrap();
    path
}

/// Runs the batch; returns (exit code, report).
fn batch(manifest: &Path, extra: &[&str]) -> (Option<i32>, Value) {
    let mut args = vec!["batch", s(manifest)];
    args.extend_from_slice(extra);
    let out = sinew(&args);
    let report = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("no report ({e}): {}", String::from_utf8_lossy(&out.stderr)));
    (out.status.code(), report)
}

fn statuses(report: &Value) -> Vec<(String, String)> {
    report["jobs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| {
            (
                j["name"].as_str().unwrap().to_string(),
                j["status"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

#[test]
fn a_batch_writes_what_the_commands_write_and_reruns_only_what_changed() {
    let tmp = scratch("incremental");
    let dir = tmp.path();
    line_art(dir, 3);
    character_in(dir);
    let character: Vec<String> = ["torso", "head", "tail"]
        .iter()
        .map(|n| format!("character/{n}.png"))
        .collect();
    let mut jobs: Vec<Value> = (0..3).map(colorize_job).collect();
    jobs.push(json!({
        "kind": "rig", "name": "parts",
        "inputs": {"images": character},
        "options": {"build": {"mesh": {"min_angle_deg": 25.0}}},
        "outputs": {"rig": "out/rig/parts.json", "preview": "out/rig/mesh.png"}
    }));
    let manifest = write_manifest(dir, &jobs);
    let (code, report) = batch(&manifest, &["--jobs", "2"]);
    assert_eq!(code, Some(0), "{report}");
    assert!(statuses(&report).iter().all(|(_, st)| st == "done"));
    assert_eq!(report["done"], 4);

    // The same bytes as the commands.
    let cli = dir.join("cli");
    std::fs::create_dir_all(&cli).unwrap();
    let art = dir.join("in/art1.png");
    let strokes = dir.join("in/art1.json");
    let out = cli.join("art1.png");
    let run = sinew(&[
        "colorize",
        s(&art),
        "--scribbles",
        s(&strokes),
        "-o",
        s(&out),
        "--fill",
        "soft",
    ]);
    assert!(run.status.success());
    assert!(std::fs::read(&out).unwrap() == std::fs::read(dir.join("out/art1.png")).unwrap());
    // The rig names its images relative to its own folder: as deep as the batch's.
    std::fs::create_dir_all(cli.join("rig")).unwrap();
    let rig = cli.join("rig/parts.json");
    let images: Vec<PathBuf> = jobs[3]["inputs"]["images"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| dir.join(v.as_str().unwrap()))
        .collect();
    let mut args = vec!["rig"];
    args.extend(images.iter().map(|p| s(p)));
    args.extend(["-o", s(&rig), "--min-angle", "25"]);
    let run = sinew(&args);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(std::fs::read(&rig).unwrap() == std::fs::read(dir.join("out/rig/parts.json")).unwrap());

    // Nothing changed: everything is skipped.
    let (code, report) = batch(&manifest, &[]);
    assert_eq!(code, Some(0));
    assert_eq!(report["skipped"], 4, "{report}");

    // A changed input, a changed option, a deleted output: those three run again.
    std::fs::copy(dir.join("in/art2.json"), dir.join("in/art0.json")).unwrap();
    jobs[1]["options"]["scale"] = json!(500.0);
    std::fs::remove_file(dir.join("out/rig/mesh.png")).unwrap();
    let manifest = write_manifest(dir, &jobs);
    let (code, report) = batch(&manifest, &[]);
    assert_eq!(code, Some(0));
    let ran: Vec<String> = statuses(&report)
        .into_iter()
        .filter(|(_, st)| st == "done")
        .map(|(n, _)| n)
        .collect();
    assert_eq!(ran, ["colorize-0", "colorize-1", "parts"], "{report}");
    assert!(dir.join("out/rig/mesh.png").is_file());
}

#[test]
fn a_failing_job_fails_its_readers_but_not_the_others() {
    let tmp = scratch("failing");
    let dir = tmp.path();
    line_art(dir, 2);
    // Scribbles that are not a scribble file: that job fails when it runs.
    std::fs::write(dir.join("in/art1.json"), "{\"strokes\": 3}").unwrap();
    let mut jobs = vec![colorize_job(0), colorize_job(1)];
    // A rig of the colorized image (an opaque picture: one part) reads what colorize-1 writes.
    jobs.push(json!({
        "kind": "rig", "name": "reader",
        "inputs": {"images": ["out/art1.png"]},
        "outputs": {"rig": "out/reader.json"}
    }));
    let manifest = write_manifest(dir, &jobs);
    let (code, report) = batch(&manifest, &[]);
    assert_eq!(code, Some(2), "{report}");
    assert_eq!(
        statuses(&report),
        [
            ("colorize-0".into(), "done".into()),
            ("colorize-1".into(), "failed".into()),
            ("reader".into(), "failed".into())
        ]
    );
    let errors: Vec<&str> = report["jobs"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|j| j["error"].as_str())
        .collect();
    assert!(errors[0].contains("art1.json"), "{errors:?}");
    assert!(errors[1].contains("colorize-1"), "{errors:?}");
    assert!(errors.iter().all(|e| !e.contains('\n')));
    assert!(dir.join("out/art0.png").is_file());
    assert!(!dir.join("out/art1.png").exists());
    // Fixed, the rerun does only what is left.
    line_art(dir, 2);
    let (code, report) = batch(&manifest, &[]);
    assert_eq!(code, Some(0), "{report}");
    assert_eq!(
        statuses(&report),
        [
            ("colorize-0".into(), "skipped".into()),
            ("colorize-1".into(), "done".into()),
            ("reader".into(), "done".into())
        ]
    );
}

#[test]
fn the_character_rigs_renders_and_exports_in_one_batch() {
    let tmp = scratch("character");
    let dir = tmp.path();
    let list: Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{CHARACTER}/layers.json")).unwrap())
            .unwrap();
    let images: Vec<String> = list["layers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| format!("character/{}.png", n.as_str().unwrap()))
        .collect();
    character_in(dir);
    // A rig from the demo (which adds the animations), rendered and exported by the batch.
    let demo = dir.join("demo");
    let run = sinew(&["demo", "-o", s(&demo)]);
    assert!(run.status.success());
    let jobs = vec![
        json!({"kind": "rig", "name": "rig", "inputs": {"images": images,
               "handles": "character/handles.json"},
               "outputs": {"rig": "out/rig.json"}}),
        json!({"kind": "export", "name": "export", "inputs": {"rig": "out/rig.json"},
               "outputs": {"folder": "out/spine"}}),
        json!({"kind": "render", "name": "walk", "inputs": {"rig": "demo/character.json"},
               "options": {"animation": "walk", "fps": 6, "scale": 0.25},
               "outputs": {"output": "out/walk.gif"}}),
    ];
    let manifest = write_manifest(dir, &jobs);
    let (code, report) = batch(&manifest, &[]);
    assert_eq!(code, Some(0), "{report}");
    assert!(dir.join("out/spine/rig.json").is_file());
    // The render is the command's, byte for byte.
    let gif = dir.join("walk.gif");
    let run = sinew(&[
        "render",
        s(&demo.join("character.json")),
        "--anim",
        "walk",
        "--fps",
        "6",
        "--scale",
        "0.25",
        "-o",
        s(&gif),
    ]);
    assert!(run.status.success());
    assert!(std::fs::read(&gif).unwrap() == std::fs::read(dir.join("out/walk.gif")).unwrap());
}

/// Runs `sinew colorize` on `dir/in/NAME.png` and `.json` with `flags`; returns the image's
/// bytes.
fn colorize_command(dir: &Path, name: &str, flags: &[&str]) -> Vec<u8> {
    let out = dir.join(format!("cli-{name}-{}.png", flags.join("")));
    let art = dir.join(format!("in/{name}.png"));
    let strokes = dir.join(format!("in/{name}.json"));
    let mut args = vec![
        "colorize",
        s(&art),
        "--scribbles",
        s(&strokes),
        "-o",
        s(&out),
    ];
    args.extend_from_slice(flags);
    let run = sinew(&args);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    std::fs::read(&out).unwrap()
}

#[test]
fn a_colorize_job_splits_regions_as_the_command_does() {
    // Two background colors with no line between them: the split decides where they meet.
    let tmp = scratch("split");
    let dir = tmp.path();
    std::fs::create_dir_all(dir.join("in")).unwrap();
    let sc = scene(&SceneSpec {
        size: 96,
        split_background: true,
        ..Default::default()
    });
    save_png(&dir.join("in/undrawn.png"), &sc.lineart).unwrap();
    let strokes = json!({ "strokes": sc.strokes });
    std::fs::write(dir.join("in/undrawn.json"), strokes.to_string()).unwrap();
    let job = |name: &str, options: Value| {
        json!({
            "kind": "colorize", "name": name,
            "inputs": {"lineart": "in/undrawn.png", "scribbles": "in/undrawn.json"},
            "options": options,
            "outputs": {"image": format!("out/{name}.png")}
        })
    };
    let jobs = [
        job("default", json!({})),
        job("depth", json!({"split": "depth"})),
        job("deep", json!({"split": "depth", "split_depth_px": 4})),
        job("density", json!({"split": "density", "split_blur_px": 3})),
        job("alpha", json!({"split_depth_exponent": 1})),
    ];
    let manifest = write_manifest(dir, &jobs);
    let (code, report) = batch(&manifest, &[]);
    assert_eq!(code, Some(0), "{report}");
    let written = |name: &str| std::fs::read(dir.join(format!("out/{name}.png"))).unwrap();
    for (name, flags) in [
        ("default", vec![]),
        ("depth", vec!["--split", "depth"]),
        ("deep", vec!["--split", "depth", "--split-depth", "4"]),
        ("density", vec!["--split", "density", "--split-blur", "3"]),
        ("alpha", vec!["--split-exponent", "1"]),
    ] {
        assert!(
            written(name) == colorize_command(dir, "undrawn", &flags),
            "job '{name}' differs from sinew colorize {flags:?}"
        );
    }
    // The split matters on this scene: each option changed the image.
    let default = written("default");
    for name in ["depth", "density", "alpha"] {
        assert!(written(name) != default, "'{name}' is the default's image");
    }
    assert!(
        written("deep") != written("depth"),
        "split_depth_px ignored"
    );
}

/// A bad manifest: one line, exit 2, and no job ran (no output, no state).
fn assert_refused(name: &str, jobs: &[Value], expect: &str) {
    let tmp = scratch(name);
    let dir = tmp.path();
    line_art(dir, 2);
    let manifest = write_manifest(dir, jobs);
    assert_bad_input(&["batch", s(&manifest)], expect);
    assert!(!dir.join("out").exists(), "{name}: a job ran");
    assert!(!dir.join("batch.state.json").exists());
}

/// `job` with the field at `path` (keys from the job's top) set to `value`.
fn with_field(mut job: Value, path: &[&str], value: Value) -> Value {
    let mut field = &mut job;
    for key in path {
        field = &mut field[*key];
    }
    *field = value;
    job
}

#[test]
fn bad_manifests_are_refused_before_any_work() {
    // (case, k, field, value, message): colorize_job(k) with one field set, after the jobs
    // before it (colorize-0 .. colorize-k-1) as they are.
    let cases = [
        (
            "missing",
            1,
            &["inputs", "lineart"][..],
            json!("in/nothing.png"),
            "in/nothing.png: the input does not exist and no job writes it",
        ),
        (
            "twice",
            1,
            &["outputs", "image"],
            json!("out/art0.png"),
            "jobs 'colorize-0' and 'colorize-1' both write it",
        ),
        // An output folder holding another job's output is one output written twice too.
        (
            "inside",
            1,
            &["outputs", "layers"],
            json!("out"),
            "both write it",
        ),
        (
            "unknown",
            1,
            &["kind"],
            json!("bake"),
            "job 1 ('colorize-1'): unknown kind 'bake' (known: rig, autorig, render, export, colorize)",
        ),
        (
            "own",
            0,
            &["outputs", "image"],
            json!("in/art0.png"),
            "the output would overwrite an input",
        ),
        (
            "manifest",
            0,
            &["outputs", "image"],
            json!("batch.json"),
            "the output would overwrite the manifest or its state",
        ),
        (
            "option",
            0,
            &["options", "fil"],
            json!("flat"),
            "unknown field `fil`",
        ),
        (
            "split",
            0,
            &["options", "split"],
            json!("deep"),
            "job 0 ('colorize-0'): unknown variant `deep`, expected one of `reach`, `density`, `depth`, `weights`",
        ),
        (
            "alpha",
            0,
            &["options", "split_depth_exponent"],
            json!(99),
            "job 'colorize-0': invalid colorize option: split_depth_exponent must lie in [0, 32], not 99",
        ),
    ];
    for (name, k, field, value, expect) in cases {
        let mut jobs: Vec<Value> = (0..k).map(colorize_job).collect();
        jobs.push(with_field(colorize_job(k), field, value));
        assert_refused(name, &jobs, expect);
    }

    // a writes what b reads, b writes what a reads.
    let mut a = colorize_job(0);
    a["inputs"]["lineart"] = json!("out/b.png");
    a["outputs"]["image"] = json!("out/a.png");
    let mut b = colorize_job(1);
    b["inputs"]["lineart"] = json!("out/a.png");
    b["outputs"]["image"] = json!("out/b.png");
    assert_refused("cycle", &[a, b], "form a cycle");
    assert_refused(
        "names",
        &[colorize_job(0), colorize_job(0)],
        "two jobs have this name",
    );
}

#[test]
fn the_manifest_schema_is_printed() {
    let out = sinew(&["schema", "batch"]);
    assert!(out.status.success());
    let schema: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(schema.to_string().contains("colorize"));
}
