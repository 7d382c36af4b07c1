//! The JSON Schemas of `sinew schema` against real files: every bundled file, a rig the library
//! writes (and, with the binary, one `sinew rig` writes), generated scribbles and the examples of
//! `docs/formats.md` validate, and each of those examples also loads with sinew's own reader;
//! wrong files are rejected by the schema and by the reader alike.

// Scratch folders always; the `sinew` runs with the binary (feature `cli`).
mod command;
mod common;

use serde_json::{json, Value};
use sinew::anim;
use sinew::colorize::synthetic::{scene, SceneSpec};
use sinew::colorize::{ScribbleOptions, Scribbles};
use sinew::io::{BuildOptions, RigDocument};
use sinew::pipeline::{self, Layer};
use sinew::rig::{Bone, Handles, Pose};
use sinew::schema::{schema, SchemaKind};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: cannot read: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: not JSON: {e}", path.display()))
}

fn validator(kind: SchemaKind) -> jsonschema::Validator {
    let schema = serde_json::to_value(schema(kind)).expect("a schema is JSON");
    jsonschema::validator_for(&schema)
        .unwrap_or_else(|e| panic!("the {} schema is not a valid schema: {e}", kind.name()))
}

/// Every schema error of `instance`, one per line (empty when it is valid).
fn errors(kind: SchemaKind, instance: &Value) -> String {
    validator(kind)
        .iter_errors(instance)
        .map(|e| format!("{} at {}", e, e.instance_path()))
        .collect::<Vec<_>>()
        .join("\n")
}

fn assert_valid(kind: SchemaKind, instance: &Value, what: &str) {
    let errors = errors(kind, instance);
    assert!(
        errors.is_empty(),
        "{what} does not match the {} schema:\n{errors}",
        kind.name()
    );
}

fn assert_invalid(kind: SchemaKind, instance: &Value, what: &str) {
    assert!(
        !validator(kind).is_valid(instance),
        "the {} schema accepts {what}: {instance}",
        kind.name()
    );
}

#[test]
fn the_bundled_files_validate() {
    let assets = root().join("assets/character");
    assert_valid(
        SchemaKind::Handles,
        &read_json(&assets.join("handles.json")),
        "assets/character/handles.json",
    );
    assert_valid(
        SchemaKind::Animations,
        &read_json(&assets.join("animations.json")),
        "assets/character/animations.json",
    );
    assert_valid(
        SchemaKind::Events,
        &read_json(&assets.join("events.json")),
        "assets/character/events.json",
    );
    let mut poses = 0;
    for entry in std::fs::read_dir(assets.join("poses")).expect("the poses folder") {
        let path = entry.expect("a folder entry").path();
        if path.extension().is_some_and(|e| e == "json") {
            assert_valid(
                SchemaKind::Pose,
                &read_json(&path),
                &path.display().to_string(),
            );
            poses += 1;
        }
    }
    assert!(poses >= 3, "only {poses} bundled poses");
}

/// A small rig as the library writes it: a generated sprite, two bones, weights, the options,
/// an animation and a locked handle.
#[test]
fn a_written_rig_validates() {
    let tmp = command::scratch("rig");
    let dir = tmp.path();
    let path = dir.join("critter.png");
    let image = common::critter(96);
    image.save(&path).unwrap();
    let layer = Layer::whole("critter", path, image);
    let bone = |name: &str, parent: Option<&str>, head: [f64; 2], tail: [f64; 2]| Bone {
        name: name.into(),
        parent: parent.map(Into::into),
        head: head.into(),
        tail: tail.into(),
    };
    let handles = Handles {
        bones: vec![
            bone("body", None, [48.0, 70.0], [48.0, 40.0]),
            bone("head", Some("body"), [48.0, 40.0], [48.0, 15.0]),
        ],
        ..Handles::default()
    };
    let (mut doc, _) =
        pipeline::build_rig(&[layer], dir, &BuildOptions::default(), &handles).expect("rigs");
    doc.animations.insert(
        "nod".into(),
        anim::Animation::from_json(
            "nod",
            &json!({"bones": {"head": {"rotate": [
                {"time": 0, "value": 0, "curve": [0.1, 0, 0.2, 10]},
                {"time": 0.5, "value": 10}
            ]}}}),
        )
        .expect("an animation"),
    );
    doc.locked = vec!["body".into()];
    let rig = dir.join("rig.json");
    doc.save(&rig).expect("saves");
    let written = read_json(&rig);
    assert!(written["parts"][0]["weights"]["rows"].is_array());
    assert!(written["options"]["ik"].is_object());
    assert_valid(SchemaKind::Rig, &written, "a rig the library wrote");
}

#[test]
fn generated_scribbles_validate() {
    let sc = scene(&SceneSpec {
        size: 64,
        ..Default::default()
    });
    let file = json!({ "strokes": sc.strokes });
    assert_valid(SchemaKind::Scribbles, &file, "generated scribbles");
    Scribbles::from_json(&file.to_string(), 64, 64, &ScribbleOptions::default())
        .expect("the reader takes them too");
}

/// The fenced blocks of `docs/formats.md` whose info string is `json KIND`.
fn documented_examples() -> Vec<(SchemaKind, String)> {
    let text = std::fs::read_to_string(root().join("docs/formats.md")).expect("docs/formats.md");
    let mut examples = Vec::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        let Some(kind) = line.strip_prefix("```json ") else {
            continue;
        };
        let kind: SchemaKind = kind
            .trim()
            .parse()
            .unwrap_or_else(|e| panic!("docs/formats.md: {e}"));
        let body: Vec<&str> = lines.by_ref().take_while(|l| *l != "```").collect();
        examples.push((kind, body.join("\n")));
    }
    examples
}

/// Loads `text` with sinew's own reader for `kind`.
fn load(kind: SchemaKind, text: &str) -> Result<(), String> {
    let value: Value = serde_json::from_str(text).map_err(|e| e.to_string())?;
    match kind {
        SchemaKind::Handles => serde_json::from_value::<Handles>(value)
            .map_err(|e| e.to_string())?
            .validate()
            .map_err(|e| e.to_string()),
        SchemaKind::Rig => {
            let doc = RigDocument::from_json(text, Path::new("example.json"))
                .map_err(|e| e.to_string())?;
            doc.check_animations().map_err(|e| e.to_string())
        }
        SchemaKind::Pose => serde_json::from_value::<Pose>(value)
            .map(|_| ())
            .map_err(|e| e.to_string()),
        SchemaKind::Animations => {
            let map: BTreeMap<String, Value> =
                serde_json::from_value(value).map_err(|e| e.to_string())?;
            anim::parse_animations(&map)
                .map(|_| ())
                .map_err(|e| e.to_string())
        }
        SchemaKind::Scribbles => Scribbles::from_json(text, 512, 512, &ScribbleOptions::default())
            .map(|_| ())
            .map_err(|e| e.to_string()),
        SchemaKind::Events => anim::events_from_json(&value)
            .map(|_| ())
            .map_err(|e| e.to_string()),
        // The manifest's own checks (inputs exist, no cycle) need its files: the parse only.
        SchemaKind::Batch => sinew::batch::manifest::parse(text)
            .map(|_| ())
            .map_err(|e| e.to_string()),
    }
}

#[test]
fn the_documented_examples_validate_and_load() {
    let examples = documented_examples();
    for kind in SchemaKind::ALL {
        assert!(
            examples.iter().any(|(k, _)| *k == kind),
            "docs/formats.md has no `json {}` example",
            kind.name()
        );
    }
    for (kind, text) in &examples {
        let value: Value = serde_json::from_str(text)
            .unwrap_or_else(|e| panic!("the {} example is not JSON: {e}", kind.name()));
        assert_valid(
            *kind,
            &value,
            &format!("the documented {} example", kind.name()),
        );
        load(*kind, text).unwrap_or_else(|e| {
            panic!("sinew refuses the documented {} example: {e}", kind.name())
        });
    }
}

#[test]
fn wrong_files_are_rejected_by_the_schema_and_the_reader() {
    let handles = json!({"bones": [{"name": "hip", "head": [0, 0], "tail": [0, 10]}]});
    assert_valid(SchemaKind::Handles, &handles, "one bone");
    let rig = json!({
        "format": "sinew-rig", "version": 1, "canvas": [8, 8],
        "parts": [{"name": "a", "image": "a.png",
                   "mesh": {"vertices": [[0, 0], [8, 0], [0, 8]], "triangles": [[0, 1, 2]]}}]
    });
    assert_valid(SchemaKind::Rig, &rig, "a one-triangle rig");
    let with = |base: &Value, pointer: &str, value: Value| {
        let mut changed = base.clone();
        *changed.pointer_mut(pointer).expect("a field to change") = value;
        changed
    };
    let wrong: Vec<(SchemaKind, Value, &str)> = vec![
        (
            SchemaKind::Handles,
            json!({"bones": [{"name": "hip", "head": [0, 0]}]}),
            "a bone without a tail",
        ),
        (
            SchemaKind::Handles,
            json!({"bonez": []}),
            "an unknown field",
        ),
        (
            SchemaKind::Handles,
            with(&handles, "/bones/0/head", json!([0, 0, 0])),
            "a point of three coordinates",
        ),
        (
            SchemaKind::Rig,
            with(&rig, "/format", json!("spine")),
            "another format",
        ),
        (
            SchemaKind::Rig,
            with(&rig, "/version", json!(2)),
            "another version",
        ),
        (
            SchemaKind::Rig,
            with(&rig, "/parts/0/mesh/triangles/0", json!([0, 1])),
            "a triangle of two corners",
        ),
        (
            SchemaKind::Rig,
            with(&rig, "/canvas", json!([8, -8])),
            "a negative canvas side",
        ),
        (
            SchemaKind::Pose,
            json!({"bones": {"hip": {"rotate": "20"}}}),
            "an angle as a string",
        ),
        (
            SchemaKind::Pose,
            json!({"ik": [{"at": [0, 0]}]}),
            "a drag without its target",
        ),
        (
            SchemaKind::Animations,
            json!({"wave": {"bones": {"hip": {"rotate": [
                {"time": 0, "value": 0, "curve": "smooth"}
            ]}}}}),
            "an unknown curve",
        ),
        (
            SchemaKind::Animations,
            json!({"wave": {"parts": {"arm": {"color": [{"time": 0, "value": "red"}]}}}}),
            "a color that is not hex",
        ),
        (
            SchemaKind::Animations,
            json!({"wave": [{"time": 0}]}),
            "an animation that is an array",
        ),
        (
            SchemaKind::Scribbles,
            json!({"strokes": [{"color": "red", "width": 4, "points": [[1, 1]]}]}),
            "a color that is not #rrggbb",
        ),
        (
            SchemaKind::Scribbles,
            json!({"strokes": [{"color": "#ff0000", "width": 4, "points": []}]}),
            "a stroke without points",
        ),
        (
            SchemaKind::Batch,
            json!({"jobs": [{"kind": "bake", "name": "a", "inputs": {}, "outputs": {}}]}),
            "a job of an unknown kind",
        ),
        (
            SchemaKind::Batch,
            json!({"jobs": [{"kind": "colorize", "name": "a",
                "inputs": {"lineart": "a.png", "scribbles": "a.json"},
                "options": {"fill": "bucket"}, "outputs": {"image": "b.png"}}]}),
            "an unknown fill",
        ),
        (
            SchemaKind::Batch,
            json!({"jobs": [{"kind": "render", "name": "a", "inputs": {"rig": "r.json"},
                "options": {"fps": 24}, "outputs": {"output": "a.gif"}}]}),
            "a render without its animation",
        ),
    ];
    for (kind, value, what) in &wrong {
        assert_invalid(*kind, value, what);
        assert!(
            load(*kind, &value.to_string()).is_err(),
            "sinew's reader takes {what}, which the {} schema refuses: {value}",
            kind.name()
        );
    }
}

/// The names the batch schema allows for a colorize job's `fill`, `weights` and `split` are
/// exactly those serde writes for the library's values (the schema is derived from the same
/// enums), and a job naming each one validates and loads.
#[test]
fn the_colorize_jobs_value_names_are_the_enums_serde_names() {
    use sinew::colorize::{ColorWeights, FillMode, RegionSplit};
    let batch = serde_json::to_value(schema(SchemaKind::Batch)).unwrap();
    let names_in_schema = |option: &str| -> Vec<String> {
        let reference = batch["$defs"]["ColorizeJobOptions"]["properties"][option]["$ref"]
            .as_str()
            .unwrap_or_else(|| panic!("{option}: no $ref"));
        let values = &batch["$defs"][reference.trim_start_matches("#/$defs/")];
        let mut names: Vec<String> = match values.get("oneOf") {
            Some(one_of) => one_of
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v["const"].clone())
                .collect(),
            None => values["enum"].as_array().expect("oneOf or enum").clone(),
        }
        .into_iter()
        .map(|name| name.as_str().expect("a name").to_string())
        .collect();
        names.sort();
        names
    };
    /// The names serde writes for `values`, sorted.
    fn serde_names<T: serde::Serialize>(values: &[T]) -> Vec<String> {
        let mut names: Vec<String> = values
            .iter()
            .map(|v| {
                serde_json::to_value(v)
                    .unwrap()
                    .as_str()
                    .expect("a name")
                    .to_string()
            })
            .collect();
        names.sort();
        names
    }
    let options = [
        ("fill", serde_names(&[FillMode::Flat, FillMode::Soft])),
        (
            "weights",
            serde_names(&[ColorWeights::Harmonic, ColorWeights::Bbw]),
        ),
        ("split", serde_names(&RegionSplit::ALL)),
    ];
    for (option, names) in options {
        assert_eq!(names_in_schema(option), names, "{option}");
        for value in names {
            let manifest = json!({"jobs": [{"kind": "colorize", "name": "a",
                "inputs": {"lineart": "a.png", "scribbles": "a.json"},
                "options": {option: value}, "outputs": {"image": "b.png"}}]});
            assert_valid(SchemaKind::Batch, &manifest, &format!("{option} {value}"));
            load(SchemaKind::Batch, &manifest.to_string())
                .unwrap_or_else(|e| panic!("{option} {value}: {e}"));
        }
    }
}

/// `sinew schema KIND` prints the library's schema; an unknown kind is one line, exit 2.
#[cfg(feature = "cli")]
#[test]
fn the_command_prints_each_schema() {
    for kind in SchemaKind::ALL {
        let out = command::sinew(&["schema", kind.name()]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let printed: Value = serde_json::from_slice(&out.stdout).expect("the schema is JSON");
        assert_eq!(
            printed,
            serde_json::to_value(schema(kind)).unwrap(),
            "{}",
            kind.name()
        );
    }
    command::assert_bad_input(&["schema", "poses"], "invalid value 'poses'");
}

/// The rig `sinew rig` writes for the bundled character with its handles validates, and so does
/// the same rig with the bundled animations in it (as `sinew demo` writes it).
#[cfg(feature = "cli")]
#[test]
fn the_rig_the_command_writes_for_the_character_validates() {
    let assets = root().join("assets/character");
    let tmp = command::scratch("character");
    let dir = tmp.path();
    let layers = read_json(&assets.join("layers.json"));
    // The layers, then the other attachments of their slots.
    let attachments = layers["attachments"].as_object().expect("attachments");
    let images: Vec<String> = layers["layers"]
        .as_array()
        .expect("a layer list")
        .iter()
        .map(|n| n.as_str().expect("a layer name"))
        .chain(attachments.keys().map(String::as_str))
        .map(|name| assets.join(format!("{name}.png")).display().to_string())
        .collect();
    let rig = dir.join("character.json");
    let handles = assets.join("handles.json");
    let mut args = vec!["rig"];
    args.extend(images.iter().map(String::as_str));
    args.extend(["--handles", command::s(&handles)]);
    args.extend(["-o", command::s(&rig)]);
    let out = command::sinew(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut written = read_json(&rig);
    assert_eq!(
        written["parts"].as_array().map(Vec::len),
        Some(images.len())
    );
    assert_valid(SchemaKind::Rig, &written, "the rig `sinew rig` wrote");
    // Its slots and skins, as `sinew demo` sets them.
    for part in written["parts"].as_array_mut().expect("parts") {
        if let Some(slot) = part["name"].as_str().and_then(|n| attachments.get(n)) {
            part["slot"] = slot.clone();
        }
    }
    written["skins"] = layers["skins"].clone();
    assert_valid(SchemaKind::Rig, &written, "the rig with slots and skins");
    let mut wrong = written.clone();
    wrong["skins"]["pail"]["bag"] = serde_json::json!(["bag_pail"]);
    assert_invalid(
        SchemaKind::Rig,
        &wrong,
        "a skin's attachment that is not a name",
    );
    written["animations"] = read_json(&assets.join("animations.json"));
    written["events"] = read_json(&assets.join("events.json"));
    assert_valid(
        SchemaKind::Rig,
        &written,
        "the rig with the bundled animations",
    );
    let doc = RigDocument::from_json(&written.to_string(), &rig).expect("sinew reads it back");
    doc.check_animations().expect("the animations fit the rig");
}
