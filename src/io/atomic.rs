//! Writing outputs so that a reader never sees half of one, and so that only what sinew may
//! replace is replaced.
//!
//! Like `cp`, a write goes *through* a symbolic link to the file it names (atomically there: the
//! link stays a link, its target gets the new content); an existing output that is not a regular
//! file (a named pipe, a device such as `/dev/full`, a socket, a folder) is refused, never replaced.
//! The content goes to a temporary file beside the (resolved) target, which is then renamed over
//! it: the rename is atomic on one file system, so the target holds either its old or its new
//! content. Temporaries are named `.NAME.PID.N.tmp`; ones left by a process that was killed are
//! removed by the next write of the same target ([`remove_stale_temporaries`]). Files that
//! belong together (a sprite sheet and its JSON, a Spine export) are written as one set by
//! [`write_set`] (module [`super::set`]): a journal makes a set interrupted between its renames
//! complete on the next write into its folder.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

pub use super::set::{complete_interrupted_sets, write_set};

/// Symbolic links followed from an output path before giving up (as the kernel's own limit).
pub const MAX_SYMLINK_HOPS: usize = 40;

/// What an output path must be where it already exists.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind {
    /// A regular file (replaced whole).
    File,
    /// A folder (a frame folder or an export folder, written into).
    Folder,
}

/// Why an output path cannot be written; an [`io::Error`] of kind `InvalidInput` carrying it is
/// what the writers return, so their messages say it on one line.
fn refuse(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// What a non-regular file is, for messages.
fn describe(file_type: &fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return "a named pipe";
        }
        if file_type.is_char_device() || file_type.is_block_device() {
            return "a device";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    if file_type.is_dir() {
        "a folder"
    } else if file_type.is_file() {
        "a regular file"
    } else {
        "not a regular file"
    }
}

/// The path a write of `path` replaces: `path` itself, or, through symbolic links, the file they
/// name (which need not exist yet, as `cp` creates it). Where something exists there, it must be
/// of `kind`; anything else (a pipe, a device, a socket, a folder where a file is expected and
/// the other way round) is refused.
pub fn resolve_output(path: &Path, kind: OutputKind) -> io::Result<PathBuf> {
    let mut at = path.to_path_buf();
    for _ in 0..=MAX_SYMLINK_HOPS {
        let meta = match fs::symlink_metadata(&at) {
            Ok(meta) => meta,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(at),
            Err(e) => return Err(e),
        };
        let file_type = meta.file_type();
        if file_type.is_symlink() {
            let target = fs::read_link(&at)?;
            at = match at.parent() {
                Some(dir) if target.is_relative() => dir.join(target),
                _ => target,
            };
            continue;
        }
        let fits = match kind {
            OutputKind::File => file_type.is_file(),
            OutputKind::Folder => file_type.is_dir(),
        };
        if !fits {
            let wanted = match kind {
                OutputKind::File => "a regular file",
                OutputKind::Folder => "a folder",
            };
            let via = if at == path {
                String::new()
            } else {
                format!(" (the link leads to {})", at.display())
            };
            return Err(refuse(format!(
                "it is {}{via}, not {wanted}: sinew replaces only {}; remove it or choose another path",
                describe(&file_type),
                match kind {
                    OutputKind::File => "regular files",
                    OutputKind::Folder => "folders",
                }
            )));
        }
        return Ok(at);
    }
    Err(refuse(format!(
        "more than {MAX_SYMLINK_HOPS} symbolic links in a row (a loop?)"
    )))
}

/// Writes `bytes` to `path` atomically (temporary file + rename), through symbolic links; an
/// existing `path` that is not a regular file is refused (see [`resolve_output`]). A file it
/// replaces keeps its permissions; the content is synced before the rename and the folder
/// after it, so a power cut leaves the old file or the new one.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let target = resolve_output(path, OutputKind::File)?;
    remove_stale_temporaries(&target);
    let tmp = temporary_sibling(&target);
    let result = create_new(&tmp, bytes)
        .and_then(|file| {
            keep_permissions(&target, &tmp)?;
            file.sync_all()
        })
        .and_then(|()| fs::rename(&tmp, &target));
    if result.is_err() {
        // The temporary file may not exist; nothing else to report.
        let _ = fs::remove_file(&tmp);
        return result;
    }
    // Best effort: the rename is done; a folder that cannot be synced (some file systems
    // refuse) loses it only to a power cut.
    let _ = sync_folder(parent_or_dot(&target));
    Ok(())
}

/// Creates `path` (which must not exist) with `bytes`, synced to disk.
pub fn write_new(path: &Path, bytes: &[u8]) -> io::Result<()> {
    create_new(path, bytes)?.sync_all()
}

/// Creates `path` (which must not exist) with `bytes`, not yet synced: the caller syncs it
/// ([`sync_paths`]).
pub(crate) fn create_new(path: &Path, bytes: &[u8]) -> io::Result<fs::File> {
    let mut file = fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)?;
    file.write_all(bytes)?;
    Ok(file)
}

/// Gives `tmp` the permissions of `target` where `target` exists (a replaced file keeps its
/// mode: a script's executable bit, a shared file's group write); a new file keeps the
/// process's defaults.
pub(crate) fn keep_permissions(target: &Path, tmp: &Path) -> io::Result<()> {
    match fs::metadata(target) {
        Ok(meta) => fs::set_permissions(tmp, meta.permissions()),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

/// Files at most this many are synced one by one; more, on Linux, by one `syncfs` per file
/// system (a layered file's thousands of part images took 2.7 ms of fsync each on a virtual
/// disk: 5.5 s for 2,000 layers against 0.3 s of work).
pub const SYNC_ONE_BY_ONE_MAX: usize = 8;

/// Syncs the files at `paths` (written and closed) to disk: each with `fsync` when there are
/// few (see [`SYNC_ONE_BY_ONE_MAX`]), else, on Linux, the file system of each with one
/// `syncfs` (once per file system, not per batch: under a busy disk each `syncfs` waits for
/// everyone's writes, and 40 of them for 10,000 files took 30 s).
pub(crate) fn sync_paths(paths: &[PathBuf]) -> io::Result<()> {
    #[cfg(target_os = "linux")]
    if paths.len() > SYNC_ONE_BY_ONE_MAX {
        use std::os::unix::fs::MetadataExt;
        use std::os::unix::io::AsRawFd;
        let mut devices = Vec::new();
        for path in paths {
            let file = fs::File::open(path)?;
            let device = file.metadata()?.dev();
            if devices.contains(&device) {
                continue;
            }
            devices.push(device);
            // SAFETY: the descriptor is open for the whole call (`file` lives to the loop's end).
            if unsafe { libc::syncfs(file.as_raw_fd()) } != 0 {
                return Err(io::Error::last_os_error());
            }
        }
        return Ok(());
    }
    paths
        .iter()
        .try_for_each(|p| fs::File::open(p).and_then(|f| f.sync_all()))
}

/// Syncs the folder `dir` (its entries: a rename or a new file in it) where the system can.
pub(crate) fn sync_folder(dir: &Path) -> io::Result<()> {
    #[cfg(unix)]
    {
        fs::File::open(dir)?.sync_all()
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        Ok(())
    }
}

/// `dir/.name.PID.N.tmp`: hidden, unique per process and write (two threads writing the same
/// target never share a temporary file), on the same file system as `path`.
pub fn temporary_sibling(path: &Path) -> PathBuf {
    static WRITES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = WRITES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    path.with_file_name(format!(
        ".{}.{}.{n}.tmp",
        file_name(path),
        std::process::id()
    ))
}

pub(crate) fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The folder `path` is in (`.` for a bare name).
pub(crate) fn parent_or_dot(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// The process id in a temporary's name `.NAME.PID.N.tmp` of target name `name`.
fn temporary_pid(entry: &str, name: &str) -> Option<u32> {
    let rest = entry
        .strip_prefix('.')?
        .strip_prefix(name)?
        .strip_prefix('.')?
        .strip_suffix(".tmp")?;
    let (pid, n) = rest.split_once('.')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    (digits(pid) && digits(n)).then(|| pid.parse().ok())?
}

/// Whether process `pid` may still be running (and writing its temporaries). Where that cannot
/// be told (no `/proc`), every process may be.
pub(crate) fn may_be_running(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let proc = Path::new("/proc");
    !proc.join("self").exists() || proc.join(pid.to_string()).exists()
}

/// The temporaries of `target` (see [`temporary_sibling`]) left beside it by processes that are
/// no longer running (a killed run), sorted.
pub fn stale_temporaries(target: &Path) -> Vec<PathBuf> {
    let name = file_name(target);
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let Ok(entries) = fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut stale: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .filter(|e| {
            e.file_name()
                .to_str()
                .and_then(|n| temporary_pid(n, &name))
                .is_some_and(|pid| !may_be_running(pid))
        })
        .map(|e| dir.join(e.file_name()))
        .collect();
    stale.sort();
    stale
}

/// Removes the stale temporary files of `target` (see [`stale_temporaries`]), after completing
/// the sets a killed run left in its folder ([`complete_interrupted_sets`]: their temporaries
/// are not stale, they are the set's new files). Best effort: a temporary that cannot be removed
/// stays (it is hidden and harms nothing). Temporary folders are left to
/// [`crate::io::sequence::folder`], which knows what may be in them.
pub fn remove_stale_temporaries(target: &Path) {
    complete_interrupted_sets(parent_or_dot(target));
    for tmp in stale_temporaries(target) {
        if fs::symlink_metadata(&tmp).is_ok_and(|m| m.is_file()) {
            let _ = fs::remove_file(tmp);
        }
    }
}

/// [`remove_stale_temporaries`] for many targets: each folder read once (a set of thousands of
/// files in one folder read it thousands of times).
pub fn remove_stale_temporaries_of(targets: &[PathBuf]) {
    let mut folders: Vec<(&Path, std::collections::HashSet<String>)> = Vec::new();
    for target in targets {
        let dir = parent_or_dot(target);
        let name = file_name(target);
        match folders.iter_mut().find(|(d, _)| *d == dir) {
            Some((_, names)) => {
                names.insert(name);
            }
            None => folders.push((dir, [name].into())),
        }
    }
    for (dir, names) in folders {
        complete_interrupted_sets(dir);
        let Ok(entries) = fs::read_dir(dir) else {
            continue;
        };
        for entry in entries.filter_map(|e| e.ok()) {
            let Some(entry_name) = entry.file_name().to_str().map(str::to_string) else {
                continue;
            };
            let stale = temporary_target_name(&entry_name).is_some_and(|name| {
                names.contains(name)
                    && temporary_pid(&entry_name, name).is_some_and(|pid| !may_be_running(pid))
            });
            let path = dir.join(&entry_name);
            if stale && fs::symlink_metadata(&path).is_ok_and(|m| m.is_file()) {
                let _ = fs::remove_file(path);
            }
        }
    }
}

/// The target name in a temporary's name `.NAME.PID.N.tmp`, if it has that form.
fn temporary_target_name(entry: &str) -> Option<&str> {
    let rest = entry.strip_prefix('.')?.strip_suffix(".tmp")?;
    let mut parts = rest.rsplitn(3, '.');
    let (_n, _pid, name) = (parts.next()?, parts.next()?, parts.next()?);
    Some(name)
}

/// Swaps the names of two folders in one step where the system can (Linux), else by two
/// renames (with a moment between them when `target` is missing).
pub fn exchange_folders(staging: &Path, target: &Path) -> io::Result<()> {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::ffi::OsStrExt;
        let c = |p: &Path| std::ffi::CString::new(p.as_os_str().as_bytes());
        let (a, b) = (c(staging)?, c(target)?);
        // SAFETY: both are valid NUL-terminated paths that live across the call.
        let rc = unsafe {
            libc::renameat2(
                libc::AT_FDCWD,
                a.as_ptr(),
                libc::AT_FDCWD,
                b.as_ptr(),
                libc::RENAME_EXCHANGE,
            )
        };
        if rc == 0 {
            return Ok(());
        }
        let error = io::Error::last_os_error();
        // A file system or kernel without the exchange: fall back to two renames.
        if !matches!(
            error.raw_os_error(),
            Some(libc::EINVAL) | Some(libc::ENOSYS) | Some(libc::ENOTSUP)
        ) {
            return Err(error);
        }
    }
    let aside = temporary_sibling(target);
    fs::rename(target, &aside)?;
    if let Err(e) = fs::rename(staging, target) {
        let _ = fs::rename(&aside, target);
        return Err(e);
    }
    fs::rename(&aside, staging)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An empty folder of its own for one test, removed when the result drops.
    fn scratch(name: &str) -> tempfile::TempDir {
        crate::test_scratch::scratch(&format!("atomic-{name}"))
    }

    #[test]
    fn replaces_content_and_leaves_no_temporary() {
        let tmp = scratch("replace");
        let dir = tmp.path();
        let target = dir.join("a.json");
        write_atomic(&target, b"old").unwrap();
        write_atomic(&target, b"new").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"new");
        assert_eq!(fs::read_dir(dir).unwrap().count(), 1);
        // A write into a missing folder fails and leaves the target untouched.
        assert!(write_atomic(&dir.join("missing/b.json"), b"x").is_err());
    }

    #[test]
    fn writes_of_one_target_from_two_threads_do_not_mix() {
        let tmp = scratch("two");
        let dir = tmp.path();
        let target = dir.join("a.json");
        let contents = [vec![b'a'; 1 << 20], vec![b'b'; 1 << 20]];
        std::thread::scope(|scope| {
            for bytes in &contents {
                let target = &target;
                scope.spawn(move || {
                    for _ in 0..5 {
                        write_atomic(target, bytes).unwrap();
                    }
                });
            }
        });
        let written = fs::read(&target).unwrap();
        assert!(contents.contains(&written), "the target mixes two writes");
        assert_eq!(fs::read_dir(dir).unwrap().count(), 1);
    }

    #[cfg(unix)]
    #[test]
    fn writes_go_through_symbolic_links_and_folders_are_refused() {
        let tmp = scratch("links");
        let dir = tmp.path();
        let real = dir.join("real.png");
        fs::write(&real, b"old").unwrap();
        let link = dir.join("link.png");
        std::os::unix::fs::symlink("real.png", &link).unwrap();
        let chain = dir.join("chain.png");
        std::os::unix::fs::symlink(&link, &chain).unwrap();
        write_atomic(&chain, b"new").unwrap();
        assert!(fs::symlink_metadata(&link).unwrap().is_symlink());
        assert!(fs::symlink_metadata(&chain).unwrap().is_symlink());
        assert_eq!(fs::read(&real).unwrap(), b"new");
        // A dangling link creates its target, as cp does.
        let dangling = dir.join("dangling.png");
        std::os::unix::fs::symlink("made.png", &dangling).unwrap();
        write_atomic(&dangling, b"made").unwrap();
        assert_eq!(fs::read(dir.join("made.png")).unwrap(), b"made");
        // A loop is refused.
        let a = dir.join("a");
        std::os::unix::fs::symlink("b", &a).unwrap();
        std::os::unix::fs::symlink("a", dir.join("b")).unwrap();
        let err = write_atomic(&a, b"x").unwrap_err();
        assert!(err.to_string().contains("symbolic links"), "{err}");
        // A folder where a file is expected, and a file where a folder is.
        let err = write_atomic(dir, b"x").unwrap_err();
        assert!(err.to_string().contains("it is a folder"), "{err}");
        let err = resolve_output(&real, OutputKind::Folder).unwrap_err();
        assert!(err.to_string().contains("not a folder"), "{err}");
        assert_eq!(resolve_output(&link, OutputKind::File).unwrap(), real);
    }

    #[test]
    fn stale_temporaries_of_dead_processes_are_removed_and_live_ones_kept() {
        let tmp = scratch("stale");
        let dir = tmp.path();
        let target = dir.join("walk.json");
        fs::write(&target, b"previous").unwrap();
        // A pid above the kernel's largest (4194304) never runs.
        let dead = dir.join(".walk.json.4294967294.0.tmp");
        // This process's own, with a write number its writes never reach (the other tests'
        // writes count up from 0 in this process).
        let live = dir.join(format!(
            ".walk.json.{}.{}.tmp",
            std::process::id(),
            u64::MAX
        ));
        let other = dir.join(".other.json.4294967294.0.tmp");
        let unlike = dir.join(".walk.json.12x.0.tmp");
        for p in [&dead, &live, &other, &unlike] {
            fs::write(p, b"half").unwrap();
        }
        if Path::new("/proc/self").exists() {
            assert_eq!(stale_temporaries(&target), vec![dead.clone()]);
            write_atomic(&target, b"next").unwrap();
            assert!(!dead.exists());
        }
        for p in [&live, &other, &unlike] {
            assert!(p.exists(), "{}", p.display());
        }
    }

    #[test]
    fn temporary_names_parse() {
        assert_eq!(temporary_pid(".a.png.12.3.tmp", "a.png"), Some(12));
        assert_eq!(temporary_pid(".a.png.12.tmp", "a.png"), None);
        assert_eq!(temporary_pid(".b.png.12.3.tmp", "a.png"), None);
        assert_eq!(temporary_pid(".a.png.1.2.3.tmp", "a.png"), None);
        assert_eq!(temporary_target_name(".a.png.12.3.tmp"), Some("a.png"));
        assert_eq!(temporary_target_name(".a.b.png.12.3.tmp"), Some("a.b.png"));
        assert_eq!(temporary_target_name("a.png.12.3.tmp"), None);
        assert_eq!(temporary_target_name(".a.png"), None);
    }

    #[cfg(unix)]
    #[test]
    fn a_replaced_file_keeps_its_permissions_and_a_new_one_gets_the_defaults() {
        use std::os::unix::fs::PermissionsExt;
        let tmp = scratch("mode");
        let dir = tmp.path();
        let (script, fresh) = (dir.join("run.sh"), dir.join("fresh.txt"));
        write_atomic(&script, b"#!/bin/sh\n").unwrap();
        fs::set_permissions(&script, fs::Permissions::from_mode(0o750)).unwrap();
        write_atomic(&script, b"#!/bin/sh\ntrue\n").unwrap();
        let mode = |p: &Path| fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&script), 0o750);
        assert_eq!(fs::read(&script).unwrap(), b"#!/bin/sh\ntrue\n");
        write_atomic(&fresh, b"x").unwrap();
        // A new file: whatever the process's umask leaves of 0o666, never executable.
        assert_eq!(mode(&fresh) & 0o111, 0);
    }
}
