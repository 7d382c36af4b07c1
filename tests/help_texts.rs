//! Every help text the command line prints (issue 45, item 5): `sinew --help` and the long
//! help of every command and subcommand, found by walking their "Commands:" lists, and every
//! description in `sinew schema KIND`'s JSON Schemas. Each must be free of rustdoc syntax
//! (`` [`name`] ``, `[text](path)`, `::` paths), of absolute paths (a build machine's
//! folders), and of dead references: a `sinew WORD` names a command that exists, a
//! `docs/FILE.md` exists, and its `"Section"` is one of that file's headings. Every command
//! has a one-line summary of at most 80 characters and at least one example.

#![cfg(feature = "cli")]

mod command;

use command::sinew;
use std::collections::BTreeMap;
use std::path::Path;

/// The longest one-line summary a command may have, characters.
const SUMMARY_CHARS: usize = 80;

/// The long help of `sinew PATH... --help`, checked to succeed.
fn long_help(path: &[String]) -> String {
    let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
    args.push("--help");
    let out = sinew(&args);
    assert!(out.status.success(), "sinew {} failed", args.join(" "));
    String::from_utf8(out.stdout).expect("help is UTF-8")
}

/// The commands a help text lists under "Commands:" (without `help`).
fn listed_commands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| l.trim() != "Commands:")
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect()
}

/// Every command path (`[]` for `sinew` itself, `["export", "spine"]`, ...) and its long help.
fn all_helps() -> BTreeMap<Vec<String>, String> {
    let mut found = BTreeMap::new();
    let mut queue = vec![Vec::<String>::new()];
    while let Some(path) = queue.pop() {
        let help = long_help(&path);
        for name in listed_commands(&help) {
            let mut child = path.clone();
            child.push(name);
            queue.push(child);
        }
        found.insert(path, help);
    }
    found
}

/// The headings of a markdown file, without their `#`s.
fn headings(markdown: &str) -> Vec<String> {
    markdown
        .lines()
        .filter(|l| l.starts_with('#'))
        .map(|l| l.trim_start_matches('#').trim().to_string())
        .collect()
}

/// What is wrong in `text` (a help or a schema description), given every command path.
fn problems(text: &str, commands: &BTreeMap<Vec<String>, String>) -> Vec<String> {
    let mut found = Vec::new();
    for syntax in ["[`", "`]", "](", "::"] {
        if text.contains(syntax) {
            found.push(format!("rustdoc syntax {syntax:?}"));
        }
    }
    for folder in ["/work/", "/home/", "/root/", "/tmp/", "/Users/", "C:\\"] {
        if text.contains(folder) {
            found.push(format!("an absolute path ({folder})"));
        }
    }
    // `` `sinew WORD ...` `` in code quotes (what a reader would type): WORD is a command.
    for quoted in text.split('`').skip(1).step_by(2) {
        let mut words = quoted.split_whitespace();
        if words.next() != Some("sinew") {
            continue;
        }
        let Some(next) = words.next() else { continue };
        let looks_like_command =
            next.chars().all(|c| c.is_ascii_lowercase() || c == '-') && !next.starts_with('-');
        if looks_like_command && next != "help" && !commands.contains_key(&vec![next.to_string()]) {
            found.push(format!("'sinew {next}' is no command"));
        }
    }
    // docs/FILE.md and, when a quoted section follows it, that section.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let flat = text.split_whitespace().collect::<Vec<_>>().join(" ");
    for (at, _) in flat.match_indices("docs/") {
        let rest = &flat[at..];
        let Some(end) = rest.find(".md") else {
            continue;
        };
        let file = &rest[..end + 3];
        let Ok(markdown) = std::fs::read_to_string(root.join(file)) else {
            found.push(format!("{file} does not exist"));
            continue;
        };
        let after = rest[end + 3..].trim_start_matches([',', ' ']);
        if let Some(quoted) = after.strip_prefix('"') {
            let section = quoted.split('"').next().unwrap_or_default();
            if !headings(&markdown).iter().any(|h| h.contains(section)) {
                found.push(format!("{file} has no section \"{section}\""));
            }
        }
    }
    found
}

#[test]
fn every_help_text_is_clean_and_has_a_summary_and_an_example() {
    let helps = all_helps();
    assert!(
        helps.len() > 15,
        "found only {} commands: {:?}",
        helps.len(),
        helps.keys().collect::<Vec<_>>()
    );
    let mut failures = Vec::new();
    for (path, help) in &helps {
        let name = format!("sinew {}", path.join(" "));
        for problem in problems(help, &helps) {
            failures.push(format!("{name}: {problem}"));
        }
        let summary = help.lines().next().unwrap_or_default();
        if summary.is_empty() || summary.chars().count() > SUMMARY_CHARS {
            failures.push(format!(
                "{name}: the summary is not one line of at most {SUMMARY_CHARS} characters: {summary:?}"
            ));
        }
        // Groups (`sinew`, `sinew export`) list commands; every command shows how to run it.
        if !help.contains("Examples:") {
            failures.push(format!("{name}: no examples"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_example_names_a_command_that_exists() {
    let helps = all_helps();
    let mut failures = Vec::new();
    for (path, help) in &helps {
        let examples = help
            .lines()
            .skip_while(|l| l.trim() != "Examples:")
            .skip(1)
            .filter(|l| l.trim_start().starts_with("sinew "));
        for example in examples {
            let words: Vec<&str> = example.split_whitespace().skip(1).collect();
            // The longest command path the example starts with.
            let mut command: Vec<String> = Vec::new();
            for word in &words {
                let mut longer = command.clone();
                longer.push(word.to_string());
                if helps.contains_key(&longer) {
                    command = longer;
                } else {
                    break;
                }
            }
            if command.is_empty() && words.first() != Some(&"help") {
                failures.push(format!(
                    "sinew {}: example names no command: {example}",
                    path.join(" ")
                ));
                continue;
            }
            // Every --flag it uses is one its command's help lists.
            let Some(own) = helps.get(&command) else {
                continue;
            };
            for flag in words.iter().filter(|w| w.starts_with("--")) {
                let flag = flag.split('=').next().unwrap_or(flag);
                if !own.contains(&format!("{flag} ")) && !own.contains(&format!("{flag}\n")) {
                    failures.push(format!(
                        "sinew {}: example uses {flag}, which sinew {} does not take: {example}",
                        path.join(" "),
                        command.join(" ")
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn schema_descriptions_are_clean() {
    let helps = all_helps();
    let kinds_help = long_help(&["schema".to_string()]);
    // The kinds are the possible values `sinew schema --help` lists.
    let kinds: Vec<String> = kinds_help
        .lines()
        .filter_map(|l| l.trim().strip_prefix("- "))
        .filter_map(|l| l.split(':').next())
        .map(|k| k.trim().to_string())
        .collect();
    assert!(kinds.len() >= 4, "schema kinds not found in: {kinds_help}");
    let mut failures = Vec::new();
    for kind in &kinds {
        let out = sinew(&["schema", kind]);
        assert!(out.status.success(), "sinew schema {kind} failed");
        let schema: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let mut descriptions = Vec::new();
        collect_descriptions(&schema, &mut descriptions);
        assert!(!descriptions.is_empty(), "{kind}: no descriptions");
        for text in descriptions {
            for problem in problems(&text, &helps) {
                failures.push(format!("schema {kind}: {problem}: {text:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Every `description` string in a JSON Schema.
fn collect_descriptions(value: &serde_json::Value, into: &mut Vec<String>) {
    match value {
        serde_json::Value::Object(map) => {
            for (key, value) in map {
                match (key.as_str(), value) {
                    ("description", serde_json::Value::String(text)) => into.push(text.clone()),
                    _ => collect_descriptions(value, into),
                }
            }
        }
        serde_json::Value::Array(items) => {
            for item in items {
                collect_descriptions(item, into);
            }
        }
        _ => {}
    }
}

#[test]
fn the_checks_find_what_they_look_for() {
    let mut helps = BTreeMap::new();
    helps.insert(vec!["rig".to_string()], String::new());
    let bad = "See [`super::bone_ik`] and [the guide](docs/guide.md); run `sinew spine`; \
               /work/main/assets; docs/nothing.md; docs/formats.md, \"No such section\".";
    let found = problems(bad, &helps);
    for expected in [
        "rustdoc syntax \"[`\"",
        "rustdoc syntax \"](\"",
        "rustdoc syntax \"::\"",
        "an absolute path (/work/)",
        "'sinew spine' is no command",
        "docs/nothing.md does not exist",
        "docs/formats.md has no section \"No such section\"",
    ] {
        assert!(
            found.iter().any(|f| f == expected),
            "{expected} not in {found:?}"
        );
    }
    let good = "Run `sinew rig art.png -o rig.json`; see docs/formats.md, \"Handles file\".";
    assert_eq!(problems(good, &helps), Vec::<String>::new());
}
