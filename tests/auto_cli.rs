//! `sinew auto ART -o DIR` end to end through the binary: the bundled layered PSD, a flat
//! sprite and a quadruped become a rig with the library's motions, GIFs, sprite sheets and a
//! Spine export; a rig the library cannot drive (no template) still gets everything else; bad input is refused with
//! one line, exit code 2 and nothing written; an earlier output is replaced whole, keeping what
//! the person added, and survives a failed run.
//!
//! Renders are small (`--render-size 96 --fps 8`) so the test stays fast under the debug
//! profile; the defaults (512 px, 24 fps) are measured by tools/auto-bench/run.sh.

mod command;

use command::{assert_bad_input, s, scratch, sinew};
use std::path::{Path, PathBuf};

const SMALL: [&str; 4] = ["--render-size", "96", "--fps", "8"];

fn fixture(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(path)
}

/// Runs `sinew auto ART -o OUT` with the small renders; asserts success; returns stdout.
fn auto(art: &Path, out: &Path) -> String {
    let mut args = vec!["auto", s(art), "-o", s(out)];
    args.extend(SMALL);
    let run = sinew(&args);
    assert!(
        run.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    String::from_utf8_lossy(&run.stdout).into_owned()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn names(value: &serde_json::Value) -> Vec<String> {
    let mut names: Vec<String> = value
        .as_object()
        .map(|o| o.keys().cloned().collect())
        .unwrap_or_default();
    names.sort();
    names
}

const ALL: [&str; 6] = ["idle", "jump", "jump_forward", "run", "walk", "wave"];

#[test]
fn the_bundled_psd_becomes_a_moving_character() {
    let tmp = scratch("psd");
    let out = tmp.path().join("out");
    let stdout = auto(&fixture("layered/bundled_character.psd"), &out);
    assert!(stdout.contains("template: humanoid"), "{stdout}");
    assert!(stdout.contains("time "), "{stdout}");

    let rig = json(&out.join("rig.json"));
    assert_eq!(names(&rig["animations"]), ALL);
    // Weights on every part; the part images are in the folder, found from the document.
    for part in rig["parts"].as_array().unwrap() {
        assert!(part.get("weights").is_some(), "{}", part["name"]);
        let image = part["image"].as_str().unwrap();
        assert!(image.starts_with("rig.parts/"), "{image}");
        assert!(out.join(image).is_file(), "{image}");
    }
    for name in ALL {
        let gif = std::fs::read(out.join(format!("{name}.gif"))).unwrap();
        assert!(gif.starts_with(b"GIF89a"), "{name}");
        let sheet = image::open(out.join(format!("{name}.sheet.png"))).unwrap();
        assert!(sheet.width() >= 96, "{name}");
        let frames = json(&out.join(format!("{name}.sheet.json")));
        assert!(!frames["frames"].as_object().unwrap().is_empty(), "{name}");
    }
    let spine = json(&out.join("spine/bundled_character.json"));
    assert_eq!(names(&spine["animations"]), ALL);
    assert!(out.join("spine/bundled_character.atlas").is_file());

    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["template"], "humanoid");
    assert_eq!(summary["parts"].as_array().unwrap().len(), 12);
    let in_place: Vec<&str> = summary["motions"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["in_place"] == true)
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(in_place, ["idle", "walk", "run", "jump", "jump_forward"]);
    let shares: f64 = summary["stages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["share"].as_f64().unwrap())
        .sum();
    assert!((0.9..=1.0 + 1e-9).contains(&shares), "{shares}");
    // Every file listed exists, and nothing else was written (no temporaries left).
    let listed: Vec<&str> = summary["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    for f in &listed {
        assert!(out.join(f).is_file(), "{f}");
    }
    let mut found = Vec::new();
    walk(&out, &out, &mut found);
    found.sort();
    let mut listed: Vec<String> = listed.iter().map(|f| f.to_string()).collect();
    listed.sort();
    assert_eq!(found, listed);
    let leftovers: Vec<_> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers, [std::ffi::OsString::from("out")]);

    // The rig sinew auto wrote is a rig the other commands take.
    let pose = out.join("..").join("walk.png");
    let run = sinew(&[
        "pose",
        s(&out.join("rig.json")),
        "--anim",
        "walk",
        "--time",
        "0.3",
        "-o",
        s(&pose),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// Files under `dir`, relative to `root`.
fn walk(root: &Path, dir: &Path, found: &mut Vec<String>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            walk(root, &path, found);
        } else {
            found.push(
                path.strip_prefix(root)
                    .unwrap()
                    .to_string_lossy()
                    .into_owned(),
            );
        }
    }
}

#[test]
fn a_flat_sprite_works_too() {
    let tmp = scratch("flat");
    let out = tmp.path().join("kid");
    let stdout = auto(&fixture("autorig-real/kid.png"), &out);
    assert!(stdout.contains("template: humanoid"), "{stdout}");
    let rig = json(&out.join("rig.json"));
    assert_eq!(names(&rig["animations"]), ALL);
    // The sprite is copied into the folder: the output does not depend on the input's place.
    assert_eq!(rig["parts"][0]["image"], "rig.parts/kid.png");
    assert!(out.join("rig.parts/kid.png").is_file());
    assert!(out.join("walk.gif").is_file());
    assert!(out.join("spine/kid.json").is_file());
}

#[test]
fn a_quadruped_walks_on_four_legs() {
    let tmp = scratch("quadruped");
    let out = tmp.path().join("cat");
    let stdout = auto(&fixture("autorig-real/cat.png"), &out);
    assert!(stdout.contains("template: quadruped"), "{stdout}");
    let rig = json(&out.join("rig.json"));
    assert_eq!(names(&rig["animations"]), ALL);
    let summary = json(&out.join("summary.json"));
    for m in summary["motions"].as_array().unwrap() {
        assert!(m["report"]["views"].get("legs").is_some(), "{m}");
    }
    assert!(out.join("walk.gif").is_file());
    assert!(out.join("spine/cat.json").is_file());
}

#[test]
fn a_rig_the_library_cannot_drive_gets_no_motion_but_everything_else() {
    let tmp = scratch("none");
    let out = tmp.path().join("fish");
    let stdout = auto(&fixture("autorig-real/fish.png"), &out);
    assert!(stdout.contains("template: none"), "{stdout}");
    assert!(stdout.contains("motions skipped"), "{stdout}");
    let rig = json(&out.join("rig.json"));
    assert!(names(&rig["animations"]).is_empty());
    assert!(out.join("spine/fish.json").is_file());
    assert!(!out.join("walk.gif").exists());
    let summary = json(&out.join("summary.json"));
    assert!(summary["motions"].as_array().unwrap().is_empty());
    assert_eq!(summary["motions_skipped"].as_array().unwrap().len(), 1);
}

#[test]
fn bad_input_writes_nothing() {
    let tmp = scratch("bad");
    let dir = tmp.path();
    let out = dir.join("out");
    assert_bad_input(
        &["auto", s(&dir.join("missing.psd")), "-o", s(&out)],
        "missing.psd",
    );
    let garbage = dir.join("garbage.psd");
    std::fs::write(&garbage, b"8BPS this is not a PSD").unwrap();
    assert_bad_input(&["auto", s(&garbage), "-o", s(&out)], "garbage.psd");
    let png = dir.join("garbage.png");
    std::fs::write(&png, b"not a png").unwrap();
    assert_bad_input(&["auto", s(&png), "-o", s(&out)], "garbage.png");
    assert_bad_input(
        &["auto", s(&png), "-o", s(&dir.join("no/such/folder"))],
        "does not exist",
    );
    // An output that is a file, and a folder of someone else's files.
    assert_bad_input(&["auto", s(&png), "-o", s(&garbage)], "garbage.psd");
    let theirs = dir.join("theirs");
    std::fs::create_dir(&theirs).unwrap();
    std::fs::write(theirs.join("notes.txt"), b"mine").unwrap();
    assert_bad_input(
        &[
            "auto",
            s(&fixture("layered/bundled_character.psd")),
            "-o",
            s(&theirs),
        ],
        "not one sinew auto wrote",
    );
    let mut left: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["garbage.png", "garbage.psd", "theirs"]);
    assert_eq!(
        std::fs::read_dir(&theirs).unwrap().count(),
        1,
        "the foreign folder was touched"
    );
}

#[test]
fn a_rerun_replaces_the_earlier_output_and_a_failed_one_keeps_it() {
    let tmp = scratch("rerun");
    let dir = tmp.path();
    let out = dir.join("out");
    auto(&fixture("autorig-real/kid.png"), &out);
    // The person's own files stay through a rerun.
    std::fs::write(out.join("notes.txt"), b"mine").unwrap();
    std::fs::create_dir(out.join("mine")).unwrap();
    std::fs::write(out.join("mine/a.txt"), b"mine").unwrap();
    let before = std::fs::read(out.join("rig.json")).unwrap();

    // A failed run (garbage art) leaves the folder as it was.
    let png = dir.join("garbage.png");
    std::fs::write(&png, b"not a png").unwrap();
    assert_bad_input(&["auto", s(&png), "-o", s(&out)], "garbage.png");
    assert_eq!(std::fs::read(out.join("rig.json")).unwrap(), before);

    // Another character (one no motion drives) into the same folder: the kid's files are
    // gone, the person's kept.
    auto(&fixture("autorig-real/fish.png"), &out);
    assert!(!out.join("rig.parts/kid.png").exists());
    assert!(!out.join("walk.gif").exists());
    assert!(!out.join("spine/kid.json").exists());
    assert!(out.join("rig.parts/fish.png").is_file());
    assert_eq!(std::fs::read(out.join("notes.txt")).unwrap(), b"mine");
    assert_eq!(std::fs::read(out.join("mine/a.txt")).unwrap(), b"mine");
    let leftovers = std::fs::read_dir(dir).unwrap().count();
    assert_eq!(leftovers, 2, "out and garbage.png only");
}
