//! Paths named inside files, confined to the folder they are relative to.
//!
//! In: the root folder (a batch manifest's folder, a Spine script's folder, …) and a path as a
//! file wrote it. Out: the path under the root, or why it is refused: an absolute path, a `..`
//! that climbs out of the root, or an existing component (a symbolic link) whose target lies
//! outside it. `..` and `.` are resolved by name, and the returned path is that lexical one,
//! so the operating system never walks a `link/..`. A manifest or a Spine script from a
//! stranger can then read and write only inside its own folder. Paths a person types on the
//! command line are not confined (`-o ../out` means what it says); only paths inside files are.
//!
//! The check is made before any work; a link swapped in afterwards (between the check and the
//! write) is not caught here.

use std::path::{Component, Path, PathBuf};

/// Why a path written in a file is refused; displays as `"PATH" …` (the path as written), for
/// the caller to prefix with the file and the field.
#[derive(Debug, thiserror::Error)]
pub enum PathError {
    #[error("\"{written}\" is empty")]
    Empty { written: String },
    #[error("\"{written}\" is absolute; paths here are relative to {}", .root.display())]
    Absolute { written: String, root: PathBuf },
    #[error("\"{written}\" climbs out of {} by '..'", .root.display())]
    Climbs { written: String, root: PathBuf },
    #[error("\"{written}\" leads out of {} through a symbolic link ({} is {})", .root.display(), .link.display(), .target.display())]
    Link {
        written: String,
        root: PathBuf,
        /// The existing part of the path that resolves outside.
        link: PathBuf,
        /// Where it resolves.
        target: PathBuf,
    },
    #[error("\"{written}\": cannot resolve {}: {source}", .at.display())]
    Resolve {
        written: String,
        at: PathBuf,
        source: std::io::Error,
    },
}

/// `relative` under `root`: refused when empty, absolute, climbing out of `root` by `..`, or
/// when its longest existing part resolves (symbolic links followed) outside `root` resolved.
/// The path returned is `root` joined with `relative` with `.` and `..` resolved by name.
pub fn confined(root: &Path, relative: &Path) -> Result<PathBuf, PathError> {
    confined_from(root, Path::new(""), relative)
}

/// [`confined`] for a path written relative to `base`, a folder inside `root` given relative
/// to it (a rig document's folder inside a manifest's): `base/relative` must stay in `root`;
/// errors show `relative` as written.
pub fn confined_from(root: &Path, base: &Path, relative: &Path) -> Result<PathBuf, PathError> {
    let written = relative.to_string_lossy().into_owned();
    if relative.as_os_str().is_empty() {
        return Err(PathError::Empty { written });
    }
    if relative.has_root() {
        return Err(PathError::Absolute {
            written,
            root: root.to_path_buf(),
        });
    }
    let mut inside = PathBuf::new();
    for component in base.components().chain(relative.components()) {
        match component {
            Component::Prefix(_) | Component::RootDir => {
                return Err(PathError::Absolute {
                    written,
                    root: root.to_path_buf(),
                })
            }
            Component::CurDir => {}
            Component::ParentDir => {
                if !inside.pop() {
                    return Err(PathError::Climbs {
                        written,
                        root: root.to_path_buf(),
                    });
                }
            }
            Component::Normal(name) => inside.push(name),
        }
    }
    let path = root.join(&inside);
    let resolve = |at: &Path| {
        std::fs::canonicalize(at).map_err(|source| PathError::Resolve {
            written: written.clone(),
            at: at.to_path_buf(),
            source,
        })
    };
    let real_root = resolve(root)?;
    // The longest existing part of the path: where a link would take it.
    let mut existing = path.as_path();
    while existing != root && std::fs::symlink_metadata(existing).is_err() {
        match existing.parent() {
            Some(parent) => existing = parent,
            None => break,
        }
    }
    if existing != root {
        let target = match std::fs::canonicalize(existing) {
            Ok(target) => target,
            // A dangling link: where it points, joined as the OS would, by name.
            Err(_) => match std::fs::read_link(existing) {
                Ok(to) => existing.parent().unwrap_or(root).join(to),
                Err(source) => {
                    return Err(PathError::Resolve {
                        written,
                        at: existing.to_path_buf(),
                        source,
                    })
                }
            },
        };
        if !target.starts_with(&real_root) {
            return Err(PathError::Link {
                written,
                root: root.to_path_buf(),
                link: existing.to_path_buf(),
                target,
            });
        }
    }
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dot_dot_inside_the_root_is_kept_and_leaving_it_refused() {
        let dir = crate::test_scratch::scratch("confine");
        let root = dir.path();
        assert_eq!(
            confined(root, Path::new("a/./b/../c.png")).unwrap(),
            root.join("a/c.png")
        );
        assert!(matches!(
            confined(root, Path::new("a/../../c.png")),
            Err(PathError::Climbs { .. })
        ));
        assert!(matches!(
            confined(root, Path::new("/etc/passwd")),
            Err(PathError::Absolute { .. })
        ));
        assert!(matches!(
            confined(root, Path::new("")),
            Err(PathError::Empty { .. })
        ));
    }

    #[test]
    fn links_out_are_refused_and_links_within_kept() {
        let dir = crate::test_scratch::scratch("confine-links");
        let root = dir.path().join("root");
        let outside = dir.path().join("outside");
        std::fs::create_dir_all(root.join("real")).unwrap();
        std::fs::create_dir_all(&outside).unwrap();
        std::os::unix::fs::symlink(&outside, root.join("out")).unwrap();
        std::os::unix::fs::symlink(root.join("real"), root.join("in")).unwrap();
        std::os::unix::fs::symlink(dir.path().join("nowhere"), root.join("dangling")).unwrap();
        let e = confined(&root, Path::new("out/x.json")).unwrap_err();
        assert!(matches!(e, PathError::Link { .. }), "{e}");
        assert!(matches!(
            confined(&root, Path::new("dangling")),
            Err(PathError::Link { .. })
        ));
        assert_eq!(
            confined(&root, Path::new("in/x.json")).unwrap(),
            root.join("in/x.json")
        );
        assert_eq!(
            confined(&root, Path::new("new/deeper/x.json")).unwrap(),
            root.join("new/deeper/x.json")
        );
    }
}
