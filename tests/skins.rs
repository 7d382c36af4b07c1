//! Slots with several attachments, skins and attachment keys through the binary: what `sinew
//! pose` and `sinew render` draw with `--skin` and at times around attachment keys, and bad
//! input (an attachment key or a pose naming an attachment the slot lacks, a skin naming a
//! missing slot, an unknown `--skin`, a bad `sinew rig --attachment`) refused in one line with exit code 2 and no output.

mod command;
mod common;

use command::{assert_bad_input, s, scratch, sinew};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// A rig of one slot, `critter`, with a second attachment `critter_blue` (the same critter
/// with red and blue swapped), a skin `blue` showing it, and an animation `swap` keying
/// critter → critter_blue at 0.5 s → hidden at 0.75 s. Its document and path.
fn rig(dir: &Path) -> (Value, PathBuf) {
    let critter = common::critter(64);
    critter.save(dir.join("critter.png")).unwrap();
    let mut blue = critter.clone();
    for p in blue.pixels_mut() {
        p.0.swap(0, 2);
    }
    blue.save(dir.join("critter_blue.png")).unwrap();
    let (mut doc, rig) = command::rig_cli(
        dir,
        &[&dir.join("critter.png"), &dir.join("critter_blue.png")],
        r#"{"bones":[{"name":"a","head":[32,45],"tail":[32,20]}]}"#,
        &["--attachment", "critter_blue=critter"],
    );
    assert_eq!(doc["parts"][1]["slot"], json!("critter"));
    doc["skins"] = json!({"blue": {"critter": "critter_blue"}});
    doc["animations"] = json!({"swap": {
        "bones": {"a": {"rotate": [{"time": 0, "value": 0}, {"time": 1, "value": 0}]}},
        "parts": {"critter": {"attachment": [
            {"time": 0, "value": "critter"}, {"time": 0.5, "value": "critter_blue"},
            {"time": 0.75, "value": null}]}}}});
    std::fs::write(&rig, doc.to_string()).unwrap();
    (doc, rig)
}

fn write(dir: &Path, name: &str, value: &Value) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, value.to_string()).unwrap();
    path
}

/// The RGBA of `png` at the critter's belly (canvas (32, 37)).
fn belly(png: &Path) -> [u8; 4] {
    image::open(png).unwrap().to_rgba8().get_pixel(32, 37).0
}

#[test]
fn skins_and_attachment_keys_choose_what_the_slot_draws() {
    let tmp = scratch("skins");
    let dir = tmp.path();
    let (_, rig) = rig(dir);
    let png = dir.join("p.png");
    let pose = |extra: &[&str]| {
        let mut args = vec!["pose", s(&rig), "-o", s(&png)];
        args.extend_from_slice(extra);
        let out = sinew(&args);
        assert!(
            out.status.success(),
            "{extra:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        belly(&png)
    };
    let orange = pose(&[]);
    assert!(orange[0] > 200 && orange[2] < 80, "{orange:?}");
    let swapped = [orange[2], orange[1], orange[0], orange[3]];
    // The skin replaces the slot's own part; two skins combine (the later wins).
    assert_eq!(pose(&["--skin", "blue"]), swapped);
    // Keys: the slot's own name until 0.5 s (through the skin), then the named part, then none.
    assert_eq!(pose(&["--anim", "swap", "--time", "0.25"]), orange);
    assert_eq!(
        pose(&["--anim", "swap", "--time", "0.25", "--skin", "blue"]),
        swapped
    );
    assert_eq!(pose(&["--anim", "swap", "--time", "0.5"]), swapped);
    assert_eq!(pose(&["--anim", "swap", "--time", "0.8"])[3], 0);
    // A pose file may name the attachment too.
    let file = write(
        dir,
        "pose.json",
        &json!({"parts": {"critter": {"attachment": "critter_blue"}}}),
    );
    assert_eq!(pose(&["--pose", s(&file)]), swapped);
    // Rendering steps through the same swaps (frames at 0, 0.25, 0.5, 0.75 s at 4 fps).
    let frames = dir.join("frames");
    let out = sinew(&[
        "render",
        s(&rig),
        "--anim",
        "swap",
        "--fps",
        "4",
        "-o",
        s(&frames),
    ]);
    assert!(out.status.success());
    let mut names: Vec<_> = std::fs::read_dir(&frames)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    names.sort();
    let bellies: Vec<[u8; 4]> = names.iter().map(|p| belly(p)).collect();
    assert_eq!(
        bellies,
        [orange, orange, swapped, [0, 0, 0, 0]],
        "{names:?}"
    );
}

#[test]
fn missing_attachments_slots_and_skins_are_refused_in_one_line() {
    let tmp = scratch("skins-bad");
    let dir = tmp.path();
    let (doc, _) = rig(dir);
    let png = dir.join("out.png");
    let gif = dir.join("out.gif");
    let export = dir.join("export");

    let mut bad = doc.clone();
    bad["animations"]["swap"]["parts"]["critter"]["attachment"][1]["value"] = json!("ghost");
    let rig = write(dir, "ghost.json", &bad);
    for args in [
        vec!["render", s(&rig), "--anim", "swap", "-o", s(&gif)],
        vec!["pose", s(&rig), "--anim", "swap", "-o", s(&png)],
        vec!["export", "spine", s(&rig), "-o", s(&export)],
    ] {
        assert_bad_input(
            &args,
            "animation 'swap', parts.critter.attachment: key 1 shows 'ghost', which slot \
             'critter' does not have (its attachments: critter, critter_blue)",
        );
    }

    let mut bad = doc.clone();
    bad["skins"]["blue"]["tail"] = json!("critter_blue");
    let rig = write(dir, "tail.json", &bad);
    assert_bad_input(
        &["pose", s(&rig), "-o", s(&png)],
        "skin 'blue' names slot 'tail', which the rig does not have",
    );

    let rig = write(dir, "good.json", &doc);
    assert_bad_input(
        &["pose", s(&rig), "--skin", "red", "-o", s(&png)],
        "the rig has no skin 'red' (its skins: blue)",
    );
    assert_bad_input(
        &[
            "render",
            s(&rig),
            "--anim",
            "swap",
            "--skin",
            "red",
            "-o",
            s(&gif),
        ],
        "the rig has no skin 'red'",
    );
    let file = write(
        dir,
        "pose.json",
        &json!({"parts": {"critter": {"attachment": "ghost"}}}),
    );
    assert_bad_input(
        &["pose", s(&rig), "--pose", s(&file), "-o", s(&png)],
        "the pose shows attachment 'ghost' in slot 'critter'",
    );
    // `sinew rig --attachment` names layers, and a slot that is a slot.
    let out_rig = dir.join("new.json");
    let critter = dir.join("critter.png");
    let blue = dir.join("critter_blue.png");
    for (attachment, message) in [
        (
            "ghost=critter",
            "--attachment: 'ghost' is not a layer of the rig",
        ),
        ("critter_blue", "is not PART=SLOT"),
        ("critter=critter", "names itself as its slot"),
    ] {
        assert_bad_input(
            &[
                "rig",
                s(&critter),
                s(&blue),
                "--attachment",
                attachment,
                "-o",
                s(&out_rig),
            ],
            message,
        );
    }
    assert!(!png.exists() && !gif.exists() && !export.exists() && !out_rig.exists());
}
