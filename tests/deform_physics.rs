//! Deform keys and physics constraints through the binary: bad input refused in one line (exit
//! 2, nothing written), and physics frames a function of the time alone (not of the frame
//! rate or of which frames were asked for before); exported natively to 4.2, baked for 4.3.

mod command;
mod common;

use command::{assert_bad_input, s, scratch};
use serde_json::{json, Value};
use sinew::export::spine::{export_spine, SpineOptions, SpineVersion};
use sinew::pipeline::Scene;
use sinew::scene::{frames, PlayOptions, Playhead};
use std::path::{Path, PathBuf};

/// A two-bone rig of a 64 px critter (`a`, and `b` hanging from it): its document and path.
fn rig(dir: &Path) -> (Value, PathBuf) {
    let sprite = dir.join("critter.png");
    common::critter(64).save(&sprite).unwrap();
    command::rig_cli(
        dir,
        &[&sprite],
        r#"{"bones":[{"name":"a","head":[32,45],"tail":[32,30]},
                     {"name":"b","parent":"a","head":[32,30],"tail":[32,18]}]}"#,
        &[],
    )
}

fn write(path: &Path, value: &Value) -> PathBuf {
    std::fs::write(path, value.to_string()).unwrap();
    path.to_path_buf()
}

fn vertex_count(doc: &Value) -> usize {
    doc["parts"][0]["mesh"]["vertices"]
        .as_array()
        .unwrap()
        .len()
}

#[test]
fn deform_offsets_of_the_wrong_length_are_refused() {
    let tmp = scratch("deform-length");
    let dir = tmp.path();
    let (mut doc, rig) = rig(dir);
    let n = vertex_count(&doc);
    let part = doc["parts"][0]["name"].as_str().unwrap().to_string();
    doc["animations"] = json!({"squash": {"deform": {part.clone(): [
        {"time": 0, "value": vec![[0.0, 0.0]; n - 1]}]}}});
    write(&rig, &doc);
    let png = dir.join("out.png");
    let gif = dir.join("out.gif");
    for args in [
        vec!["pose", s(&rig), "--anim", "squash", "-o", s(&png)],
        vec!["render", s(&rig), "--anim", "squash", "-o", s(&gif)],
    ] {
        assert_bad_input(
            &args,
            &format!(
                "deform.{part}: key 0 has {} offsets but the part's mesh has {n}",
                n - 1
            ),
        );
    }
    // Keys of one timeline disagreeing among themselves.
    doc["animations"] = json!({"squash": {"deform": {part.clone(): [
        {"time": 0, "value": vec![[0.0, 0.0]; n]}, {"time": 1, "value": vec![[0.0, 0.0]; 2]}]}}});
    write(&rig, &doc);
    assert_bad_input(
        &["pose", s(&rig), "--anim", "squash", "-o", s(&png)],
        "key 1 has 2 vertices but key 0 has",
    );
    // A part the rig does not have.
    doc["animations"] = json!({"squash": {"deform": {"nobody": [
        {"time": 0, "value": [[0.0, 0.0]]}]}}});
    write(&rig, &doc);
    assert_bad_input(
        &["pose", s(&rig), "--anim", "squash", "-o", s(&png)],
        "names part 'nobody', which the rig does not have",
    );
    assert!(!png.exists() && !gif.exists());
}

#[test]
fn bad_physics_parameters_are_refused() {
    let tmp = scratch("physics-bad");
    let dir = tmp.path();
    let (doc, rig) = rig(dir);
    let png = dir.join("out.png");
    for (constraint, message) in [
        (
            json!({"name": "p", "bone": "b", "rotate": 1, "gravity": "NaN"}),
            "invalid type",
        ),
        (
            json!({"name": "p", "bone": "b", "rotate": 1, "mass": 0}),
            "physics constraint 'p': \"mass\" is 0: at least",
        ),
        (
            json!({"name": "p", "bone": "b", "rotate": 1, "fps": -60}),
            "physics constraint 'p': \"fps\" is -60: in (0, 1000]",
        ),
        (
            json!({"name": "p", "bone": "nope", "rotate": 1}),
            "physics constraint 'p': bone 'nope' does not exist",
        ),
    ] {
        let mut doc = doc.clone();
        doc["handles"]["physics"] = json!([constraint]);
        write(&rig, &doc);
        assert_bad_input(&["pose", s(&rig), "-o", s(&png)], message);
    }
    // A number JSON cannot hold as a finite f64 (serde reads 1e400 as out of range).
    let mut bad = doc.clone();
    bad["handles"]["physics"] = json!([{"name": "p", "bone": "b", "rotate": 1}]);
    let text = bad.to_string().replace("\"rotate\":1", "\"rotate\":1e400");
    std::fs::write(&rig, text).unwrap();
    assert_bad_input(&["pose", s(&rig), "-o", s(&png)], "out of range");
    assert!(!png.exists());
}

#[test]
fn physics_frames_depend_on_the_time_alone() {
    let tmp = scratch("physics-time");
    let dir = tmp.path();
    let (mut doc, rig) = rig(dir);
    doc["handles"]["physics"] = json!([{"name": "p", "bone": "b", "rotate": 1, "x": 1,
        "inertia": 0.8, "strength": 40, "damping": 0.9, "gravity": 30}]);
    doc["animations"] = json!({"swing": {"bones": {"a": {
        "rotate": [{"time": 0, "value": 0}, {"time": 0.3, "value": 40, "curve": "stepped"},
                   {"time": 0.6, "value": -20}],
        "translate": [{"time": 0, "value": [0, 0]}, {"time": 0.5, "value": [12, -6]}]}}}});
    write(&rig, &doc);
    let scene = Scene::load(&rig).unwrap();
    let animation = &scene.doc.animations["swing"];
    let options = PlayOptions::default();
    // At 24 and 30 fps, and one frame asked alone, off and on the 60 Hz update grid.
    let at_24: Vec<f64> = (0..=24).map(|k| k as f64 / 24.0).collect();
    let at_30: Vec<f64> = (0..=30).map(|k| k as f64 / 30.0).collect();
    let f24 = frames(&scene, animation, &at_24, options).unwrap();
    let f30 = frames(&scene, animation, &at_30, options).unwrap();
    for (k24, k30) in [(12, 15), (24, 30)] {
        assert_eq!(
            f24[k24].transforms, f30[k30].transforms,
            "t = {} s",
            at_24[k24]
        );
    }
    for t in [0.55, 1.0 / 24.0 * 7.0] {
        let mut head = Playhead::new(&scene, animation, options);
        let alone = head.frame(t).unwrap();
        let mut head = Playhead::new(&scene, animation, options);
        head.frame(0.9).unwrap(); // later first: the simulation restarts
        assert_eq!(
            head.frame(t).unwrap().transforms,
            alone.transforms,
            "t = {t} s"
        );
    }
    // The physics does move the bone: against the same frames without it.
    let still = frames(&scene.without_physics(), animation, &at_24, options).unwrap();
    let moved = f24
        .iter()
        .zip(&still)
        .map(|(a, b)| (a.transforms[1].translation - b.transforms[1].translation).norm())
        .fold(0.0, f64::max);
    assert!(moved > 1.0, "physics moved bone b only {moved} px");
    // Spine 4.2 simulates the constraint itself; 4.3 (another model) gets its motion baked.
    let images: Vec<_> = scene
        .doc
        .parts
        .iter()
        .map(|p| sinew::io::load_png(&sinew::io::RigDocument::image_path(&rig, p)).unwrap())
        .collect();
    for (version, native) in [(SpineVersion::V4_2, true), (SpineVersion::V4_3, false)] {
        let options = SpineOptions {
            version,
            ..Default::default()
        };
        let export = export_spine(&scene, &images, "rig", &options).unwrap();
        assert_eq!(export.json.contains("\"physics\":["), native, "{version:?}");
        let baked = &export.baked.iter().find(|(a, _)| a == "swing").unwrap().1;
        assert_eq!(
            baked.contains(&"b".to_string()),
            !native,
            "{version:?}: {baked:?}"
        );
    }
    // Static poses show no physics.
    let rest = scene.handle_transforms(&Default::default()).unwrap();
    assert_eq!(
        rest,
        scene
            .without_physics()
            .handle_transforms(&Default::default())
            .unwrap()
    );
}
