//! `sinew animate`: a motion of the bundled library or a BVH file added to a rig document, and
//! the bad-input contract for capture files (one line, exit code 2, nothing written).
#![cfg(feature = "cli")]

mod command;

use command::{assert_bad_input, s, scratch, sinew};
use std::path::{Path, PathBuf};

/// The bundled character rigged by `sinew demo` into `dir`; returns its rig document.
fn demo_rig(dir: &Path) -> PathBuf {
    let out = sinew(&["demo", "-o", s(dir)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir.join("character.json")
}

fn animations(rig: &Path) -> Vec<String> {
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(rig).expect("the rig")).expect("json");
    doc["animations"]
        .as_object()
        .map(|m| m.keys().cloned().collect())
        .unwrap_or_default()
}

fn walk_bvh() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/motions/walk.bvh"))
        .expect("walk.bvh")
}

#[test]
fn a_library_motion_and_a_capture_file_become_animations() {
    let tmp = scratch("library");
    let rig = demo_rig(tmp.path());
    let before = std::fs::read(&rig).expect("rig");
    let out_rig = tmp.path().join("moving.json");
    let out = sinew(&[
        "animate",
        s(&rig),
        "--motion",
        "run",
        "--in-place",
        "-o",
        s(&out_rig),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("animation 'run'") && stdout.contains("loops"),
        "{stdout}"
    );
    assert!(animations(&out_rig).contains(&"run".to_string()));
    assert_eq!(
        std::fs::read(&rig).expect("rig"),
        before,
        "-o elsewhere leaves the rig alone"
    );

    // A capture file, with a name, into the rig itself; then rendered from the new document.
    let clip = tmp.path().join("my walk.bvh");
    std::fs::write(&clip, walk_bvh()).expect("write");
    let out = sinew(&[
        "animate",
        s(&out_rig),
        "--motion",
        s(&clip),
        "--name",
        "stroll",
        "--view",
        "side",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let names = animations(&out_rig);
    assert!(
        names.contains(&"stroll".to_string()) && names.contains(&"run".to_string()),
        "{names:?}"
    );
    let gif = tmp.path().join("stroll.gif");
    let out = sinew(&[
        "render",
        s(&out_rig),
        "--anim",
        "stroll",
        "--fps",
        "6",
        "-o",
        s(&gif),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(gif.is_file());
}

#[test]
fn bad_captures_are_one_line_and_write_nothing() {
    let tmp = scratch("bad");
    let rig = demo_rig(tmp.path());
    let before = std::fs::read(&rig).expect("rig");
    let out_rig = tmp.path().join("out.json");
    let walk = walk_bvh();
    let half = &walk[..walk.len() / 2];
    let nan = walk.replacen(" 0.", " nan ", 1);
    let motion_at = walk.find("MOTION").expect("a MOTION section");
    let wrong_count = {
        let (head, rows) = walk.split_at(motion_at);
        let mut rows: Vec<String> = rows.lines().map(str::to_string).collect();
        if let Some(row) = rows.get_mut(4) {
            row.push_str(" 1.0 2.0");
        }
        format!("{head}{}\n", rows.join("\n"))
    };
    let million = {
        let (head, _) = walk.split_at(motion_at);
        format!("{head}MOTION\nFrames: 1000000\nFrame Time: 0.0333\n")
    };
    let many_joints = {
        let mut text = String::from(
            "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n",
        );
        for k in 0..10_000 {
            text += &format!("JOINT j{k}\n{{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\nEnd Site\n{{\nOFFSET 0 1 0\n}}\n}}\n");
        }
        text + "}\nMOTION\nFrames: 1\nFrame Time: 0.0333\n0 0 0\n"
    };
    for (name, text, says) in [
        ("truncated", half.to_string(), "line"),
        ("nan", nan, "line"),
        ("wrong-count", wrong_count, "line"),
        ("million", million, "frames"),
        ("many-joints", many_joints, "joints"),
    ] {
        let clip = tmp.path().join(format!("{name}.bvh"));
        std::fs::write(&clip, text).expect("write");
        assert_bad_input(
            &["animate", s(&rig), "--motion", s(&clip), "-o", s(&out_rig)],
            says,
        );
        assert!(!out_rig.exists(), "{name}: nothing written");
        assert_eq!(
            std::fs::read(&rig).expect("rig"),
            before,
            "{name}: the rig is untouched"
        );
    }
    let stderr = assert_bad_input(&["animate", s(&rig), "--motion", "moonwalk"], "walk");
    assert!(stderr.contains("no motion 'moonwalk'"), "{stderr}");
    let map = tmp.path().join("map.json");
    std::fs::write(&map, r#"{"bones": {"hip": ["Pelvis", "Spine"]}}"#).expect("write");
    assert_bad_input(
        &[
            "animate",
            s(&rig),
            "--motion",
            "walk",
            "--map",
            s(&map),
            "-o",
            s(&out_rig),
        ],
        "Pelvis",
    );
    assert!(!out_rig.exists());
    assert_eq!(std::fs::read(&rig).expect("rig"), before);
}
