//! The installed binary stands alone (issue 45, item 4): a copy of `sinew` in a temporary
//! folder, run from another temporary folder with a bare environment and **the checkout out of
//! reach**, runs `sinew demo` (its character is built in) and starts a Ray batch's driver (the
//! driver is built in, the Python is `python3` from PATH), and no default or message of the
//! binary names the checkout.
//!
//! "Out of reach": the command runs in a mount namespace of its own (`unshare --user
//! --map-root-user --mount`) in which an empty tmpfs is mounted over the checkout, so the checkout
//! is gone for that process only (other tests, running in parallel, still see it); and it runs
//! under `strace -f -e trace=file`, whose log must name no path in the checkout (an attempt that
//! failed counts too). Each is used where the machine has it (CI's has both), and at least one
//! must be there.

mod command;

use command::{s, scratch};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The checkout the test binary was built from, which the installed copy must never touch.
const CHECKOUT: &str = env!("CARGO_MANIFEST_DIR");

/// A program on this machine's PATH, if there is one.
fn which(program: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(program))
        .find(|p| p.is_file())
}

/// Whether this machine can hide the checkout in a private mount namespace.
fn can_hide_checkout(unshare: &Path) -> bool {
    Command::new(unshare)
        .args([
            "--user",
            "--map-root-user",
            "--mount",
            "--propagation",
            "private",
        ])
        .args(["sh", "-c", "mount -t tmpfs none \"$1\"", "sh", CHECKOUT])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// What a run out of reach of the checkout gave: its output and the file paths it named.
struct Run {
    output: Output,
    /// Every path in strace's log (`None`: strace is not on this machine).
    traced: Option<Vec<String>>,
    /// Whether the checkout was hidden from it.
    hidden: bool,
}

/// Runs `program args` in `cwd` with only `PATH` (= `path`) in its environment, the checkout
/// hidden and the file calls traced where the machine can (at least one of the two).
fn run_out_of_reach(program: &Path, args: &[&str], cwd: &Path, path: &str) -> Run {
    assert!(
        !cwd.starts_with(CHECKOUT) && !program.starts_with(CHECKOUT),
        "the scratch folder is inside the checkout: set TMPDIR elsewhere"
    );
    let unshare = which("unshare").filter(|u| can_hide_checkout(u));
    let strace = which("strace");
    assert!(
        unshare.is_some() || strace.is_some(),
        "neither `unshare` (with user namespaces) nor `strace` is on this machine: the test \
         needs one to keep the binary away from the checkout (apt install util-linux strace)"
    );
    let log = cwd.join("strace.log");
    let mut line: Vec<String> = Vec::new();
    if let Some(strace) = &strace {
        line.extend([
            s(strace).into(),
            "-f".into(),
            "-qq".into(),
            "-e".into(),
            "trace=file".into(),
            "-o".into(),
            s(&log).into(),
        ]);
    }
    line.push(s(program).into());
    line.extend(args.iter().map(|a| a.to_string()));
    let mut command = match &unshare {
        Some(unshare) => {
            let mut c = Command::new(unshare);
            c.args([
                "--user",
                "--map-root-user",
                "--mount",
                "--propagation",
                "private",
            ])
            .args([
                "sh",
                "-c",
                "mount -t tmpfs none \"$1\" && shift && exec \"$@\"",
                "sh",
                CHECKOUT,
            ])
            .args(&line);
            c
        }
        None => {
            let mut c = Command::new(&line[0]);
            c.args(&line[1..]);
            c
        }
    };
    let output = command
        .current_dir(cwd)
        .env_clear()
        .env("PATH", path)
        .output()
        .expect("run the installed sinew");
    let traced = strace.map(|_| {
        let text = std::fs::read_to_string(&log).expect("strace's log");
        std::fs::remove_file(&log).unwrap();
        quoted_strings(&text)
    });
    Run {
        output,
        traced,
        hidden: unshare.is_some(),
    }
}

/// The double-quoted strings of strace's log (the paths of its file calls).
fn quoted_strings(log: &str) -> Vec<String> {
    let mut found = Vec::new();
    for line in log.lines() {
        let mut rest = line;
        while let Some(start) = rest.find('"') {
            let after = &rest[start + 1..];
            let Some(end) = after.find('"') else { break };
            found.push(after[..end].to_string());
            rest = &after[end + 1..];
        }
    }
    found
}

/// Asserts the run touched nothing in the checkout (per strace) and was hidden from it or
/// traced.
fn assert_never_named_the_checkout(run: &Run, what: &str) {
    assert!(run.hidden || run.traced.is_some());
    if let Some(paths) = &run.traced {
        let inside: Vec<&String> = paths
            .iter()
            .filter(|p| Path::new(p).starts_with(CHECKOUT))
            .collect();
        assert!(
            inside.is_empty(),
            "{what} named files of the checkout: {inside:?}"
        );
        // The trace is real: it saw the binary start.
        assert!(paths.iter().any(|p| p.ends_with("/bin/sinew")), "{paths:?}");
    }
}

/// The built binary copied to `dir/bin/sinew`, as `cargo install` or a package would put it.
fn install(dir: &Path) -> PathBuf {
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let installed = bin.join("sinew");
    std::fs::copy(env!("CARGO_BIN_EXE_sinew"), &installed).unwrap();
    installed
}

/// Every file under `dir`, recursively.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files.extend(files_under(&path));
        } else {
            files.push(path);
        }
    }
    files
}

/// Whether `needle` occurs in `haystack`.
fn contains(haystack: &[u8], needle: &[u8]) -> bool {
    let Some((&first, rest)) = needle.split_first() else {
        return true;
    };
    haystack
        .iter()
        .enumerate()
        .filter(|&(_, &b)| b == first)
        .any(|(i, _)| haystack[i + 1..].starts_with(rest))
}

#[test]
fn the_installed_binary_runs_the_demo_with_the_checkout_out_of_reach() {
    let tmp = scratch("demo");
    let dir = tmp.path();
    let sinew = install(dir);
    let work = dir.join("work");
    std::fs::create_dir_all(&work).unwrap();
    let run = run_out_of_reach(&sinew, &["demo", "-o", "out"], &work, "/usr/bin:/bin");
    let stdout = String::from_utf8_lossy(&run.output.stdout);
    let stderr = String::from_utf8_lossy(&run.output.stderr);
    assert!(
        run.output.status.success(),
        "sinew demo failed out of reach of the checkout:\n{stdout}\n{stderr}"
    );
    assert_never_named_the_checkout(&run, "sinew demo");
    assert!(
        !stdout.contains(CHECKOUT) && !stderr.contains(CHECKOUT),
        "{stdout}\n{stderr}"
    );

    // Its outputs: the rig, the renders, the Spine export, and the built-in character's
    // layers, which are the bundled ones byte for byte.
    let out = work.join("out");
    for file in [
        "character.json",
        "rest.png",
        "walk.gif",
        "wave.png",
        "spine/character.json",
    ] {
        assert!(out.join(file).is_file(), "no {file}");
    }
    let parts = out.join("character.parts");
    let layers: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(Path::new(CHECKOUT).join("assets/character/layers.json")).unwrap(),
    )
    .unwrap();
    let names: Vec<String> = layers["layers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap().to_string())
        .chain(layers["attachments"].as_object().unwrap().keys().cloned())
        .collect();
    assert_eq!(std::fs::read_dir(&parts).unwrap().count(), names.len());
    for name in &names {
        let file = format!("{name}.png");
        let bundled = std::fs::read(Path::new(CHECKOUT).join("assets/character").join(&file));
        assert!(
            std::fs::read(parts.join(&file)).unwrap() == bundled.unwrap(),
            "{file} differs from assets/character's"
        );
    }
    // No file it wrote names the checkout.
    for file in files_under(&out) {
        let bytes = std::fs::read(&file).unwrap();
        assert!(
            !contains(&bytes, CHECKOUT.as_bytes()),
            "{} names the checkout",
            file.display()
        );
    }
}

#[test]
fn the_installed_binary_starts_its_built_in_ray_driver_with_python3_from_path() {
    let tmp = scratch("ray");
    let dir = tmp.path();
    let sinew = install(dir);
    let work = dir.join("work");
    std::fs::create_dir_all(work.join("in")).unwrap();
    image::RgbaImage::from_pixel(16, 16, image::Rgba([200, 40, 40, 255]))
        .save(work.join("in/part.png"))
        .unwrap();
    std::fs::write(
        work.join("batch.json"),
        r#"{"jobs": [{"kind": "rig", "name": "part", "inputs": {"images": ["in/part.png"]},
            "outputs": {"rig": "out/part.json"}}]}"#,
    )
    .unwrap();
    // A `python3` first on PATH that keeps the script it is given and its arguments, then
    // stops as a Python without ray would.
    let fake = dir.join("fakebin");
    std::fs::create_dir_all(&fake).unwrap();
    let kept = dir.join("kept");
    std::fs::create_dir_all(&kept).unwrap();
    let python = fake.join("python3");
    std::fs::write(
        &python,
        format!(
            "#!/bin/sh\ncp \"$1\" '{k}/driver.py'\nprintf '%s\\n' \"$@\" > '{k}/args'\n\
             echo \"ModuleNotFoundError: No module named 'ray'\" >&2\nexit 1\n",
            k = kept.display()
        ),
    )
    .unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&python, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let path = format!("{}:/usr/bin:/bin", fake.display());
    let run = run_out_of_reach(
        &sinew,
        &["batch", "batch.json", "--ray", "127.0.0.1:1"],
        &work,
        &path,
    );
    let stderr = String::from_utf8_lossy(&run.output.stderr);
    // The fake Python ran the built-in driver: the project's, byte for byte.
    let driver = std::fs::read_to_string(kept.join("driver.py")).expect("python3 ran");
    let project = std::fs::read_to_string(Path::new(CHECKOUT).join("tools/ray/driver.py"));
    assert!(
        driver == project.unwrap(),
        "the driver differs from tools/ray/driver.py"
    );
    let args = std::fs::read_to_string(kept.join("args")).unwrap();
    let script = args.lines().next().unwrap();
    assert!(
        !Path::new(script).starts_with(CHECKOUT),
        "the driver ran from the checkout: {script}"
    );
    assert!(
        args.contains("127.0.0.1:1") && args.contains(s(&sinew)),
        "{args}"
    );
    // ... written for the run, removed after it.
    assert!(!Path::new(script).exists(), "{script} left behind");
    // The failure says what to do.
    assert_eq!(run.output.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("No module named 'ray'") && stderr.contains("pip install ray"),
        "{stderr}"
    );
    assert_never_named_the_checkout(&run, "sinew batch --ray");
}

/// No default or message in the binary names the checkout: the built binary holds no path
/// into its sources or assets (paths of the dependencies' generated files under `target/`,
/// which only a panic in them would print, and the debug information are not defaults).
#[test]
fn the_binary_holds_no_path_into_the_checkout() {
    let binary = std::fs::read(env!("CARGO_BIN_EXE_sinew")).unwrap();
    for inside in ["assets", "tools", "src", "docs", "tests"] {
        let path = format!("{CHECKOUT}/{inside}");
        assert!(
            !contains(&binary, path.as_bytes()),
            "the binary holds {path}"
        );
    }
}

#[test]
fn completions_and_man_pages_cover_every_command() {
    let tmp = scratch("shell");
    let dir = tmp.path();
    let commands = ["rig", "demo", "export", "batch", "completions", "man"];
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let out = command::sinew(&["completions", shell]);
        assert!(out.status.success(), "{shell}");
        let text = String::from_utf8(out.stdout).unwrap();
        for word in commands.iter().chain(&["memory-budget", "ray-python"]) {
            assert!(text.contains(word), "{shell} completions lack {word}");
        }
        if shell == "bash" {
            let script = dir.join("sinew.bash");
            std::fs::write(&script, &text).unwrap();
            let check = Command::new("bash")
                .arg("-n")
                .arg(&script)
                .output()
                .unwrap();
            assert!(
                check.status.success(),
                "{}",
                String::from_utf8_lossy(&check.stderr)
            );
        }
    }
    let refused = command::sinew(&["completions", "tcsh"]);
    assert_eq!(refused.status.code(), Some(command::EXIT_BAD_INPUT));

    let page = command::sinew(&["man"]);
    assert!(page.status.success());
    let page = String::from_utf8(page.stdout).unwrap();
    assert!(page.contains(".TH sinew 1"), "{page}");
    for word in commands {
        assert!(page.contains(word), "the man page lacks {word}");
    }
    let pages = dir.join("man1");
    let out = command::sinew(&["man", "-o", s(&pages)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for page in [
        "sinew.1",
        "sinew-demo.1",
        "sinew-export-spine.1",
        "sinew-batch.1",
    ] {
        let text = std::fs::read_to_string(pages.join(page)).unwrap();
        assert!(text.contains(".TH "), "{page}");
    }
    let demo = std::fs::read_to_string(pages.join("sinew-demo.1")).unwrap();
    assert!(demo.contains("built into sinew"), "{demo}");
    // `man` reads them where it is installed.
    if let Some(man) = which("man") {
        let read = Command::new(man)
            .args(["-l", s(&pages.join("sinew-rig.1"))])
            .env("MANPAGER", "cat")
            .env("PAGER", "cat")
            .output()
            .unwrap();
        assert!(
            read.status.success(),
            "{}",
            String::from_utf8_lossy(&read.stderr)
        );
        assert!(String::from_utf8_lossy(&read.stdout).contains("--handles"));
    }
}
