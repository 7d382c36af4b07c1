//! Rig documents are self-contained and confined (issue 44, items 3 and 7): every rig sinew
//! writes names only images inside its folder (those outside are copied into `RIG.parts/`), so
//! the folder can be moved; a rig whose images leave its folder (`..`, a symbolic link) is
//! refused by every reader with one line naming the rig, the part and the field; a re-rig with
//! fewer parts leaves no stale image in `RIG.parts/`.

mod command;
mod common;

use command::{assert_bad_input, s, scratch};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Two layers on one 64×64 canvas in `art/` (outside the rig's folder): the critter and the
/// critter mirrored, with a bone across both.
fn art(dir: &Path) -> PathBuf {
    let art = dir.join("art");
    std::fs::create_dir_all(&art).unwrap();
    let critter = common::critter(64);
    critter.save(art.join("body.png")).unwrap();
    image::imageops::flip_vertical(&critter)
        .save(art.join("tail.png"))
        .unwrap();
    std::fs::write(
        art.join("handles.json"),
        r#"{"bones":[{"name":"spine","head":[32,50],"tail":[32,14]}]}"#,
    )
    .unwrap();
    art
}

/// Runs `sinew ARGS` in `cwd`; asserts success.
fn sinew_in(cwd: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_sinew"))
        .current_dir(cwd)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The rig's part images, as written.
fn images(rig: &Value) -> Vec<String> {
    rig["parts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["image"].as_str().unwrap().to_string())
        .collect()
}

/// A pose bending the bone and an animation doing it, so a render shows the weights at work.
fn with_animation(rig: &Path) {
    let mut doc = read(rig);
    doc["animations"] = json!({"bend": {"bones": {"spine": {"rotate": [
        {"time": 0, "value": 0}, {"time": 0.25, "value": 30}]}}}});
    std::fs::write(rig, doc.to_string()).unwrap();
}

#[test]
fn a_rig_of_images_outside_its_folder_copies_them_in_and_moves_whole() {
    let tmp = scratch("moves");
    let dir = tmp.path();
    art(dir);
    let work = dir.join("work");
    std::fs::create_dir_all(work.join("out")).unwrap();
    // As a person types it: the art beside the working folder, the rig below it.
    sinew_in(
        &work,
        &[
            "rig",
            "../art/body.png",
            "../art/tail.png",
            "--handles",
            "../art/handles.json",
            "-o",
            "out/rig.json",
        ],
    );
    let out = work.join("out");
    let rig = out.join("rig.json");
    let doc = read(&rig);
    assert_eq!(images(&doc), ["rig.parts/body.png", "rig.parts/tail.png"]);
    for image in images(&doc) {
        assert_eq!(
            std::fs::read(out.join(&image)).unwrap(),
            std::fs::read(dir.join("art").join(Path::new(&image).file_name().unwrap())).unwrap(),
            "{image} is a copy of the layer"
        );
    }
    with_animation(&rig);
    let pose = dir.join("pose.json");
    std::fs::write(&pose, r#"{"bones":{"spine":{"rotate":25}}}"#).unwrap();
    let draw = |rig: &Path, tag: &str| -> (Vec<u8>, Vec<u8>) {
        let (posed, gif) = (
            dir.join(format!("posed-{tag}.png")),
            dir.join(format!("bend-{tag}.gif")),
        );
        let run = |args: &[&str]| {
            let out = command::sinew(args);
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
        };
        run(&["pose", s(rig), "--pose", s(&pose), "-o", s(&posed)]);
        run(&["render", s(rig), "--anim", "bend", "-o", s(&gif)]);
        (std::fs::read(posed).unwrap(), std::fs::read(gif).unwrap())
    };
    let before = draw(&rig, "before");
    // The folder moved elsewhere, the art gone: the rig draws the same.
    let moved = dir.join("elsewhere/deeper/moved");
    std::fs::create_dir_all(moved.parent().unwrap()).unwrap();
    std::fs::rename(&out, &moved).unwrap();
    std::fs::remove_dir_all(dir.join("art")).unwrap();
    let after = draw(&moved.join("rig.json"), "after");
    assert!(before == after, "the moved rig draws identically");
}

#[test]
fn images_already_inside_keep_their_path_and_nothing_is_copied() {
    let tmp = scratch("inside");
    let dir = tmp.path();
    let art = art(dir);
    // The rig in the art's own folder: `body.png` as it is.
    sinew_in(
        &art,
        &[
            "rig",
            "body.png",
            "tail.png",
            "--handles",
            "handles.json",
            "-o",
            "rig.json",
        ],
    );
    assert_eq!(
        images(&read(&art.join("rig.json"))),
        ["body.png", "tail.png"]
    );
    assert!(!art.join("rig.parts").exists());
    // In a subfolder of the rig's: kept too.
    let out = dir.join("out");
    std::fs::create_dir_all(out.join("layers")).unwrap();
    std::fs::copy(art.join("body.png"), out.join("layers/body.png")).unwrap();
    sinew_in(&out, &["rig", "layers/body.png", "-o", "rig.json"]);
    assert_eq!(images(&read(&out.join("rig.json"))), ["layers/body.png"]);
    assert!(!out.join("rig.parts").exists());
}

#[test]
fn a_rig_naming_images_outside_its_folder_is_refused_by_every_reader() {
    let tmp = scratch("refused");
    let dir = tmp.path();
    let art = art(dir);
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let rig = out.join("rig.json");
    sinew_in(
        dir,
        &[
            "rig",
            "art/body.png",
            "--handles",
            "art/handles.json",
            "-o",
            "out/rig.json",
        ],
    );
    with_animation(&rig);
    let good = read(&rig);
    // The image exists where the hand-edited path points: refused for leaving, not missing.
    std::os::unix::fs::symlink(&art, out.join("link")).unwrap();
    let root = std::path::absolute(&out).unwrap();
    for (image, problem) in [
        (
            "../art/body.png".to_string(),
            format!(
                "\"../art/body.png\" climbs out of {} by '..'",
                root.display()
            ),
        ),
        (
            "rig.parts/../../art/body.png".to_string(),
            "climbs out of".to_string(),
        ),
        (
            "link/body.png".to_string(),
            "leads out of".to_string() + &format!(" {} through a symbolic link", root.display()),
        ),
        (
            s(&art.join("body.png")).to_string(),
            "is absolute".to_string(),
        ),
    ] {
        let mut doc = good.clone();
        doc["parts"][0]["image"] = json!(image);
        std::fs::write(&rig, doc.to_string()).unwrap();
        let line = format!("{}: part 'body' (parts[0].image): ", rig.display());
        let advice = "keep a rig's images in its folder (sinew rig and the editor's Save copy them into rig.parts/)";
        let (posed, gif, spine) = (dir.join("p.png"), dir.join("b.gif"), dir.join("spine"));
        for args in [
            vec!["pose", s(&rig), "-o", s(&posed)],
            vec!["render", s(&rig), "--anim", "bend", "-o", s(&gif)],
            vec!["export", "spine", s(&rig), "-o", s(&spine)],
            vec!["target", s(&rig), "spine-4.2"],
        ] {
            let stderr = assert_bad_input(&args, &problem);
            assert!(
                stderr.starts_with(&format!("sinew: error: {line}"))
                    && stderr.trim_end().ends_with(advice),
                "{args:?}: {stderr}"
            );
        }
        assert!(!posed.exists() && !gif.exists() && !spine.exists());
        // The editor's loader says the same.
        let e = sinew::document::Document::open(&rig)
            .err()
            .expect("the editor refuses the rig")
            .to_string();
        assert!(e.contains(&line) && e.contains(&problem), "{e}");
    }
}

#[test]
fn a_re_rig_with_fewer_parts_leaves_no_stale_image() {
    let tmp = scratch("stale");
    let dir = tmp.path();
    art(dir);
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let rig_of = |layers: &[&str]| {
        let mut args = vec!["rig"];
        args.extend_from_slice(layers);
        args.extend(["-o", "out/rig.json"]);
        sinew_in(dir, &args);
    };
    rig_of(&["art/body.png", "art/tail.png"]);
    let parts = out.join("rig.parts");
    assert!(parts.join("body.png").is_file() && parts.join("tail.png").is_file());
    // What is not a PNG sinew wrote there stays: a note, a PNG of the person's, a PNG beside
    // the rig, a link.
    std::fs::write(parts.join("notes.txt"), "mine").unwrap();
    std::fs::copy(dir.join("art/tail.png"), parts.join("mine.png")).unwrap();
    std::fs::copy(dir.join("art/tail.png"), out.join("keep.png")).unwrap();
    std::os::unix::fs::symlink(dir.join("art/tail.png"), parts.join("linked.png")).unwrap();
    rig_of(&["art/body.png"]);
    assert_eq!(images(&read(&out.join("rig.json"))), ["rig.parts/body.png"]);
    assert!(
        !parts.join("tail.png").exists(),
        "the stale image is removed"
    );
    assert!(parts.join("body.png").is_file());
    assert!(parts.join("notes.txt").is_file() && out.join("keep.png").is_file());
    assert!(parts.join("mine.png").is_file());
    assert!(parts.join("linked.png").is_symlink());
    assert!(
        dir.join("art/tail.png").is_file(),
        "the art is never touched"
    );
}

#[test]
fn the_editors_save_writes_a_self_contained_rig() {
    use sinew::document::{Command as Edit, Document};
    let tmp = scratch("editor");
    let dir = tmp.path();
    let art = art(dir);
    let mut doc = Document::new();
    for name in ["body", "tail"] {
        let path = art.join(format!("{name}.png"));
        let layer = sinew::pipeline::Layer::whole(name, &path, sinew::io::load_png(&path).unwrap());
        doc.apply(Edit::AddLayer(layer)).unwrap();
    }
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let rig = out.join("scene.json");
    doc.save(&rig).unwrap();
    assert_eq!(
        images(&read(&rig)),
        ["scene.parts/body.png", "scene.parts/tail.png"]
    );
    // Opened again from the moved folder, the art gone.
    std::fs::remove_dir_all(&art).unwrap();
    let moved = dir.join("moved");
    std::fs::rename(&out, &moved).unwrap();
    let mut reopened = Document::open(&moved.join("scene.json")).unwrap();
    // An image deleted behind the editor's back is written again from the layer it holds.
    std::fs::remove_file(moved.join("scene.parts/tail.png")).unwrap();
    reopened.save(&moved.join("scene.json")).unwrap();
    assert!(moved.join("scene.parts/tail.png").is_file());
    Document::open(&moved.join("scene.json")).unwrap();
    // Save As elsewhere: the images come along into the new rig's folder.
    let other = dir.join("other");
    std::fs::create_dir_all(&other).unwrap();
    reopened.save(&other.join("copy.json")).unwrap();
    assert_eq!(
        images(&read(&other.join("copy.json"))),
        ["copy.parts/body.png", "copy.parts/tail.png"]
    );
    std::fs::remove_dir_all(&moved).unwrap();
    Document::open(&other.join("copy.json")).unwrap();
}
