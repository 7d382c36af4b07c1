//! Paths inside files are confined to the folder they are relative to (issue 44, item 3): a
//! batch manifest's every path to the manifest's folder, a rig document's part images to the
//! rig's folder (a batch checks them before any job; tests/self_contained.rs has the other
//! readers), a Spine script's images to its JSON's folder. `..` out of the folder, an absolute path and a
//! symbolic link leading out are each refused before any work: one line naming the file, the
//! field and the path as written, exit code 2, nothing written anywhere.

mod command;
mod common;

use command::{assert_bad_input, s, scratch};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Every file under `dir` (recursively), relative, sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() && !path.is_symlink() {
                stack.push(path.clone());
            }
            out.push(path.strip_prefix(dir).unwrap().to_path_buf());
        }
    }
    out.sort();
    out
}

/// A scratch folder holding `outside/` (a folder the manifest must not reach) and `project/`
/// (the manifest's folder, with one sprite and a link `project/away` → `outside`).
fn project(name: &str) -> (tempfile::TempDir, PathBuf) {
    let tmp = scratch(name);
    let project = tmp.path().join("project");
    std::fs::create_dir_all(&project).unwrap();
    std::fs::create_dir_all(tmp.path().join("outside")).unwrap();
    common::critter(64)
        .save(project.join("critter.png"))
        .unwrap();
    std::os::unix::fs::symlink(tmp.path().join("outside"), project.join("away")).unwrap();
    (tmp, project)
}

fn manifest(dir: &Path, jobs: Vec<Value>) -> PathBuf {
    let path = dir.join("game.json");
    std::fs::write(&path, json!({ "jobs": jobs }).to_string()).unwrap();
    path
}

fn autorig_to(output: &str) -> Value {
    json!({"kind": "autorig", "name": "handles", "inputs": {"images": ["critter.png"]},
           "outputs": {"handles": output}})
}

#[test]
fn every_manifest_path_that_leaves_its_folder_is_refused_before_any_work() {
    let (tmp, project) = project("confine-manifest");
    let before = files(tmp.path());
    let absolute = tmp.path().join("abs.json");
    let cases: Vec<(Value, &str, String)> = vec![
        (
            autorig_to("../escape.json"),
            "outputs.handles",
            "\"../escape.json\" climbs out of".into(),
        ),
        (
            autorig_to("sub/../../escape.json"),
            "outputs.handles",
            "climbs out of".into(),
        ),
        (
            autorig_to(s(&absolute)),
            "outputs.handles",
            format!("\"{}\" is absolute", absolute.display()),
        ),
        (
            autorig_to("away/handles.json"),
            "outputs.handles",
            "through a symbolic link".into(),
        ),
        (
            json!({"kind": "autorig", "name": "handles",
                   "inputs": {"images": ["critter.png", "../outside.png"]},
                   "outputs": {"handles": "h.json"}}),
            "inputs.images[1]",
            "\"../outside.png\" climbs out of".into(),
        ),
        (
            json!({"kind": "export", "name": "spine", "inputs": {"rig": "/etc/passwd"},
                   "outputs": {"folder": "spine"}}),
            "inputs.rig",
            "is absolute".into(),
        ),
        (
            json!({"kind": "render", "name": "walk", "inputs": {"rig": "rig.json"},
                   "options": {"animation": "walk"}, "outputs": {"output": "away/frames"}}),
            "outputs.output",
            "through a symbolic link".into(),
        ),
    ];
    for (job, field, problem) in cases {
        let manifest = manifest(&project, vec![job]);
        let stderr = assert_bad_input(&["batch", s(&manifest)], &problem);
        assert!(
            stderr.contains(&format!("{}: job '", manifest.display()))
                && stderr.contains(&format!("': {field}: ")),
            "names the file and the field: {stderr}"
        );
        std::fs::remove_file(&manifest).unwrap();
        assert_eq!(files(tmp.path()), before, "nothing written: {stderr}");
    }
    // Inside the folder, `..` that stays in it and a link that stays in it are fine.
    std::fs::create_dir_all(project.join("real")).unwrap();
    std::os::unix::fs::symlink(project.join("real"), project.join("here")).unwrap();
    let manifest = manifest(&project, vec![autorig_to("sub/../here/handles.json")]);
    let out = command::sinew(&["batch", s(&manifest)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(project.join("real/handles.json").is_file());
    assert!(files(&tmp.path().join("outside")).is_empty());
}

#[test]
fn a_rig_a_batch_reads_may_not_name_images_outside_the_manifests_folder() {
    let (tmp, project) = project("confine-rig");
    let (mut doc, rig) = command::rig_cli(
        &project,
        &[&project.join("critter.png")],
        r#"{"bones":[{"name":"a","head":[32,45],"tail":[32,20]}]}"#,
        &[],
    );
    // The rig in a subfolder names its image by a `..` that stays in the rig's folder: fine.
    std::fs::create_dir_all(project.join("rigs/layers")).unwrap();
    std::fs::copy(
        project.join("critter.png"),
        project.join("rigs/critter.png"),
    )
    .unwrap();
    doc["parts"][0]["image"] = json!("layers/../critter.png");
    let inner = project.join("rigs/rig.json");
    std::fs::write(&inner, doc.to_string()).unwrap();
    std::fs::remove_file(&rig).unwrap();
    let export = |rig: &str| {
        json!({"kind": "export", "name": "spine", "inputs": {"rig": rig},
               "outputs": {"folder": "spine"}})
    };
    let ok = manifest(&project, vec![export("rigs/rig.json")]);
    let out = command::sinew(&["batch", s(&ok)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_dir_all(project.join("spine")).unwrap();
    std::fs::remove_file(project.join("game.state.json")).unwrap();
    // Out of the rig's folder by `..` (even within the project), out of the project, through
    // a link, or absolute: refused before any job, naming the rig.
    common::critter(64)
        .save(tmp.path().join("outside/secret.png"))
        .unwrap();
    std::os::unix::fs::symlink(tmp.path().join("outside"), project.join("rigs/away")).unwrap();
    for (image, problem) in [
        ("../critter.png", "climbs out of"),
        ("../../outside/secret.png", "climbs out of"),
        ("../../../../../../etc/passwd", "climbs out of"),
        ("away/secret.png", "through a symbolic link"),
    ] {
        doc["parts"][0]["image"] = json!(image);
        std::fs::write(&inner, doc.to_string()).unwrap();
        let manifest = manifest(&project, vec![export("rigs/rig.json")]);
        let stderr = assert_bad_input(&["batch", s(&manifest)], problem);
        assert!(
            stderr.contains(&format!(
                "{}: job 'spine': parts[0].image: \"{image}\"",
                inner.display()
            )),
            "{stderr}"
        );
        assert!(!project.join("spine").exists(), "nothing written");
    }
    // An absolute image path is refused by every reader of rig documents.
    doc["parts"][0]["image"] = json!(s(&tmp.path().join("outside/secret.png")));
    std::fs::write(&inner, doc.to_string()).unwrap();
    let out = tmp.path().join("cli-spine");
    assert_bad_input(
        &["export", "spine", s(&inner), "-o", s(&out)],
        "(parts[0].image): \"",
    );
    assert!(!out.exists());
}

#[test]
fn a_spine_script_json_reads_images_only_in_its_folder() {
    let (tmp, project) = project("confine-spine-script");
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/layered/spine");
    let art = project.join("art");
    std::fs::create_dir_all(&art).unwrap();
    for entry in std::fs::read_dir(&fixture).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, art.join(path.file_name().unwrap())).unwrap();
    }
    let script: Value =
        serde_json::from_str(&std::fs::read_to_string(art.join("character.json")).unwrap())
            .unwrap();
    let rig = project.join("rig.json");
    // As the script wrote it: rigged.
    let out = command::sinew(&["rig", s(&art.join("character.json")), "-o", s(&rig)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_file(&rig).unwrap();
    std::fs::remove_dir_all(project.join("rig.parts")).unwrap();
    let before = files(tmp.path());
    let json_path = art.join("hostile.json");
    // `skeleton.images` out of the folder, absolute, or through a link; an attachment's
    // `path` climbing out.
    let mut cases: Vec<(Value, &str)> = Vec::new();
    for images in ["../..", "/etc", "../away"] {
        let mut v = script.clone();
        v["skeleton"]["images"] = json!(images);
        cases.push((v, "\"skeleton\".\"images\""));
    }
    let mut v = script.clone();
    let skin = match &mut v["skins"] {
        Value::Array(list) => &mut list[0]["attachments"],
        other => other.get_mut("default").unwrap(),
    };
    let (slot, attachments) = skin.as_object_mut().unwrap().iter_mut().next().unwrap();
    let slot = slot.clone();
    let (name, attachment) = attachments
        .as_object_mut()
        .unwrap()
        .iter_mut()
        .next()
        .unwrap();
    let name = name.clone();
    attachment["path"] = json!("../../outside/secret");
    cases.push((v, "\"path\""));
    for (v, field) in cases {
        std::fs::write(&json_path, v.to_string()).unwrap();
        let stderr = assert_bad_input(&["rig", s(&json_path), "-o", s(&rig)], field);
        assert!(
            stderr.contains(&json_path.display().to_string()),
            "{stderr}"
        );
        std::fs::remove_file(&json_path).unwrap();
        assert_eq!(files(tmp.path()), before, "nothing written: {stderr}");
    }
    let _ = (slot, name);
}
