//! What `sinew` does to what is already at an output path: it writes through symbolic links (as
//! `cp` does), refuses pipes, devices and the wrong kind of entry, replaces a frame folder as a
//! whole (a run killed mid-way, or ended by Ctrl+C's SIGINT, included), writes multi-file
//! outputs as one set (completed by the next run when killed between its renames), and tidies
//! the temporaries a killed run left. Linux: the tests make FIFOs and devices and send signals.
#![cfg(target_os = "linux")]

mod command;
mod common;

use command::{assert_bad_input, s, scratch, sinew};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// A one-bone rig of a `size` px critter with an animation `go` of `seconds`.
fn rig(dir: &Path, size: u32, seconds: f64) -> PathBuf {
    let sprite = dir.join("critter.png");
    common::critter(size).save(&sprite).unwrap();
    let c = f64::from(size) / 2.0;
    let handles =
        serde_json::json!({"bones": [{"name": "a", "head": [c, c * 1.4], "tail": [c, c * 0.6]}]});
    let (mut doc, rig) = command::rig_cli(dir, &[&sprite], &handles.to_string(), &[]);
    doc["animations"] = serde_json::json!({"go": {"bones": {"a": {"rotate": [
        {"time": 0, "value": 0}, {"time": seconds, "value": 90}
    ]}}}});
    std::fs::write(&rig, doc.to_string()).unwrap();
    rig
}

fn ok(args: &[&str]) {
    let out = sinew(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Every entry of `dir` (name → bytes; folders as "<dir>"), hidden ones included.
fn listing(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            let bytes = if e.file_type().unwrap().is_dir() {
                b"<dir>".to_vec()
            } else {
                std::fs::read(e.path()).unwrap()
            };
            (e.file_name().to_string_lossy().into_owned(), bytes)
        })
        .collect()
}

#[cfg(unix)]
#[test]
fn outputs_are_written_through_symbolic_links() {
    let tmp = scratch("links");
    let dir = tmp.path();
    let rig = rig(dir, 64, 0.25);
    let real = dir.join("real.png");
    std::fs::write(&real, b"stale").unwrap();
    let link = dir.join("link.png");
    std::os::unix::fs::symlink("real.png", &link).unwrap();
    ok(&["pose", s(&rig), "-o", s(&link)]);
    assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
    assert!(
        sinew::io::load_png(&real).is_ok(),
        "the link's target was not written"
    );

    // A frame folder and an export folder behind links: the folders they name are written.
    let frames = dir.join("frames_real");
    std::fs::create_dir(&frames).unwrap();
    let frames_link = dir.join("frames");
    std::os::unix::fs::symlink("frames_real", &frames_link).unwrap();
    ok(&["render", s(&rig), "--anim", "go", "-o", s(&frames_link)]);
    assert!(std::fs::symlink_metadata(&frames_link)
        .unwrap()
        .is_symlink());
    assert!(frames.join("frame_0000.png").is_file());
    let export = dir.join("export_real");
    std::fs::create_dir(&export).unwrap();
    let json = export.join("rig.json");
    let elsewhere = dir.join("skeleton-elsewhere.json");
    std::fs::write(&elsewhere, b"old").unwrap();
    std::os::unix::fs::symlink(&elsewhere, &json).unwrap();
    let export_link = dir.join("export");
    std::os::unix::fs::symlink("export_real", &export_link).unwrap();
    ok(&["export", "spine", s(&rig), "-o", s(&export_link)]);
    assert!(std::fs::symlink_metadata(&json).unwrap().is_symlink());
    let text = std::fs::read_to_string(&elsewhere).unwrap();
    assert!(text.contains("\"skeleton\""), "{text}");
    assert!(export.join("rig.atlas").is_file());
}

/// Makes a named pipe at `path` with the system's `mkfifo`.
#[cfg(unix)]
fn mkfifo(path: &Path) {
    let status = Command::new("mkfifo").arg(path).status().expect("mkfifo");
    assert!(status.success());
}

#[cfg(unix)]
#[test]
fn pipes_devices_and_the_wrong_kind_of_entry_are_refused_and_kept() {
    use std::os::unix::fs::FileTypeExt;
    let tmp = scratch("special");
    let dir = tmp.path();
    let rig = rig(dir, 64, 0.25);
    let fifo = dir.join("pipe.png");
    mkfifo(&fifo);
    assert_bad_input(&["pose", s(&rig), "-o", s(&fifo)], "it is a named pipe");
    assert_bad_input(
        &["render", s(&rig), "--anim", "go", "-o", s(&fifo)],
        "it is a named pipe",
    );
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
    // A link to a pipe is refused too, naming where it leads.
    let link = dir.join("to-pipe.gif");
    std::os::unix::fs::symlink(&fifo, &link).unwrap();
    assert_bad_input(
        &["render", s(&rig), "--anim", "go", "-o", s(&link)],
        "the link leads to",
    );

    // A device: our own /dev/null where we may make one (root), else the system's, which a
    // non-root run could not replace anyway.
    let own = dir.join("null");
    let made = Command::new("mknod")
        .args([s(&own), "c", "1", "3"])
        .status()
        .is_ok_and(|st| st.success());
    let device = if made {
        own
    } else {
        PathBuf::from("/dev/null")
    };
    assert_bad_input(&["pose", s(&rig), "-o", s(&device)], "it is a device");
    assert_bad_input(
        &["render", s(&rig), "--anim", "go", "-o", s(&device)],
        "it is a device",
    );
    assert!(std::fs::metadata(&device)
        .unwrap()
        .file_type()
        .is_char_device());

    // A regular file where a frame folder is expected, a folder where a file is.
    let file = dir.join("frames");
    std::fs::write(&file, b"mine").unwrap();
    assert_bad_input(
        &["render", s(&rig), "--anim", "go", "-o", s(&file)],
        "not a folder",
    );
    assert_eq!(std::fs::read(&file).unwrap(), b"mine");
    let folder = dir.join("out.png");
    std::fs::create_dir(&folder).unwrap();
    assert_bad_input(&["pose", s(&rig), "-o", s(&folder)], "it is a folder");
    assert_bad_input(
        &["export", "spine", s(&rig), "-o", s(&file)],
        "not a folder",
    );
    let export = dir.join("export");
    std::fs::create_dir(&export).unwrap();
    mkfifo(&export.join("rig.atlas"));
    assert_bad_input(
        &["export", "spine", s(&rig), "-o", s(&export)],
        "it is a named pipe",
    );
    assert!(!export.join("rig.json").exists());
}

#[test]
fn a_render_replaces_the_whole_previous_render_and_keeps_other_files() {
    let tmp = scratch("replace");
    let dir = tmp.path();
    let rig = rig(dir, 64, 1.0);
    let frames = dir.join("frames");
    ok(&[
        "render",
        s(&rig),
        "--anim",
        "go",
        "--fps",
        "24",
        "-o",
        s(&frames),
    ]);
    std::fs::write(frames.join("notes.txt"), b"mine").unwrap();
    std::fs::create_dir(frames.join("refs")).unwrap();
    std::fs::write(frames.join("refs/a.txt"), b"mine too").unwrap();
    ok(&[
        "render",
        s(&rig),
        "--anim",
        "go",
        "--fps",
        "4",
        "-o",
        s(&frames),
    ]);
    let names: Vec<String> = listing(&frames).into_keys().collect();
    let mut expected: Vec<String> = (0..4).map(|i| format!("frame_{i:04}.png")).collect();
    expected.extend(["notes.txt".to_string(), "refs".to_string()]);
    expected.sort();
    assert_eq!(names, expected);
    assert_eq!(
        std::fs::read(frames.join("refs/a.txt")).unwrap(),
        b"mine too"
    );
    // Nothing hidden is left beside the folder.
    assert_nothing_hidden_in(dir);
}

#[test]
fn a_render_killed_by_a_signal_leaves_the_previous_or_the_new_render() {
    let tmp = scratch("kill");
    let dir = tmp.path();
    // Big frames, so that writing them takes a good part of the run.
    let rig = rig(dir, 256, 2.0);
    let render = |fps: &str, out: &Path| {
        vec![
            "render".to_string(),
            s(&rig).into(),
            "--anim".into(),
            "go".into(),
            "--fps".into(),
            fps.into(),
            "--scale".into(),
            "3".into(),
            "-o".into(),
            s(out).into(),
        ]
    };
    // The previous render (11 frames) and the new one (60 frames), made whole for reference.
    let old_ref = dir.join("old");
    let new_ref = dir.join("new");
    ok(&render("5.5", &old_ref)
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>());
    let t = Instant::now();
    ok(&render("30", &new_ref)
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>());
    let full = t.elapsed();
    let mut old = listing(&old_ref);
    let mut new = listing(&new_ref);
    assert_eq!(old.len(), 11);
    assert_eq!(new.len(), 60);
    old.insert("notes.txt".into(), b"mine".to_vec());
    new.insert("notes.txt".into(), b"mine".to_vec());

    let target = dir.join("frames");
    let mut outcomes = Vec::new();
    for fraction in [0.2, 0.4, 0.55, 0.7, 0.8, 0.9, 0.95, 1.05] {
        // Back to the previous render; the user's file stays the same file throughout.
        std::fs::create_dir_all(&target).unwrap();
        for name in listing(&target)
            .into_keys()
            .filter(|n| n.starts_with("frame_"))
        {
            std::fs::remove_file(target.join(name)).unwrap();
        }
        for (name, bytes) in &old {
            if name.starts_with("frame_") || !target.join(name).exists() {
                std::fs::write(target.join(name), bytes).unwrap();
            }
        }
        let mut child = Command::new(env!("CARGO_BIN_EXE_sinew"))
            .args(render("30", &target))
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(full.mul_f64(fraction));
        // SIGKILL (no handler runs, as when the machine kills a run) and SIGINT (Ctrl+C on a
        // terminal) in turn.
        let signal = if outcomes.len() % 2 == 0 {
            libc::SIGKILL
        } else {
            libc::SIGINT
        };
        // SAFETY: kill(2) on the child's own pid, which `wait` below has not reaped yet.
        unsafe { libc::kill(child.id() as libc::pid_t, signal) };
        let status = child.wait().unwrap();
        let now = listing(&target);
        if now == old {
            outcomes.push(format!("{fraction}: old ({status})"));
        } else if now == new {
            outcomes.push(format!("{fraction}: new ({status})"));
        } else {
            panic!(
                "killed at {fraction} of the run: the folder holds neither render: {:?}",
                now.keys().collect::<Vec<_>>()
            );
        }
    }
    eprintln!("{outcomes:?}");
    // The next run tidies what a killed one left beside the folder and completes.
    ok(&render("30", &target)
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>());
    assert_eq!(listing(&target), new);
    assert_nothing_hidden_in(dir);
}

/// No hidden entry (a temporary or a half-swapped folder) is left in `dir`.
fn assert_nothing_hidden_in(dir: &Path) {
    let hidden: Vec<String> = listing(dir)
        .into_keys()
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
}

#[test]
fn temporaries_left_by_a_killed_run_are_removed_by_the_next() {
    let tmp = scratch("stale");
    let dir = tmp.path();
    let rig = rig(dir, 64, 0.25);
    let export = dir.join("export");
    ok(&["export", "spine", s(&rig), "-o", s(&export)]);
    // A pid above the kernel's largest never runs: these are a killed run's.
    let dead = 4_294_967_294u32;
    let stale_file = export.join(format!(".rig.json.{dead}.0.tmp"));
    std::fs::write(&stale_file, b"half").unwrap();
    let other = export.join("mine.txt");
    std::fs::write(&other, b"mine").unwrap();
    // A frame folder's staging folder, killed after the swap: the old frames and a user's file
    // not yet moved back.
    let frames = dir.join("frames");
    ok(&["render", s(&rig), "--anim", "go", "-o", s(&frames)]);
    let staging = dir.join(format!(".frames.{dead}.3.tmp"));
    std::fs::create_dir(&staging).unwrap();
    std::fs::write(staging.join("frame_0000.png"), b"old").unwrap();
    std::fs::write(staging.join("notes.txt"), b"mine").unwrap();
    if !Path::new("/proc/self").exists() {
        eprintln!("no /proc: whether a process runs cannot be told; temporaries are kept");
        return;
    }
    ok(&["export", "spine", s(&rig), "-o", s(&export)]);
    assert!(!stale_file.exists());
    assert_eq!(std::fs::read(&other).unwrap(), b"mine");
    ok(&["render", s(&rig), "--anim", "go", "-o", s(&frames)]);
    assert!(!staging.exists());
    assert_eq!(std::fs::read(frames.join("notes.txt")).unwrap(), b"mine");
}

/// Runs `sinew ARGS` under strace, which sends it SIGKILL on entering its `nth` call of one of
/// `syscalls` (fault injection: a real signal at an exact point of the run, whatever the
/// timing). Returns how it ended.
fn killed_at_syscall(args: &[String], syscalls: &str, nth: usize) -> std::process::ExitStatus {
    Command::new("strace")
        .args(["-f", "-qq", "-o", "/dev/null", "-e"])
        .arg(format!("trace={syscalls}"))
        .arg("-e")
        .arg(format!("inject={syscalls}:signal=SIGKILL:when={nth}"))
        .arg(env!("CARGO_BIN_EXE_sinew"))
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .unwrap()
}

/// Multi-file outputs (a sprite sheet's PNG and JSON; a Spine export's skeleton, atlas and
/// page) killed by SIGKILL before the set is committed, before each of its renames and before
/// its journal is removed:
/// the folder then holds the old set whole, or a journal beside it (a mixed set), and after the
/// next run that writes anything into the folder (here a GIF) it holds the old or the new set
/// whole, the user's file untouched, nothing hidden.
#[test]
fn a_set_of_files_killed_between_its_renames_is_whole_after_the_next_run() {
    if Command::new("strace").arg("-V").output().is_err() {
        eprintln!("skipped: no strace here to stop the run at its renames (apt install strace)");
        return;
    }
    let tmp = scratch("set-kill");
    let dir = tmp.path();
    let small = dir.join("small");
    let big = dir.join("big");
    std::fs::create_dir_all(&small).unwrap();
    std::fs::create_dir_all(&big).unwrap();
    let (rig_old, rig_new) = (rig(&small, 64, 0.5), rig(&big, 96, 0.5));
    let out = dir.join("out");
    let sheet = |rig: &Path, fps: &str, folder: &Path| -> Vec<String> {
        let png = folder.join("walk.png");
        [
            "render",
            s(rig),
            "--anim",
            "go",
            "--fps",
            fps,
            "-o",
            s(&png),
        ]
        .map(String::from)
        .to_vec()
    };
    let spine = |rig: &Path, folder: &Path| -> Vec<String> {
        ["export", "spine", s(rig), "-o", s(folder)]
            .map(String::from)
            .to_vec()
    };
    type Args = Box<dyn Fn(&Path) -> Vec<String>>;
    let cases: Vec<(&str, Args, Args)> = vec![
        (
            "sheet",
            Box::new(move |f: &Path| sheet(&rig_old, "4", f)),
            Box::new(move |f: &Path| sheet(&rig_new, "12", f)),
        ),
        (
            "spine",
            Box::new({
                let rig = dir.join("small/rig.json");
                move |f: &Path| spine(&rig, f)
            }),
            Box::new({
                let rig = dir.join("big/rig.json");
                move |f: &Path| spine(&rig, f)
            }),
        ),
    ];
    let gif_rig = dir.join("small/rig.json");
    let mut mixed = 0;
    for (kind, old_args, new_args) in &cases {
        let reference = |args: &Args, name: &str| {
            let folder = dir.join(format!("{kind}-{name}"));
            std::fs::create_dir_all(&folder).unwrap();
            let a = args(&folder);
            ok(&a.iter().map(String::as_str).collect::<Vec<_>>());
            let mut files = listing(&folder);
            files.insert("notes.txt".into(), b"mine".to_vec());
            files
        };
        let old = reference(old_args, "old");
        let new = reference(new_args, "new");
        assert!(old.len() >= 3 && old.keys().eq(new.keys()), "{old:?}");
        assert!(
            old.iter()
                .all(|(name, bytes)| name == "notes.txt" || new[name] != *bytes),
            "{kind}: every file of the new set differs from the old"
        );
        let renames = old.len() - 1;
        // Before the commit (syncing the first new file), before each rename, and before the
        // journal is removed.
        let points = [("fsync", 1)]
            .into_iter()
            .chain((1..=renames).map(|n| ("rename,renameat,renameat2", n)))
            .chain([("unlink,unlinkat", 1)]);
        for (syscalls, nth) in points {
            let _ = std::fs::remove_dir_all(&out);
            std::fs::create_dir_all(&out).unwrap();
            for (name, bytes) in &old {
                std::fs::write(out.join(name), bytes).unwrap();
            }
            let status = killed_at_syscall(&new_args(&out), syscalls, nth);
            let at = format!("{kind}, SIGKILL at {syscalls} #{nth} ({status})");
            let now = listing(&out);
            let hidden = |name: &str| name.starts_with('.');
            let journal = now
                .keys()
                .any(|n| n.starts_with(".sinew-set.") && n.ends_with(".journal"));
            let visible: BTreeMap<String, Vec<u8>> =
                now.into_iter().filter(|(n, _)| !hidden(n)).collect();
            let before = if visible == old {
                "old"
            } else if visible == new {
                "new"
            } else {
                assert!(journal, "{at}: a mixed set and no journal to complete it");
                mixed += 1;
                "mixed"
            };
            // The next run that writes into the folder completes or rolls back the set.
            let gif = out.join("next.gif");
            ok(&["render", s(&gif_rig), "--anim", "go", "-o", s(&gif)]);
            std::fs::remove_file(&gif).unwrap();
            let after = listing(&out);
            // A set killed before its commit leaves temporaries of its other files (hidden,
            // `.NAME.PID.N.tmp`), which the next write of those files removes.
            if !journal {
                after.keys().filter(|n| hidden(n)).for_each(|n| {
                    assert!(n.ends_with(".tmp"), "{at}: {n} left");
                });
            }
            let after: BTreeMap<String, Vec<u8>> =
                after.into_iter().filter(|(n, _)| !hidden(n)).collect();
            let outcome = if after == new {
                "new"
            } else if after == old {
                "old"
            } else {
                panic!(
                    "{at}: after the next run the folder holds neither set: {:?}",
                    after.keys().collect::<Vec<_>>()
                )
            };
            if journal {
                assert_eq!(outcome, "new", "{at}: a committed set is completed");
            }
            eprintln!("{at}: {before} (journal: {journal}) -> {outcome}");
            // Rerun whole, the set is new and nothing hidden stays.
            let a = new_args(&out);
            ok(&a.iter().map(String::as_str).collect::<Vec<_>>());
            assert_eq!(listing(&out), new, "{at}: the rerun");
        }
    }
    // The kills landed between renames at least once per set (each set has 2+ renames).
    assert!(mixed >= 2, "no kill left a mixed set: {mixed}");
}
