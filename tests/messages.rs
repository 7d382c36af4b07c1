//! Every refusal the command line prints, for a corpus of bad inputs across its commands, is
//! in the user's words (issue 44): exit code 2, one line, no Rust syntax (`::` paths,
//! `Some(…)`, `Err(…)`, `Struct { field: … }`, debug-escaped quotes), no name with an
//! underscore the user did not write (a field or flag is named as the file or the command line
//! writes it), and the file the refusal is about named in it.
//!
//! The corpus is built in a scratch folder from `sinew demo`'s output and a few hand-made bad
//! files; each case is one command line and the text its message must contain.

#![cfg(feature = "cli")]

mod command;

use command::{s, scratch, sinew, EXIT_BAD_INPUT};
use std::path::{Path, PathBuf};

/// One bad input: the command line and what its one line must name (a file, a flag, a name,
/// a suggestion: each of `names`).
struct Case {
    args: Vec<String>,
    names: Vec<String>,
}

/// Everything the user wrote or could read for `case`: its arguments, the text of the files
/// they name, and the help of its command (which lists the names it accepts, such as the
/// motion library's `jump_forward`).
fn user_text(case: &Case) -> String {
    let mut text = case.args.join(" ");
    let commands = [
        "rig",
        "pose",
        "render",
        "export",
        "spine",
        "gltf",
        "dragonbones",
    ];
    let more = ["autorig", "animate", "colorize", "batch"];
    let mut help: Vec<&str> = case
        .args
        .iter()
        .map(String::as_str)
        .filter(|a| commands.contains(a) || more.contains(a))
        .take(2)
        .collect();
    help.push("--help");
    text.push(' ');
    text.push_str(&String::from_utf8_lossy(&sinew(&help).stdout));
    for arg in &case.args {
        if let Ok(content) = std::fs::read(arg) {
            text.push(' ');
            text.push_str(&String::from_utf8_lossy(&content));
        }
    }
    text
}

/// What is wrong with `message` (the whole stderr) for `case`, if anything.
fn problems(case: &Case, code: Option<i32>, message: &str) -> Vec<String> {
    let mut found = Vec::new();
    if code != Some(EXIT_BAD_INPUT) {
        found.push(format!("exit code {code:?}, not {EXIT_BAD_INPUT}"));
    }
    let lines: Vec<&str> = message.lines().collect();
    if lines.len() != 1 {
        found.push(format!("{} lines, not one", lines.len()));
    }
    let line = lines.first().copied().unwrap_or("");
    // Rust's own syntax: paths, Option/Result debug output, struct debug output, escapes.
    for token in [
        "::",
        "Some(",
        "None",
        "Ok(",
        "Err(",
        "\\\"",
        "panicked",
        "RUST_BACKTRACE",
    ] {
        if line.contains(token) {
            found.push(format!("Rust syntax '{token}'"));
        }
    }
    let words: Vec<&str> = line
        .split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .filter(|w| !w.is_empty())
        .collect();
    for pair in words.windows(2) {
        // `Name { field` (a struct's debug output).
        let starts_upper = pair[0].chars().next().is_some_and(char::is_uppercase);
        if starts_upper && line.contains(&format!("{} {{ {}", pair[0], pair[1])) {
            found.push(format!("struct debug output '{} {{'", pair[0]));
        }
    }
    let written = user_text(case);
    for word in &words {
        if word.contains('_') && !written.contains(word) {
            found.push(format!("code word '{word}' the user did not write"));
        }
    }
    for name in &case.names {
        if !line.contains(name.as_str()) {
            found.push(format!("does not name '{name}'"));
        }
    }
    found
}

/// The demo's rig (`character.json`) and its folder, made once for the whole corpus.
fn demo(dir: &Path) -> PathBuf {
    let out = dir.join("demo");
    let run = sinew(&["demo", "-o", s(&out)]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    out.join("character.json")
}

/// A PSD header announcing a 4 × 4 RGB image, cut short after it.
fn cut_psd() -> Vec<u8> {
    let mut out = b"8BPS".to_vec();
    out.extend(1u16.to_be_bytes());
    out.extend([0u8; 6]);
    out.extend(3u16.to_be_bytes());
    out.extend(4u32.to_be_bytes());
    out.extend(4u32.to_be_bytes());
    out.extend(8u16.to_be_bytes());
    out.extend(3u16.to_be_bytes());
    out
}

#[test]
fn every_refusal_is_one_line_in_the_users_words_naming_its_file() {
    let tmp = scratch("corpus");
    let dir = tmp.path();
    let rig = demo(dir);
    let part = rig.parent().unwrap().join("character.parts/head.png");
    let part = if part.exists() {
        part
    } else {
        // Wherever the demo put its part images: the first PNG under its parts folder.
        walk_png(&rig.parent().unwrap().join("character.parts")).expect("a part image")
    };
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };
    let text_png = write("notes.png", b"these are notes, not a picture");
    let jpg = write("photo.jpg", b"\xff\xd8\xff\xe0 not really a jpeg");
    let psd = write("cut.psd", &cut_psd());
    let bad_json = write("broken.json", b"{\"bones\": [");
    let handles = write(
        "orphans.json",
        br#"{"bones":[{"name":"arm","parent":"shoulder","head":[1,1],"tail":[9,9]}]}"#,
    );
    let pose = write("wild.json", br#"{"bones":{"head":{"rotate_deg":1e300}}}"#);
    let bvh = write("garbage.bvh", b"HIERARCHY\nROOT hips\n{\n OFFSET 0 0\n");
    let manifest = write("jobs.json", b"[1, 2, 3]");
    let escaping = write(
        "escape.json",
        br#"{"jobs":[{"kind":"rig","name":"r","images":["a.png"],"output":"../out.json"}]}"#,
    );
    let line = write("line.png", &std::fs::read(&part).unwrap());
    let scribbles = write("scribbles.json", b"not json");
    let good_scribbles = write(
        "dots.json",
        br#"{"scribbles":[{"color":[255,0,0],"points":[[2,2],[3,3]]}]}"#,
    );
    let missing = dir.join("missing.png");
    // Issue 45: refusals that say what to do next.
    let kra = write("cat.kra", &krita_head());
    let misspelt = write(
        "misspelt.json",
        br#"{"bones":[{"name":"shoulder","head":[1,1],"tail":[9,9]},
                     {"name":"arm","parent":"sholder","head":[9,9],"tail":[20,20]}]}"#,
    );
    let layer = part.file_stem().unwrap().to_string_lossy().into_owned();
    // The layer's name with its last two letters swapped.
    let mut swapped: Vec<char> = layer.chars().collect();
    let n = swapped.len();
    swapped.swap(n - 1, n - 2);
    let swapped: String = swapped.into_iter().collect();
    let bind = write(
        "bind.json",
        format!(
            r#"{{"bones":[{{"name":"b","head":[1,1],"tail":[9,9]}}],"bind":{{"b":["{swapped}"]}}}}"#
        )
        .as_bytes(),
    );
    let ik = write(
        "ik.json",
        br#"{"bones":[{"name":"upper","head":[1,1],"tail":[9,9]},
                     {"name":"lower","parent":"upper","head":[9,9],"tail":[20,20]},
                     {"name":"goal","head":[30,30],"tail":[31,31]}],
             "ik":[{"name":"reach","bones":["upper","lower"],"target":"gaol"}]}"#,
    );
    // The demo's rig without its animations, beside it (its part images are found).
    let bare = rig.with_file_name("bare.json");
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&rig).unwrap()).unwrap();
    doc.as_object_mut().unwrap().remove("animations");
    doc.as_object_mut().unwrap().remove("events");
    std::fs::write(&bare, doc.to_string()).unwrap();
    let out = |name: &str| dir.join("out").join(name).to_string_lossy().into_owned();
    std::fs::create_dir_all(dir.join("out")).unwrap();
    let case = |args: &[&str], names: &str| Case {
        args: args.iter().map(|a| a.to_string()).collect(),
        names: vec![names.to_string()],
    };
    // A case whose message must name several things (the file and a suggestion, say).
    let naming = |args: &[&str], names: &[&str]| Case {
        args: args.iter().map(|a| a.to_string()).collect(),
        names: names.iter().map(|n| n.to_string()).collect(),
    };
    let name = |p: &Path| p.file_name().unwrap().to_string_lossy().into_owned();
    let cases = vec![
        case(&["rig", s(&missing), "-o", &out("a.json")], &name(&missing)),
        case(
            &["rig", s(&text_png), "-o", &out("a.json")],
            &name(&text_png),
        ),
        case(&["rig", s(&jpg), "-o", &out("a.json")], &name(&jpg)),
        case(&["rig", s(&psd), "-o", &out("a.json")], &name(&psd)),
        case(
            &[
                "rig",
                s(&part),
                "--handles",
                s(&bad_json),
                "-o",
                &out("a.json"),
            ],
            &name(&bad_json),
        ),
        case(
            &[
                "rig",
                s(&part),
                "--handles",
                s(&handles),
                "-o",
                &out("a.json"),
            ],
            "shoulder",
        ),
        case(
            &["rig", s(&part), "--min-angle", "90", "-o", &out("a.json")],
            "--min-angle",
        ),
        case(
            &["autorig", s(&missing), "-o", &out("h.json")],
            &name(&missing),
        ),
        case(
            &["pose", s(&bad_json), "-o", &out("p.png")],
            &name(&bad_json),
        ),
        case(
            &["pose", s(&rig), "--pose", s(&pose), "-o", &out("p.png")],
            &name(&pose),
        ),
        case(
            &["render", s(&rig), "--anim", "moonwalk", "-o", &out("r.gif")],
            "moonwalk",
        ),
        naming(
            &["render", s(&rig), "--anim", "walkk", "-o", &out("r.gif")],
            &[&name(&rig), "did you mean 'walk'?"],
        ),
        naming(
            &["render", s(&bare), "--anim", "walk", "-o", &out("r.gif")],
            &[
                &name(&bare),
                "sinew animate",
                "--motion walk",
                "--mode animate",
            ],
        ),
        naming(
            &[
                "render",
                s(&rig),
                "--anim",
                "walk",
                "--skin",
                "pails",
                "-o",
                &out("r.gif"),
            ],
            &[&name(&rig), "did you mean 'pail'?"],
        ),
        naming(
            &["pose", s(&rig), "--skin", "pails", "-o", &out("p.png")],
            &["did you mean 'pail'?"],
        ),
        naming(
            &["rig", s(&jpg), "-o", &out("a.json")],
            &[&name(&jpg), "JPEG", "PSD, PSB or OpenRaster (.ora)"],
        ),
        naming(
            &["rig", s(&kra), "-o", &out("a.json")],
            &[&name(&kra), "Krita", "OpenRaster (.ora)", "File ▸ Export"],
        ),
        naming(
            &[
                "rig",
                s(&part),
                "--handles",
                s(&misspelt),
                "-o",
                &out("a.json"),
            ],
            &[&name(&misspelt), "did you mean 'shoulder'?"],
        ),
        naming(
            &["rig", s(&part), "--handles", s(&bind), "-o", &out("a.json")],
            &[&name(&bind), &format!("did you mean '{layer}'?")],
        ),
        naming(
            &["rig", s(&part), "--handles", s(&ik), "-o", &out("a.json")],
            &[&name(&ik), "did you mean 'goal'?"],
        ),
        naming(
            &[
                "rig",
                s(&part),
                "--attachment",
                &format!("{swapped}={layer}"),
                "-o",
                &out("a.json"),
            ],
            &["--attachment", &format!("did you mean '{layer}'?")],
        ),
        naming(
            &["animate", s(&rig), "--motion", "wlak"],
            &["--motion", "did you mean 'walk'?"],
        ),
        case(
            &[
                "render",
                s(&rig),
                "--anim",
                "walk",
                "--fps",
                "0",
                "-o",
                &out("r.gif"),
            ],
            "frame rate",
        ),
        case(
            &[
                "render",
                s(&rig),
                "--anim",
                "walk",
                "--size",
                "0x0",
                "-o",
                &out("r.gif"),
            ],
            "--size",
        ),
        case(
            &[
                "render",
                s(&rig),
                "--anim",
                "walk",
                "--scale",
                "1e9",
                "-o",
                &out("r.gif"),
            ],
            "scale",
        ),
        case(
            &["export", "spine", s(&missing), "-o", &out("spine")],
            &name(&missing),
        ),
        case(
            &[
                "export",
                "spine",
                s(&rig),
                "--spine-version",
                "9.9",
                "-o",
                &out("spine"),
            ],
            "9.9",
        ),
        case(&["animate", s(&rig), "--motion", "moonwalk"], "moonwalk"),
        case(
            &[
                "animate",
                s(&rig),
                "--motion",
                s(&bvh),
                "-o",
                &out("m.json"),
            ],
            &name(&bvh),
        ),
        case(
            &[
                "colorize",
                s(&line),
                "--scribbles",
                s(&good_scribbles),
                "--join-curve",
                "1e9",
                "-o",
                &out("c.png"),
            ],
            "--join-curve",
        ),
        case(
            &[
                "colorize",
                s(&line),
                "--scribbles",
                s(&scribbles),
                "-o",
                &out("c.png"),
            ],
            &name(&scribbles),
        ),
        case(&["batch", s(&manifest)], &name(&manifest)),
        case(&["batch", s(&escaping)], &name(&escaping)),
        case(
            &[
                "--memory-budget",
                "12",
                "render",
                s(&rig),
                "--anim",
                "walk",
                "-o",
                &out("r.gif"),
            ],
            "--memory-budget",
        ),
    ];
    let mut report = Vec::new();
    for case in &cases {
        let args: Vec<&str> = case.args.iter().map(String::as_str).collect();
        let run = sinew(&args);
        let message = String::from_utf8_lossy(&run.stderr).into_owned();
        let found = problems(case, run.status.code(), &message);
        if !found.is_empty() {
            report.push(format!(
                "sinew {}\n    {}\n    -> {}",
                case.args.join(" "),
                message.trim_end().replace('\n', "\n    "),
                found.join("; ")
            ));
        }
    }
    assert!(
        report.is_empty(),
        "{} of {} refusals are not in the user's words:\n{}",
        report.len(),
        cases.len(),
        report.join("\n")
    );
    // Nothing was written by any of them.
    assert_eq!(std::fs::read_dir(dir.join("out")).unwrap().count(), 0);
}

/// The checks themselves: each kind of code talk is caught.
#[test]
fn code_talk_is_caught() {
    let case = Case {
        args: vec!["rig".into(), "a.png".into()],
        names: vec!["a.png".into()],
    };
    let bad = [
        "sinew: error: a.png: limit exceeded (LayeredLimits::max_side_px)",
        "sinew: error: a.png: got Some(3)",
        "sinew: error: a.png: Malformed { reason: \"x\" }",
        "sinew: error: a.png: \\\"quoted\\\"",
        "sinew: error: a.png: max_side_px must be positive",
        "sinew: error: limit exceeded",
        "sinew: error: a.png: one\nand two lines",
    ];
    for message in bad {
        assert!(
            !problems(&case, Some(EXIT_BAD_INPUT), message).is_empty(),
            "{message}"
        );
    }
    assert!(!problems(&case, Some(1), "sinew: error: a.png: not a PNG").is_empty());
    assert_eq!(
        problems(
            &case,
            Some(EXIT_BAD_INPUT),
            "sinew: error: a.png: not a PNG image"
        ),
        Vec::<String>::new()
    );
}

/// The start of a Krita document: a zip whose first entry, stored, is `mimetype` saying
/// `application/x-krita`.
fn krita_head() -> Vec<u8> {
    let content = b"application/x-krita";
    let mut out = b"PK\x03\x04".to_vec();
    out.extend([20, 0, 0, 0, 0, 0]); // version, flags, method 0 (stored)
    out.extend([0u8; 8]); // time, date, CRC
    out.extend((content.len() as u32).to_le_bytes());
    out.extend((content.len() as u32).to_le_bytes());
    out.extend(8u16.to_le_bytes());
    out.extend(0u16.to_le_bytes());
    out.extend(b"mimetype");
    out.extend(content);
    out
}

fn walk_png(dir: &Path) -> Option<PathBuf> {
    for entry in std::fs::read_dir(dir).ok()?.flatten() {
        let p = entry.path();
        if p.is_dir() {
            if let Some(found) = walk_png(&p) {
                return Some(found);
            }
        } else if p.extension().is_some_and(|e| e == "png") {
            return Some(p);
        }
    }
    None
}
