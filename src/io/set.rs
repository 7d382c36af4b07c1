//! Several files written as one set: a sprite sheet's PNG and JSON, a Spine export's skeleton,
//! atlas and pages, the images of a layered file's layers.
//!
//! A rename is atomic for one file, not for several, so [`write_set`] works in steps, with a
//! journal that decides, after a kill at any point, whether the set is rolled back or completed:
//!
//! 1. Every target is checked ([`resolve_output`]: through links, regular files only), and the
//!    sets a killed run left in the targets' folders are completed ([`complete_interrupted_sets`]).
//! 2. Every new file goes to a temporary beside its target (`.NAME.PID.N.tmp`), synced.
//!    *Killed here:* no target changed; the temporaries are stale and the next write into the
//!    folder removes them: the set is rolled back.
//! 3. The journal `.sinew-set.PID.N.journal` is written in the folder of the last target and
//!    synced with its folder: each target (absolute) and its temporary, then an end line. It is
//!    the commit point; a journal without its end line was cut short and commits nothing.
//! 4. Each temporary is renamed over its target, in the order given; the folders are synced.
//!    *Killed here:* some targets are new, some old, beside the journal, until the next write
//!    into that folder (any sinew command writing there, or a rerun), which renames the
//!    temporaries the journal names that are still there: the set is completed.
//! 5. The journal is removed.
//!
//! So every set is all old or all new once the next run has written into its folder. Between a
//! kill in step 4 and that run a reader can see a mixed set beside a journal: no portable call
//! renames several files in one step (Linux's `RENAME_EXCHANGE` swaps two entries, which serves
//! a frame folder, a folder of sinew's own; a set lies among the user's other files).
//!
//! Journal format (bytes): `sinew-set 1\n`, then per file its target path and its temporary's
//! file name, each ended by a NUL byte (which no path holds), then `end\n`.

use super::atomic::{
    create_new, file_name, keep_permissions, may_be_running, parent_or_dot,
    remove_stale_temporaries_of, resolve_output, sync_folder, sync_paths, temporary_sibling,
    write_new, OutputKind,
};
use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// A journal's first line: the format and its version.
const JOURNAL_MAGIC: &[u8] = b"sinew-set 1\n";
/// A journal's last line: present only in a journal written whole (a committed set).
const JOURNAL_END: &[u8] = b"end\n";
/// Journals are named `.sinew-set.PID.N.journal`.
const JOURNAL_PREFIX: &str = ".sinew-set.";
const JOURNAL_SUFFIX: &str = ".journal";

/// Journals this process is writing or renaming by now: another thread must not complete them.
/// A journal of this process that is not here was left by a failed rename (see [`write_set`]).
static IN_FLIGHT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn in_flight() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    IN_FLIGHT.lock().unwrap_or_else(|e| e.into_inner())
}

/// Writes several files that belong together as one set (see the module doc): every target is
/// checked first, then every new file is written and synced, then a journal commits the set,
/// then the files are renamed into place in the order given. A failure before the commit (a
/// refused target, a full disk, no permission) leaves every target as it was and no temporary
/// behind; a failure or a kill after it leaves the journal, and the next write into the folder
/// completes the set. Give the file that refers to the others last. Returns the failing path
/// with its error.
pub fn write_set(files: &[(PathBuf, Vec<u8>)]) -> Result<(), (PathBuf, io::Error)> {
    let mut targets = Vec::with_capacity(files.len());
    for (path, _) in files {
        let target = resolve_output(path, OutputKind::File).map_err(|e| (path.clone(), e))?;
        targets.push(target);
    }
    // Completes the interrupted sets of the folders, then removes stale temporaries.
    remove_stale_temporaries_of(&targets);
    let (Some((last_path, _)), Some(last_target)) = (files.last(), targets.last()) else {
        return Ok(());
    };
    let mut temporaries = Vec::with_capacity(files.len());
    let remove_temporaries = |temporaries: &[PathBuf]| {
        for tmp in temporaries {
            // A temporary not yet created has nothing to remove.
            let _ = fs::remove_file(tmp);
        }
    };
    // Written and closed, given the permissions of what they replace, then synced together.
    let written = files
        .iter()
        .zip(&targets)
        .try_for_each(|((path, bytes), target)| {
            let tmp = temporary_sibling(target);
            temporaries.push(tmp.clone());
            create_new(&tmp, bytes).map_err(|e| (path.clone(), e))?;
            keep_permissions(target, &tmp).map_err(|e| (path.clone(), e))
        })
        .and_then(|()| sync_paths(&temporaries).map_err(|e| (last_path.clone(), e)));
    if let Err(e) = written {
        remove_temporaries(&temporaries);
        return Err(e);
    }
    let folders = distinct_folders(&targets);
    let journal = journal_path(last_target);
    in_flight().push(journal.clone());
    let committed = journal_bytes(&targets, &temporaries).and_then(|bytes| {
        write_new(&journal, &bytes)?;
        sync_folder(parent_or_dot(&journal))
    });
    if let Err(e) = committed {
        let _ = fs::remove_file(&journal);
        in_flight().retain(|j| j != &journal);
        remove_temporaries(&temporaries);
        return Err((last_path.clone(), e));
    }
    for (((path, _), target), tmp) in files.iter().zip(&targets).zip(&temporaries) {
        if let Err(e) = fs::rename(tmp, target) {
            // Committed: the journal stays, and the next write into the folder (from this
            // process too, as it is no longer in flight) completes the set.
            in_flight().retain(|j| j != &journal);
            return Err((path.clone(), e));
        }
    }
    for folder in &folders {
        // Best effort: the renames are done; a folder that cannot be synced (some file
        // systems refuse) loses them only to a power cut, and the journal is gone with them.
        let _ = sync_folder(folder);
    }
    let removed = fs::remove_file(&journal);
    in_flight().retain(|j| j != &journal);
    removed.map_err(|e| (last_path.clone(), e))
}

/// Completes the sets that runs no longer running left interrupted in `dir` (their journals;
/// see the module doc): a committed journal's temporaries still there are renamed over their
/// targets, and the journal is removed; a journal cut short (nothing committed) is removed, and
/// its temporaries are left to [`remove_stale_temporaries`]. Best effort: a set that cannot be
/// completed now (a folder gone, no permission) keeps its journal for a later run. A file of
/// the journal's name that is not a journal of this format is left alone.
pub fn complete_interrupted_sets(dir: &Path) {
    for journal in interrupted_journals(dir) {
        let Ok(bytes) = fs::read(&journal) else {
            continue;
        };
        match parse_journal(&bytes) {
            Journal::Foreign => {}
            Journal::CutShort => {
                let _ = fs::remove_file(&journal);
            }
            Journal::Committed(entries) => {
                let mut done = true;
                for (target, tmp) in &entries {
                    if fs::symlink_metadata(tmp).is_ok_and(|m| m.is_file())
                        && fs::rename(tmp, target).is_err()
                    {
                        done = false;
                    }
                }
                if done {
                    let targets: Vec<PathBuf> = entries.into_iter().map(|(t, _)| t).collect();
                    for folder in distinct_folders(&targets) {
                        let _ = sync_folder(&folder);
                    }
                    let _ = fs::remove_file(&journal);
                }
            }
        }
    }
}

/// The journals in `dir` of processes no longer running (or of this process, left by a failed
/// rename), sorted (older processes' first where pids do not wrap).
pub fn interrupted_journals(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut found: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let pid = e.file_name().to_str().and_then(journal_pid)?;
            let path = dir.join(e.file_name());
            let live = if pid == std::process::id() {
                let path = absolute(&path);
                in_flight().contains(&path)
            } else {
                may_be_running(pid)
            };
            (!live).then_some(path)
        })
        .collect();
    found.sort();
    found
}

/// The process id in a journal's name `.sinew-set.PID.N.journal`.
fn journal_pid(name: &str) -> Option<u32> {
    let rest = name
        .strip_prefix(JOURNAL_PREFIX)?
        .strip_suffix(JOURNAL_SUFFIX)?;
    let (pid, n) = rest.split_once('.')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    (digits(pid) && digits(n)).then(|| pid.parse().ok())?
}

/// A new journal's path beside `last_target`, absolute, unique per process and set.
fn journal_path(last_target: &Path) -> PathBuf {
    static SETS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = SETS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    absolute(parent_or_dot(last_target)).join(format!(
        "{JOURNAL_PREFIX}{}.{n}{JOURNAL_SUFFIX}",
        std::process::id()
    ))
}

/// `path` made absolute against the working folder (a later run may work elsewhere).
fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
}

/// The folders of `targets`, each once, in order.
fn distinct_folders(targets: &[PathBuf]) -> Vec<PathBuf> {
    let mut folders: Vec<PathBuf> = Vec::new();
    for target in targets {
        let folder = parent_or_dot(target).to_path_buf();
        if !folders.contains(&folder) {
            folders.push(folder);
        }
    }
    folders
}

/// The journal of a set: each target (made absolute) and its temporary's file name.
fn journal_bytes(targets: &[PathBuf], temporaries: &[PathBuf]) -> io::Result<Vec<u8>> {
    let mut bytes = JOURNAL_MAGIC.to_vec();
    for (target, tmp) in targets.iter().zip(temporaries) {
        bytes.extend_from_slice(&path_bytes(&absolute(target))?);
        bytes.push(0);
        bytes.extend_from_slice(file_name(tmp).as_bytes());
        bytes.push(0);
    }
    bytes.extend_from_slice(JOURNAL_END);
    Ok(bytes)
}

/// What a file of a journal's name holds.
#[derive(Debug, PartialEq)]
enum Journal {
    /// Not this format (another version, or not sinew's): left alone.
    Foreign,
    /// Written only in part: the set was never committed.
    CutShort,
    /// A committed set: (target, its temporary) in rename order.
    Committed(Vec<(PathBuf, PathBuf)>),
}

fn parse_journal(bytes: &[u8]) -> Journal {
    let Some(body) = bytes.strip_prefix(JOURNAL_MAGIC) else {
        // A journal cut inside its first line is ours too.
        return if JOURNAL_MAGIC.starts_with(bytes) {
            Journal::CutShort
        } else {
            Journal::Foreign
        };
    };
    let Some(body) = body.strip_suffix(JOURNAL_END) else {
        return Journal::CutShort;
    };
    // Every field ends with a NUL, so the pairs end with one (or there are none).
    if !(body.is_empty() || body.ends_with(&[0])) {
        return Journal::CutShort;
    }
    let fields: Vec<&[u8]> = body.split(|&b| b == 0).collect();
    let fields = &fields[..fields.len() - 1];
    if !fields.len().is_multiple_of(2) {
        return Journal::CutShort;
    }
    let mut entries = Vec::with_capacity(fields.len() / 2);
    for pair in fields.chunks(2) {
        let (Some(target), Some(tmp)) = (path_from_bytes(pair[0]), path_from_bytes(pair[1])) else {
            return Journal::Foreign;
        };
        // A temporary is a plain name beside its target, never a path elsewhere.
        if tmp.components().count() != 1 || tmp.file_name().is_none() || !target.is_absolute() {
            return Journal::Foreign;
        }
        let tmp = target.with_file_name(tmp);
        entries.push((target, tmp));
    }
    Journal::Committed(entries)
}

#[cfg(unix)]
fn path_bytes(path: &Path) -> io::Result<Vec<u8>> {
    use std::os::unix::ffi::OsStrExt;
    Ok(path.as_os_str().as_bytes().to_vec())
}

#[cfg(not(unix))]
fn path_bytes(path: &Path) -> io::Result<Vec<u8>> {
    path.to_str().map(|s| s.as_bytes().to_vec()).ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{}: not UTF-8, cannot be journaled", path.display()),
        )
    })
}

#[cfg(unix)]
fn path_from_bytes(bytes: &[u8]) -> Option<PathBuf> {
    use std::os::unix::ffi::OsStrExt;
    (!bytes.is_empty()).then(|| PathBuf::from(std::ffi::OsStr::from_bytes(bytes)))
}

#[cfg(not(unix))]
fn path_from_bytes(bytes: &[u8]) -> Option<PathBuf> {
    std::str::from_utf8(bytes)
        .ok()
        .filter(|s| !s.is_empty())
        .map(PathBuf::from)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::atomic::write_atomic;

    /// An empty folder of its own for one test, removed when the result drops.
    fn scratch(name: &str) -> tempfile::TempDir {
        crate::test_scratch::scratch(&format!("set-{name}"))
    }

    /// Every entry of `dir`, name → bytes.
    fn listing(dir: &Path) -> Vec<(String, Vec<u8>)> {
        let mut all: Vec<(String, Vec<u8>)> = fs::read_dir(dir)
            .unwrap()
            .map(|e| {
                let e = e.unwrap();
                let name = e.file_name().to_string_lossy().into_owned();
                (name, fs::read(e.path()).unwrap_or_default())
            })
            .collect();
        all.sort();
        all
    }

    /// A pid above the kernel's largest (4194304): never running.
    const DEAD: u32 = 4_294_967_294;

    #[test]
    fn a_set_is_written_whole_or_not_at_all() {
        let tmp = scratch("whole");
        let dir = tmp.path();
        let (png, json) = (dir.join("sheet.png"), dir.join("sheet.json"));
        write_set(&[
            (png.clone(), b"old png".to_vec()),
            (json.clone(), b"old".to_vec()),
        ])
        .unwrap();
        // The second target cannot be written (a folder where a file goes; a file where a
        // folder is needed): the first keeps its old content, and no temporary stays.
        fs::create_dir(dir.join("taken")).unwrap();
        for bad in [dir.join("taken"), json.join("below")] {
            let failed = write_set(&[
                (png.clone(), b"new png".to_vec()),
                (bad.clone(), b"x".to_vec()),
            ]);
            assert_eq!(failed.map_err(|(path, _)| path), Err(bad));
            assert_eq!(fs::read(&png).unwrap(), b"old png");
        }
        assert_eq!(fs::read_dir(dir).unwrap().count(), 3);
        write_set(&[
            (png.clone(), b"new png".to_vec()),
            (json.clone(), b"new".to_vec()),
        ])
        .unwrap();
        assert_eq!(fs::read(&png).unwrap(), b"new png");
        assert_eq!(fs::read(&json).unwrap(), b"new");
        // No journal stays after a set is written.
        assert_eq!(fs::read_dir(dir).unwrap().count(), 3);
    }

    #[test]
    fn a_large_set_in_two_folders_is_written_whole_with_modes_kept() {
        let tmp = scratch("large");
        let dir = tmp.path();
        fs::create_dir(dir.join("parts")).unwrap();
        // More files than a process may hold open (1,024 by default), in two folders.
        let n: usize = 1_100;
        let files: Vec<(PathBuf, Vec<u8>)> = (0..n)
            .map(|i| {
                let folder = if i % 2 == 0 {
                    dir.join("parts")
                } else {
                    dir.to_path_buf()
                };
                (
                    folder.join(format!("p{i}.png")),
                    format!("old {i}").into_bytes(),
                )
            })
            .collect();
        write_set(&files).unwrap();
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            fs::set_permissions(&files[1].0, fs::Permissions::from_mode(0o640)).unwrap();
        }
        let new: Vec<(PathBuf, Vec<u8>)> = files
            .iter()
            .enumerate()
            .map(|(i, (p, _))| (p.clone(), format!("new {i}").into_bytes()))
            .collect();
        write_set(&new).unwrap();
        for (path, bytes) in &new {
            assert_eq!(&fs::read(path).unwrap(), bytes);
        }
        assert_eq!(
            fs::read_dir(dir.join("parts")).unwrap().count(),
            n.div_ceil(2)
        );
        assert_eq!(fs::read_dir(dir).unwrap().count(), n / 2 + 1);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = fs::metadata(&files[1].0).unwrap().permissions().mode();
            assert_eq!(mode & 0o777, 0o640);
        }
    }

    /// The folder a run killed after its commit leaves, at each point of its renames: old
    /// targets, `renamed` of them already new, the rest's temporaries and the journal.
    fn killed_after_commit(dir: &Path, pid: u32, renamed: usize, journal_n: u64) -> PathBuf {
        let names = ["a.png", "a.atlas", "a.json"];
        let mut targets = Vec::new();
        let mut temporaries = Vec::new();
        for (i, name) in names.iter().enumerate() {
            let target = dir.join(name);
            let tmp = dir.join(format!(".{name}.{pid}.{i}.tmp"));
            fs::write(&target, format!("old {name}")).unwrap();
            if i < renamed {
                fs::write(&target, format!("new {name}")).unwrap();
            } else {
                fs::write(&tmp, format!("new {name}")).unwrap();
            }
            targets.push(target);
            temporaries.push(tmp);
        }
        let journal = dir.join(format!("{JOURNAL_PREFIX}{pid}.{journal_n}{JOURNAL_SUFFIX}"));
        fs::write(&journal, journal_bytes(&targets, &temporaries).unwrap()).unwrap();
        journal
    }

    #[test]
    fn a_set_killed_between_its_renames_is_completed_by_the_next_write_into_its_folder() {
        for renamed in 0..=3 {
            let tmp = scratch(&format!("killed-{renamed}"));
            let dir = tmp.path();
            let journal = killed_after_commit(dir, DEAD, renamed, 0);
            if !Path::new("/proc/self").exists() {
                eprintln!("no /proc: whether a process runs cannot be told; journals are kept");
                return;
            }
            // Any write into the folder, here of another file.
            write_atomic(&dir.join("other.gif"), b"gif").unwrap();
            assert!(!journal.exists());
            let expected: Vec<(String, Vec<u8>)> = ["a.atlas", "a.json", "a.png", "other.gif"]
                .iter()
                .map(|n| {
                    let bytes = if *n == "other.gif" {
                        b"gif".to_vec()
                    } else {
                        format!("new {n}").into_bytes()
                    };
                    (n.to_string(), bytes)
                })
                .collect();
            assert_eq!(listing(dir), expected, "{renamed} renamed before the kill");
        }
    }

    #[test]
    fn a_journal_cut_short_rolls_the_set_back() {
        let tmp = scratch("cut");
        let dir = tmp.path();
        let journal = killed_after_commit(dir, DEAD, 0, 0);
        let whole = fs::read(&journal).unwrap();
        // Cut inside the last field: no end line.
        fs::write(&journal, &whole[..whole.len() - 7]).unwrap();
        if !Path::new("/proc/self").exists() {
            return;
        }
        write_atomic(&dir.join("a.png"), b"next").unwrap();
        assert!(!journal.exists());
        assert_eq!(fs::read(dir.join("a.json")).unwrap(), b"old a.json");
        assert_eq!(fs::read(dir.join("a.atlas")).unwrap(), b"old a.atlas");
        assert_eq!(fs::read(dir.join("a.png")).unwrap(), b"next");
        // The other targets' stale temporaries go with their next write.
        let set: Vec<(PathBuf, Vec<u8>)> = ["a.png", "a.atlas", "a.json"]
            .iter()
            .map(|n| (dir.join(n), n.as_bytes().to_vec()))
            .collect();
        write_set(&set).unwrap();
        let names: Vec<String> = listing(dir).into_iter().map(|(n, _)| n).collect();
        assert_eq!(names, ["a.atlas", "a.json", "a.png"]);
    }

    #[test]
    fn journals_of_running_processes_and_foreign_files_are_left_alone() {
        let tmp = scratch("live");
        let dir = tmp.path();
        // This process's own journal, in flight as if another thread were renaming.
        let journal = killed_after_commit(dir, std::process::id(), 1, u64::MAX);
        in_flight().push(absolute(&journal));
        let foreign = dir.join(format!("{JOURNAL_PREFIX}{DEAD}.1{JOURNAL_SUFFIX}"));
        fs::write(&foreign, b"sinew-set 2\nwhatever").unwrap();
        let before = listing(dir);
        complete_interrupted_sets(dir);
        assert_eq!(listing(dir), before);
        // Once no thread has it in flight (a rename failed), it is completed.
        in_flight().retain(|j| j != &absolute(&journal));
        complete_interrupted_sets(dir);
        assert!(!journal.exists());
        assert!(foreign.exists());
        assert_eq!(fs::read(dir.join("a.json")).unwrap(), b"new a.json");
    }

    #[test]
    fn a_journal_reads_back_and_every_cut_of_it_is_cut_short() {
        let targets = [PathBuf::from("/x/a b.png"), PathBuf::from("/x/a.json")];
        let temporaries = [
            PathBuf::from("/x/.a b.png.7.0.tmp"),
            PathBuf::from(".a.json.7.1.tmp"),
        ];
        let bytes = journal_bytes(&targets, &temporaries).unwrap();
        assert_eq!(
            parse_journal(&bytes),
            Journal::Committed(vec![
                (targets[0].clone(), PathBuf::from("/x/.a b.png.7.0.tmp")),
                (targets[1].clone(), PathBuf::from("/x/.a.json.7.1.tmp")),
            ])
        );
        for cut in 0..bytes.len() {
            assert_eq!(
                parse_journal(&bytes[..cut]),
                Journal::CutShort,
                "cut at {cut}"
            );
        }
        assert_eq!(parse_journal(b"{\"set\": 1}"), Journal::Foreign);
        assert_eq!(journal_pid(".sinew-set.12.3.journal"), Some(12));
        assert_eq!(journal_pid(".sinew-set.12.journal"), None);
        assert_eq!(journal_pid(".sinew-set.12.3.journal.9.0.tmp"), None);
    }
}
