//! Writing files so that a reader never sees half of one.
//!
//! The content goes to a temporary file beside the target, which is then renamed over it: the
//! rename is atomic on one file system, so the target holds either its old or its new content.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` atomically (temporary file + rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let tmp = temporary_sibling(path);
    let result = (|| {
        let mut file = fs::File::create(&tmp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        // The temporary file may not exist; nothing else to report.
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// `dir/.name.PID.N.tmp`: hidden, unique per process and write (two threads writing the same
/// target never share a temporary file), on the same file system as `path`.
fn temporary_sibling(path: &Path) -> PathBuf {
    static WRITES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = WRITES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.{n}.tmp", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_content_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("sinew-atomic-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let target = dir.join("a.json");
        write_atomic(&target, b"old").unwrap();
        write_atomic(&target, b"new").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"new");
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 1);
        // A write into a missing folder fails and leaves the target untouched.
        assert!(write_atomic(&dir.join("missing/b.json"), b"x").is_err());
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn writes_of_one_target_from_two_threads_do_not_mix() {
        let dir = std::env::temp_dir().join(format!("sinew-atomic-two-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
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
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 1);
        fs::remove_dir_all(&dir).unwrap();
    }
}
