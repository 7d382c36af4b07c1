//! A rig document's part images kept in its folder (issue 44): written self-contained, read
//! confined.
//!
//! Writing ([`RigDocument::save_contained`], which [`RigDocument::save`] and
//! [`RigDocument::save_with`] run): each part's `image` is taken as the caller wrote it
//! (relative to the document's folder, or absolute). An image inside the folder keeps its
//! relative path; one outside it (`../art/arm.png`, an absolute path, a path through a link
//! leading out) is copied into `RIG.parts/` beside `RIG.json` (`RIG.parts/arm.png`, named by
//! the part as [`part_image_path`] makes file names) and the document names the copy. The
//! copies, any images given in memory (a layered file's parts, an image the editor holds whose
//! file is gone) and the document are written as one set ([`crate::io::set::write_set`]): a
//! failure leaves every earlier file as it was. Once the document is in place, the PNGs in
//! `RIG.parts/` that the document it replaced named and it no longer names (a re-rig with fewer
//! parts) are removed; nothing else there is touched (a person's own files stay), and links are
//! neither followed nor removed.
//!
//! Reading ([`RigDocument::load`] through [`confine_images`]): every part's image must lie in
//! the document's folder ([`crate::io::confine::confined`]): an absolute path, a `..` climbing out
//! and a symbolic link leading out are refused with one line naming the rig, the part, the
//! field and what to do. A rig from a stranger then reads nothing outside its folder.

use super::{DocumentError, JsonLayout, RigDocument};
use crate::io::confine::confined;
use image::RgbaImage;
use std::collections::HashSet;
use std::path::{Component, Path, PathBuf};

/// The folder beside the rig document at `doc_path` that holds the images sinew writes for it:
/// `RIG.parts/` beside `RIG.json`.
pub fn parts_folder(doc_path: &Path) -> PathBuf {
    doc_path.with_extension("parts")
}

/// The image file of the part at `layer_path` (`arm_l/hand`) under `parts_dir`: each name of
/// the path made a safe file name (characters other than letters, digits, `-`, `_`, `.` and
/// space become `_`; `.` and `..` become `_`).
pub fn part_image_path(parts_dir: &Path, layer_path: &str) -> PathBuf {
    let mut out = parts_dir.to_path_buf();
    let names: Vec<String> = layer_path
        .split('/')
        .map(|name| {
            let safe: String = name
                .chars()
                .map(|c| {
                    if c.is_alphanumeric() || "-_. ".contains(c) {
                        c
                    } else {
                        '_'
                    }
                })
                .collect();
            match safe.trim() {
                "" | "." | ".." => "_".to_string(),
                s => s.to_string(),
            }
        })
        .collect();
    for (i, name) in names.iter().enumerate() {
        if i + 1 == names.len() {
            out.push(format!("{name}.png"));
        } else {
            out.push(name);
        }
    }
    out
}

/// Images written with a document by [`RigDocument::save_contained`], beyond the files already
/// on disk.
#[derive(Clone, Debug, Default)]
pub struct PartImages<'a> {
    /// Files written in the same set, before the document: images the document names that are
    /// not on disk yet (a layered file's parts, `RIG.parts/arm_l/hand.png`), as PNG bytes.
    pub pending: Vec<(PathBuf, Vec<u8>)>,
    /// Per part (document order), its image as the caller holds it: written (as PNG) when the
    /// part's file cannot be read, so a document the editor saves names no missing file.
    pub held: Vec<Option<&'a RgbaImage>>,
}

/// What [`RigDocument::save_contained`] did besides writing the document.
#[derive(Clone, Debug, PartialEq)]
pub struct SavedRig {
    /// The document as written (its parts' `image` as the file names them).
    pub doc: RigDocument,
    /// Images copied (or written from memory) into `RIG.parts/`.
    pub copied: Vec<PathBuf>,
    /// PNGs removed from `RIG.parts/` because the document no longer names them.
    pub removed: Vec<PathBuf>,
}

/// `path` with its nearest existing ancestor resolved ([`std::fs::canonicalize`]: absolute,
/// symbolic links followed) and the components below it appended; `None` when no ancestor
/// resolves or a `..` follows a component that does not exist.
pub fn resolved(path: &Path) -> Option<PathBuf> {
    let mut missing = Vec::new();
    let mut existing = path;
    loop {
        if let Ok(base) = std::fs::canonicalize(if existing.as_os_str().is_empty() {
            Path::new(".")
        } else {
            existing
        }) {
            let mut out = base;
            for component in missing.iter().rev() {
                match component {
                    Component::Normal(name) => out.push(name),
                    Component::CurDir => {}
                    _ => return None,
                }
            }
            return Some(out);
        }
        let component = existing.components().next_back()?;
        missing.push(component);
        existing = existing.parent()?;
    }
}

/// `target` relative to `dir` (`..` where it must climb), both resolved ([`resolved`]); `None`
/// when either does not resolve.
pub fn relative_to(dir: &Path, target: &Path) -> Option<PathBuf> {
    let (dir, target) = (resolved(dir)?, resolved(target)?);
    let common = dir
        .components()
        .zip(target.components())
        .take_while(|(a, b)| a == b)
        .count();
    let ups = dir.components().count() - common;
    let mut out = PathBuf::new();
    for _ in 0..ups {
        out.push("..");
    }
    for c in target.components().skip(common) {
        out.push(c.as_os_str());
    }
    Some(out)
}

/// `path` as a document writes it: `/` between names.
fn written(path: &Path) -> String {
    path.components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

/// The folder of the document at `path` (`.` for a bare file name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Whether the relative `path` climbs above its start by `..` (by name: `a/../..` does).
pub(super) fn climbs_out(path: &Path) -> bool {
    let mut depth = 0usize;
    for component in path.components() {
        match component {
            Component::ParentDir => match depth.checked_sub(1) {
                Some(d) => depth = d,
                None => return true,
            },
            Component::Normal(_) => depth += 1,
            _ => {}
        }
    }
    false
}

/// The advice every refusal of a part image ends with.
pub(super) fn keep_inside(doc_path: &Path) -> String {
    let parts = parts_folder(doc_path);
    let parts = parts
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "RIG.parts".into());
    format!(
        "keep a rig's images in its folder (sinew rig and the editor's Save copy them into {parts}/)"
    )
}

/// Refuses any part image of `doc` (read from `path`) that leaves the document's folder: an
/// absolute path, a `..` climbing out, a symbolic link leading out (see the module doc).
pub fn confine_images(doc: &RigDocument, path: &Path) -> Result<(), DocumentError> {
    let folder = folder_of(path);
    let root = std::path::absolute(folder).unwrap_or_else(|_| folder.to_path_buf());
    for (index, part) in doc.parts.iter().enumerate() {
        confined(&root, Path::new(&part.image)).map_err(|problem| DocumentError::Confined {
            path: path.to_path_buf(),
            part: part.name.clone(),
            index,
            problem,
            advice: keep_inside(path),
        })?;
    }
    Ok(())
}

/// A part image to copy into `RIG.parts/`: where from, and the bytes when given in memory.
struct ToCopy {
    part: usize,
    from: PathBuf,
}

impl RigDocument {
    /// Writes the document to `path` self-contained (see the module doc): images outside its
    /// folder copied into `RIG.parts/`, `images.pending` and the copies written with the
    /// document as one set, then the PNGs of `RIG.parts/` the document no longer names
    /// removed. Returns the document as written and what was copied and removed.
    pub fn save_contained(
        &self,
        path: &Path,
        layout: JsonLayout,
        images: PartImages,
    ) -> Result<SavedRig, DocumentError> {
        let folder = folder_of(path);
        let write_error = |at: &Path, source: std::io::Error| DocumentError::Write {
            path: at.to_path_buf(),
            source,
        };
        let root = std::path::absolute(folder).map_err(|e| write_error(path, e))?;
        let parts_dir = parts_folder(path);
        let parts_name = parts_dir.file_name().map(PathBuf::from).unwrap_or_default();
        let pending_at: Vec<Option<PathBuf>> =
            images.pending.iter().map(|(p, _)| resolved(p)).collect();
        let pending_bytes = |at: &Path| -> Option<&[u8]> {
            let at = resolved(at)?;
            let i = pending_at.iter().position(|p| p.as_deref() == Some(&at))?;
            Some(images.pending[i].1.as_slice())
        };
        let encode = |image: &RgbaImage, to: &Path| {
            crate::io::image::encode_png(image).map_err(|e| DocumentError::EncodePart {
                path: to.to_path_buf(),
                reason: e.to_string(),
            })
        };
        let mut out = self.clone();
        let mut files: Vec<(PathBuf, Vec<u8>)> = images.pending.clone();
        // Every file the document names, resolved: no copy may take one's place.
        let mut claimed: HashSet<PathBuf> = pending_at.iter().flatten().cloned().collect();
        let mut copies = Vec::new();
        let mut copied = Vec::new();
        for (i, part) in self.parts.iter().enumerate() {
            let image = Path::new(&part.image);
            let from = if image.has_root() {
                image.to_path_buf()
            } else {
                folder.join(image)
            };
            let inside = relative_to(folder, &from)
                .filter(|rel| !rel.as_os_str().is_empty())
                .and_then(|rel| confined(&root, &rel).ok().map(|at| (rel, at)));
            let Some((rel, at)) = inside else {
                copies.push(ToCopy { part: i, from });
                continue;
            };
            out.parts[i].image = written(&rel);
            claimed.insert(resolved(&at).unwrap_or(at.clone()));
            // An image named inside whose file is gone, held in memory: written again.
            if std::fs::symlink_metadata(&at).is_err() && pending_bytes(&at).is_none() {
                if let Some(held) = images.held.get(i).copied().flatten() {
                    files.push((at.clone(), encode(held, &at)?));
                    copied.push(at);
                }
            }
        }
        if !copies.is_empty() {
            // The copies' folder must itself stay inside (not a link leading out).
            confined(&root, &parts_name).map_err(|problem| DocumentError::PartsFolder {
                path: path.to_path_buf(),
                problem,
            })?;
        }
        for copy in copies {
            let part = &self.parts[copy.part];
            let base = part_image_path(&parts_dir, &part.name);
            let target = (1..)
                .map(|n| match n {
                    1 => base.clone(),
                    n => base.with_file_name(format!(
                        "{}-{n}.png",
                        base.file_stem().unwrap_or_default().to_string_lossy()
                    )),
                })
                .find(|t| !claimed.contains(&resolved(t).unwrap_or(t.clone())))
                .unwrap_or(base);
            claimed.insert(resolved(&target).unwrap_or(target.clone()));
            let bytes = match pending_bytes(&copy.from) {
                Some(bytes) => bytes.to_vec(),
                None => match std::fs::read(&copy.from) {
                    Ok(bytes) => bytes,
                    Err(source) => match images.held.get(copy.part).copied().flatten() {
                        Some(held) => encode(held, &target)?,
                        None => {
                            return Err(DocumentError::CopyPart {
                                path: path.to_path_buf(),
                                part: part.name.clone(),
                                from: copy.from,
                                source,
                            })
                        }
                    },
                },
            };
            let rel = target.strip_prefix(folder).unwrap_or(&target);
            out.parts[copy.part].image = written(rel);
            // A copy already there with the same bytes (an earlier save) is left as it is.
            if std::fs::read(&target).ok().as_deref() != Some(bytes.as_slice()) {
                files.push((target.clone(), bytes));
            }
            copied.push(target);
        }
        files.push((path.to_path_buf(), out.to_text(path, layout)?.into_bytes()));
        for (file, _) in &files {
            if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir).map_err(|e| write_error(file, e))?;
            }
        }
        let earlier = earlier_parts(path, &parts_dir);
        crate::io::set::write_set(&files).map_err(|(at, source)| write_error(&at, source))?;
        let removed = remove_unnamed(&out, path, &parts_dir, earlier);
        Ok(SavedRig {
            doc: out,
            copied,
            removed,
        })
    }
}

/// The PNGs in `parts_dir` that the document on disk at `path` (before a save replaces it)
/// names: the files an earlier save wrote there. Read loosely (any JSON with `parts[].image`);
/// only names that go into `parts_dir` by plain names (no `..`, not absolute) and are regular
/// files in real folders inside it count (a link is neither followed nor removed). Canonical
/// paths.
fn earlier_parts(path: &Path, parts_dir: &Path) -> Vec<PathBuf> {
    let Some(parts_name) = parts_dir.file_name() else {
        return Vec::new();
    };
    let Ok(real_dir) = std::fs::canonicalize(parts_dir) else {
        return Vec::new();
    };
    if !std::fs::symlink_metadata(parts_dir).is_ok_and(|m| m.is_dir()) {
        return Vec::new();
    }
    let Some(doc) = std::fs::read_to_string(path)
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
    else {
        return Vec::new();
    };
    let folder = folder_of(path);
    let mut out = Vec::new();
    let images = doc.get("parts").and_then(|p| p.as_array());
    for image in images
        .into_iter()
        .flatten()
        .filter_map(|p| p.get("image")?.as_str())
    {
        let image = Path::new(image);
        let mut names = image.components();
        let plain = image
            .components()
            .all(|c| matches!(c, Component::Normal(_)));
        if !plain
            || names.next() != Some(Component::Normal(parts_name))
            || !image
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("png"))
        {
            continue;
        }
        let at = folder.join(image);
        // Every folder on the way a real one, the file a regular file.
        let mut real = true;
        let mut walked = folder.to_path_buf();
        for c in image.components() {
            walked.push(c);
            real &= std::fs::symlink_metadata(&walked)
                .is_ok_and(|m| m.is_dir() || (walked == at && m.is_file()));
        }
        match std::fs::canonicalize(&at) {
            Ok(canon) if real && canon.starts_with(&real_dir) => out.push(canon),
            _ => {}
        }
    }
    out
}

/// Removes the files of `earlier` (PNGs an earlier save wrote in `parts_dir`,
/// [`earlier_parts`]) that `doc` (written at `path`) no longer names, and the folders in
/// `parts_dir` (and `parts_dir` itself) that leaves empty; returns the files removed. Nothing
/// else is touched (a person's files there stay); failures are left alone (the document is
/// already in place).
fn remove_unnamed(
    doc: &RigDocument,
    path: &Path,
    parts_dir: &Path,
    earlier: Vec<PathBuf>,
) -> Vec<PathBuf> {
    let folder = folder_of(path);
    let named: HashSet<PathBuf> = doc
        .parts
        .iter()
        .filter_map(|p| std::fs::canonicalize(folder.join(&p.image)).ok())
        .collect();
    let Ok(real_dir) = std::fs::canonicalize(parts_dir) else {
        return Vec::new();
    };
    let mut removed = Vec::new();
    for file in earlier {
        if named.contains(&file) || std::fs::remove_file(&file).is_err() {
            continue;
        }
        // remove_dir removes only an empty folder.
        let mut dir = file.parent();
        while let Some(d) = dir.filter(|d| d.starts_with(&real_dir)) {
            if std::fs::remove_dir(d).is_err() {
                break;
            }
            dir = d.parent();
        }
        removed.push(file);
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn part_paths_are_safe_file_names() {
        let dir = Path::new("rig.parts");
        assert_eq!(
            part_image_path(dir, "arm_l/hand"),
            dir.join("arm_l").join("hand.png")
        );
        assert_eq!(
            part_image_path(dir, "../x:y/.."),
            dir.join("_").join("x_y").join("_.png")
        );
    }

    #[test]
    fn relative_paths_climb_where_they_must() {
        let tmp = crate::test_scratch::scratch("rel-to");
        let dir = tmp.path();
        std::fs::create_dir_all(dir.join("a/b")).unwrap();
        std::fs::create_dir_all(dir.join("c")).unwrap();
        assert_eq!(
            relative_to(&dir.join("a/b"), &dir.join("c/x.png")).unwrap(),
            Path::new("../../c/x.png")
        );
        assert_eq!(
            relative_to(&dir.join("c"), &dir.join("c/./rig.parts/arm/hand.png")).unwrap(),
            Path::new("rig.parts/arm/hand.png")
        );
        assert!(resolved(&dir.join("nowhere/../x")).is_none());
    }
}
