//! Every command of the user guide (`docs/guide/`, issue 45) runs, so the guide cannot rot.
//!
//! The chapters are read in the order of `docs/guide/src/SUMMARY.md`, and their fenced blocks
//! in order, in one scratch folder seeded with the bundled assets under the names the guide's
//! introduction lists (`character/`, `art.psd`, `krita.ora`, `take.bvh`, `lineart.png`,
//! `scribbles.json`):
//!
//! - ```` ```sh ````: each line (`\` continues it; `#` starts a comment) that starts with `sinew`
//!   runs the binary built with this test in that folder; it must exit with 0, and every output
//!   it names (`-o`, `--output`, `--preview`, `--vertices`, `--layers`, `> FILE`) must exist
//!   afterwards. A line that starts with `cargo`, `tools/` or `NAME=value cargo` is a development
//!   command (not run); a line ending in the comment `# not run: REASON` is skipped with its
//!   reason; any other line fails the test, so a typo cannot hide a command.
//! - ```` ```console ````: each `$ sinew …` line runs the same way and must fail with exit code
//!   2 and exactly the lines below it (up to the next `$`) on stderr.
//! - ```` ```json NAME ````: the block is written to `NAME` in the folder (a manifest the
//!   commands after it read).
//! - Other blocks (```` ```text ````: synopses, commands that need a display or a cluster) are
//!   not run; the chapters say how those are checked.
//!
//! Every failure is collected and reported at the end with its chapter and line. The run takes
//! about a minute in the test profile on two cores (each command's time is printed with
//! `--nocapture`); keep the guide's examples small (`--fps`, `--size`, `--render-size`) when
//! one would be slow, and show the command that runs.
#![cfg(feature = "cli")]

mod command;

use command::scratch;
use serde_json::json;
use sinew::colorize::synthetic::{scene, SceneSpec};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// A fenced block of a chapter: its info string, body and the line of its opening fence.
struct Block {
    info: String,
    body: String,
    line: usize,
}

/// The chapters listed in `SUMMARY.md`, in order.
fn chapters() -> Vec<PathBuf> {
    let src = Path::new(ROOT).join("docs/guide/src");
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).unwrap();
    let mut out = Vec::new();
    for piece in summary.split("](").skip(1) {
        let target = piece.split(')').next().unwrap();
        if target.ends_with(".md") {
            out.push(src.join(target));
        }
    }
    out
}

/// The fenced blocks of a Markdown text (fences of three backticks at the start of a line).
fn blocks(text: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for (k, line) in text.lines().enumerate() {
        match open.as_mut() {
            None => {
                if let Some(info) = line.strip_prefix("```") {
                    open = Some(Block {
                        info: info.trim().to_string(),
                        body: String::new(),
                        line: k + 1,
                    });
                }
            }
            Some(block) => {
                if line.trim_end() == "```" {
                    out.push(open.take().unwrap());
                } else {
                    block.body.push_str(line);
                    block.body.push('\n');
                }
            }
        }
    }
    assert!(open.is_none(), "an unclosed fenced block");
    out
}

/// A command line split into words as a POSIX shell does for the guide's simple commands:
/// single and double quotes, backslash escapes, `#` at the start of a word begins a comment.
/// Returns the words and the comment.
fn words(line: &str) -> (Vec<String>, String) {
    let mut words = Vec::new();
    let mut word = String::new();
    let mut in_word = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\'' => {
                in_word = true;
                for c in chars.by_ref() {
                    if c == '\'' {
                        break;
                    }
                    word.push(c);
                }
            }
            '"' => {
                in_word = true;
                while let Some(c) = chars.next() {
                    match c {
                        '"' => break,
                        '\\' => word.extend(chars.next()),
                        c => word.push(c),
                    }
                }
            }
            '\\' => {
                in_word = true;
                word.extend(chars.next());
            }
            '#' if !in_word => return (words, chars.collect::<String>().trim().to_string()),
            c if c.is_whitespace() => {
                if in_word {
                    words.push(std::mem::take(&mut word));
                    in_word = false;
                }
            }
            c => {
                in_word = true;
                word.push(c);
            }
        }
    }
    if in_word {
        words.push(word);
    }
    (words, String::new())
}

/// The lines of a `sh` block with `\`-continuations joined, each with its line in the block.
fn joined_lines(body: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut current: Option<(usize, String)> = None;
    for (k, line) in body.lines().enumerate() {
        let (start, mut text) = current.take().unwrap_or((k, String::new()));
        if let Some(head) = line.trim_end().strip_suffix('\\') {
            text.push_str(head);
            text.push(' ');
            current = Some((start, text));
        } else {
            text.push_str(line);
            out.push((start, text));
        }
    }
    out.extend(current);
    out
}

/// The bundled assets, under the names the guide's introduction gives them.
fn seed(dir: &Path) {
    copy_tree(
        &Path::new(ROOT).join("assets/character"),
        &dir.join("character"),
    );
    let fixtures = Path::new(ROOT).join("tests/fixtures/layered");
    std::fs::copy(fixtures.join("bundled_character.psd"), dir.join("art.psd")).unwrap();
    std::fs::copy(fixtures.join("krita.ora"), dir.join("krita.ora")).unwrap();
    std::fs::copy(
        Path::new(ROOT).join("assets/motions/walk.bvh"),
        dir.join("take.bvh"),
    )
    .unwrap();
    let drawing = scene(&SceneSpec::default());
    sinew::io::save_png(&dir.join("lineart.png"), &drawing.lineart).unwrap();
    std::fs::write(
        dir.join("scribbles.json"),
        json!({ "strokes": drawing.strokes }).to_string(),
    )
    .unwrap();
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        let dest = to.join(path.file_name().unwrap());
        if path.is_dir() {
            copy_tree(&path, &dest);
        } else {
            std::fs::copy(&path, &dest).unwrap();
        }
    }
}

/// The outputs a command names: the values of its output flags and a `>` redirection.
fn outputs(args: &[String]) -> Vec<String> {
    let mut out = Vec::new();
    for pair in args.windows(2) {
        let flag = pair[0].as_str();
        if matches!(
            flag,
            "-o" | "--output" | "--preview" | "--vertices" | "--layers" | ">"
        ) {
            out.push(pair[1].clone());
        }
    }
    out
}

/// Runs `sinew ARGS` (with a `> FILE` redirection taken off) in `dir`; returns the exit code
/// and stderr, and writes stdout to the redirection's file.
fn run(dir: &Path, args: &[String]) -> (Option<i32>, String) {
    let (args, redirect) = match args.iter().position(|a| a == ">") {
        Some(k) => (&args[..k], args.get(k + 1)),
        None => (args, None),
    };
    let out = Command::new(env!("CARGO_BIN_EXE_sinew"))
        .args(&args[1..])
        .current_dir(dir)
        .env_remove("SINEW_MEMORY_BUDGET")
        .env_remove("RAYON_NUM_THREADS")
        .output()
        .expect("run sinew");
    if let Some(file) = redirect {
        std::fs::write(dir.join(file), &out.stdout).unwrap();
    }
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// What one pass over the guide did.
#[derive(Default)]
struct Report {
    run: usize,
    errors_checked: usize,
    skipped: Vec<String>,
    failures: Vec<String>,
}

fn run_sh(dir: &Path, at: &str, block: &Block, report: &mut Report) {
    for (k, line) in joined_lines(&block.body) {
        let (args, comment) = words(&line);
        let where_ = format!("{at}:{}", block.line + 1 + k);
        let Some(first) = args.first() else { continue };
        if let Some(reason) = comment.strip_prefix("not run:") {
            assert!(
                !reason.trim().is_empty(),
                "{where_}: `# not run:` needs a reason"
            );
            report
                .skipped
                .push(format!("{where_}: {line} ({})", reason.trim()));
            continue;
        }
        let development = first == "cargo"
            || first.starts_with("tools/")
            || (first.contains('=') && args.get(1).is_some_and(|a| a == "cargo"));
        if development {
            report.skipped.push(format!("{where_}: {}", line.trim()));
            continue;
        }
        if first != "sinew" {
            report.failures.push(format!(
                "{where_}: `{}`: a sh line that is neither a sinew command nor a development \
                 command (cargo, tools/); put it in a text block or mark it `# not run: why`",
                line.trim()
            ));
            continue;
        }
        let start = Instant::now();
        let (code, stderr) = run(dir, &args);
        report.run += 1;
        eprintln!(
            "guide: {where_}: {:.1} s: {}",
            start.elapsed().as_secs_f64(),
            args.join(" ")
        );
        if code != Some(0) {
            report.failures.push(format!(
                "{where_}: `{}` exited with {code:?}: {}",
                args.join(" "),
                stderr.trim()
            ));
            continue;
        }
        for output in outputs(&args) {
            if !dir.join(&output).exists() {
                report.failures.push(format!(
                    "{where_}: `{}` succeeded but wrote no {output}",
                    args.join(" ")
                ));
            }
        }
    }
}

fn run_console(dir: &Path, at: &str, block: &Block, report: &mut Report) {
    let lines: Vec<&str> = block.body.lines().collect();
    let mut k = 0;
    while k < lines.len() {
        let Some(command) = lines[k].strip_prefix("$ ") else {
            report.failures.push(format!(
                "{at}:{}: a console block's line that follows no `$ ` command: {}",
                block.line + 1 + k,
                lines[k]
            ));
            k += 1;
            continue;
        };
        let where_ = format!("{at}:{}", block.line + 1 + k);
        let mut expected = Vec::new();
        k += 1;
        while k < lines.len() && !lines[k].starts_with("$ ") {
            expected.push(lines[k]);
            k += 1;
        }
        let (args, _) = words(command);
        if args.first().map(String::as_str) != Some("sinew") {
            report.failures.push(format!(
                "{where_}: a console command that is not sinew's: {command}"
            ));
            continue;
        }
        let (code, stderr) = run(dir, &args);
        report.run += 1;
        report.errors_checked += 1;
        let expected = expected.join("\n");
        if code != Some(2) || stderr.trim_end() != expected.trim_end() {
            report.failures.push(format!(
                "{where_}: `{command}` should fail with exit code 2 and\n    {expected}\n  \
                 it exited with {code:?} and printed\n    {}",
                stderr.trim_end()
            ));
        }
    }
}

#[test]
fn every_command_of_the_guide_runs() {
    let dir = scratch("guide");
    seed(dir.path());
    let start = Instant::now();
    let mut report = Report::default();
    let chapters = chapters();
    assert!(chapters.len() >= 10, "SUMMARY.md lists {chapters:?}");
    for chapter in &chapters {
        let name = chapter.strip_prefix(ROOT).unwrap().display().to_string();
        let name = name.trim_start_matches('/');
        let text = std::fs::read_to_string(chapter).unwrap_or_else(|e| panic!("{name}: {e}"));
        for block in blocks(&text) {
            let mut info = block.info.split_whitespace();
            match (info.next(), info.next()) {
                (Some("sh"), None) => run_sh(dir.path(), name, &block, &mut report),
                (Some("console"), None) => run_console(dir.path(), name, &block, &mut report),
                (Some("json"), Some(file)) => {
                    std::fs::write(dir.path().join(file), &block.body).unwrap()
                }
                _ => {}
            }
        }
    }
    eprintln!(
        "guide: {} commands run ({} of them errors checked) in {:.1} s; not run here:\n  {}",
        report.run,
        report.errors_checked,
        start.elapsed().as_secs_f64(),
        report.skipped.join("\n  ")
    );
    assert!(
        report.failures.is_empty(),
        "{} of the guide's commands failed (a message or an option changed on purpose: update \
         the chapter, it is what users read):\n{}",
        report.failures.len(),
        report.failures.join("\n")
    );
    // The guide keeps its examples: a parse that found none would pass vacuously.
    assert!(report.run >= 40, "only {} commands found", report.run);
    assert!(report.errors_checked >= 10, "{}", report.errors_checked);
}

#[test]
fn command_lines_split_as_a_shell_splits_them() {
    let (w, c) = words(r#"sinew render a.json --background '#ffffffff' -o "x y.gif" # a comment"#);
    assert_eq!(
        w,
        [
            "sinew",
            "render",
            "a.json",
            "--background",
            "#ffffffff",
            "-o",
            "x y.gif"
        ]
    );
    assert_eq!(c, "a comment");
    let (w, c) = words("sinew edit rig.json   # not run: needs a display");
    assert_eq!(w, ["sinew", "edit", "rig.json"]);
    assert_eq!(c, "not run: needs a display");
    assert_eq!(
        joined_lines("sinew a \\\n    b\nsinew c\n"),
        [
            (0, "sinew a      b".to_string()),
            (2, "sinew c".to_string())
        ]
    );
    assert_eq!(
        outputs(&["sinew", "schema", "rig", ">", "r.json"].map(String::from)),
        ["r.json"]
    );
}
