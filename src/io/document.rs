//! The native rig document (`sinew-rig`, version 1).
//!
//! In: a JSON file as in `docs/formats.md`. Out: a [`RigDocument`] that has been checked: format name and
//! version known, triangle indices in range, coordinates finite, weight rows matching vertices
//! and handles, part names unique, animations well formed (each on its own, see
//! [`Animation::from_json`]; against the rig: [`RigDocument::check_animations`]). Image paths are
//! stored relative to the document's folder. Saving writes atomically.

use crate::anim::{AnimError, Animation};
use crate::geom::Point;
use crate::mesh::{Mesh, MeshOptions};
use crate::rig::{HandleError, Handles};
use crate::trace::TraceOptions;
use crate::weights::WeightOptions;
use serde::{Deserialize, Deserializer, Serialize};
use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};

#[path = "document_parts.rs"]
mod parts;
pub use parts::{
    confine_images, part_image_path, parts_folder, relative_to, resolved, PartImages, SavedRig,
};

/// The `format` field of every rig document.
pub const RIG_FORMAT: &str = "sinew-rig";
/// The version this build reads and writes.
pub const RIG_VERSION: u32 = 1;

/// A whole rig: parts on one canvas, their meshes and weights, the handles and animations.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RigDocument {
    #[schemars(extend("const" = RIG_FORMAT))]
    pub format: String,
    #[schemars(extend("const" = RIG_VERSION))]
    pub version: u32,
    /// Canvas size in px, shared by every part's image.
    pub canvas: [u32; 2],
    /// Parts in draw order (back to front).
    pub parts: Vec<PartDoc>,
    #[serde(default)]
    pub handles: Handles,
    /// Animations by name, parsed and checked each on its own when the document is read.
    #[serde(
        default,
        skip_serializing_if = "BTreeMap::is_empty",
        deserialize_with = "deserialize_animations"
    )]
    #[schemars(with = "crate::schema::Animations")]
    pub animations: BTreeMap<String, Animation>,
    /// Events the animations fire, by name, with their default payloads. Absent when none.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub events: crate::anim::EventDefs,
    /// The options the meshes were built with, so a re-trace reproduces them.
    #[serde(default)]
    pub options: BuildOptions,
    /// Handles whose weights are locked: painting leaves them alone and recomputing the weights
    /// keeps them (a cage locks all its columns). Absent when none is locked.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub locked: Vec<String>,
    /// Skins by name: slot → the attachment it shows instead of its own part (see
    /// [`super::slots`]). Absent when none.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub skins: super::slots::Skins,
    /// What the last automatic rig installed in the editor followed (its template), so the
    /// editor offers it again on reopen. Absent when no proposal was installed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub autorig: Option<AutorigRecord>,
    /// The runtime the rig is made for ([`RuntimeTarget`]). Absent: none; animations play
    /// exactly.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<RuntimeTarget>,
}

/// What an automatic rig (`sinew autorig`, the editor's *Propose handles*) followed, as the
/// rig document records it (`"autorig": {"template": "humanoid"}`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AutorigRecord {
    /// The template the proposal followed.
    pub template: RecordedTemplate,
}

/// The runtime a rig is made for: `pose`, `render` and the editor play its animations as that
/// runtime plays the export of its format (`--match-runtime`), unless told to play exactly.
/// The rig document records it (`"target": "spine-4.2"`); `sinew target` sets it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
pub enum RuntimeTarget {
    #[serde(rename = "spine-4.1")]
    Spine41,
    #[serde(rename = "spine-4.2")]
    Spine42,
    #[serde(rename = "spine-4.3")]
    Spine43,
    #[serde(rename = "dragonbones")]
    DragonBones,
    #[serde(rename = "gltf")]
    Gltf,
}

impl RuntimeTarget {
    /// Every target, in the order `sinew target` lists them.
    pub const ALL: [RuntimeTarget; 5] = [
        RuntimeTarget::Spine41,
        RuntimeTarget::Spine42,
        RuntimeTarget::Spine43,
        RuntimeTarget::DragonBones,
        RuntimeTarget::Gltf,
    ];

    /// The name the file writes (`spine-4.2`).
    pub fn name(self) -> &'static str {
        match self {
            RuntimeTarget::Spine41 => "spine-4.1",
            RuntimeTarget::Spine42 => "spine-4.2",
            RuntimeTarget::Spine43 => "spine-4.3",
            RuntimeTarget::DragonBones => "dragonbones",
            RuntimeTarget::Gltf => "gltf",
        }
    }

    /// How people call it (`Spine 4.2`).
    pub fn label(self) -> &'static str {
        match self {
            RuntimeTarget::Spine41 => "Spine 4.1",
            RuntimeTarget::Spine42 => "Spine 4.2",
            RuntimeTarget::Spine43 => "Spine 4.3",
            RuntimeTarget::DragonBones => "DragonBones",
            RuntimeTarget::Gltf => "glTF",
        }
    }

    /// The target named `name`, as [`Self::name`] writes it.
    pub fn parse(name: &str) -> Option<RuntimeTarget> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }
}

/// The template an automatic rig followed: one of the autorig's templates, or none (bones from
/// the drawing's shape or one per layer).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum RecordedTemplate {
    None,
    Humanoid,
    Quadruped,
}

/// How the document's meshes were built.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct BuildOptions {
    pub trace: TraceOptions,
    pub mesh: MeshOptions,
    pub weights: WeightOptions,
    /// How the skinning IK solves drags on this rig.
    pub ik: crate::ik::IkOptions,
}

/// One image of the rig with its mesh.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PartDoc {
    pub name: String,
    /// The slot this part is another attachment of: the name of a part without `slot` (see
    /// [`super::slots`]). Absent: the part is a slot, and its own default attachment.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slot: Option<String>,
    /// Path of the image, relative to the document's folder.
    pub image: String,
    /// Canvas position of the image's top-left pixel, px (y down). Absent: `[0, 0]`, the image
    /// lies at the canvas's corner (a PNG layer covering the canvas). Parts from layered files
    /// keep only their layer's opaque pixels, placed here.
    #[serde(default, skip_serializing_if = "is_at_corner")]
    pub offset_px: [i32; 2],
    pub mesh: MeshDoc,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights: Option<WeightsDoc>,
    /// Weights computed for earlier handles, saved only while some handle is locked and the
    /// weights need computing again: the next computation keeps the locked handles' columns
    /// from them. Never used to pose.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stale_weights: Option<WeightsDoc>,
}

impl PartDoc {
    /// Whether an image of `image_px` (width, height) placed at this part's `offset_px` holds its
    /// mesh, with `reach_px` of transparent frame allowed around the image (meshes reach past
    /// the opaque pixels by the trace padding). A part's image that fails this is not the one
    /// its mesh was traced from (an image file replaced by one of another size).
    pub fn image_holds_mesh(&self, image_px: [u32; 2], reach_px: f64) -> bool {
        let [ox, oy] = self.offset_px.map(f64::from);
        let [w, h] = image_px.map(f64::from);
        self.mesh.vertices.iter().all(|&Point { coords: v }| {
            let (x, y) = (v.x, v.y);
            x >= ox - reach_px
                && y >= oy - reach_px
                && x <= ox + w + reach_px
                && y <= oy + h + reach_px
        })
    }
}

fn is_at_corner(offset_px: &[i32; 2]) -> bool {
    *offset_px == [0, 0]
}

/// A mesh as stored: vertices in canvas px, triangles as vertex indices.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MeshDoc {
    #[schemars(with = "Vec<[f64; 2]>")]
    pub vertices: Vec<Point>,
    pub triangles: Vec<[u32; 3]>,
}

/// Sparse skinning weights: `rows[i]` lists vertex `i`'s non-zero weights as
/// `(index into handles, weight)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WeightsDoc {
    pub handles: Vec<String>,
    /// Written at f32 precision ([`RigDocument::save_with`]); read as f64.
    #[serde(serialize_with = "rows_at_f32")]
    pub rows: Vec<Vec<(u32, f64)>>,
}

/// Serializes weight rows with each weight as the shortest text of its nearest f32.
fn rows_at_f32<S: serde::Serializer>(
    rows: &[Vec<(u32, f64)>],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let mut seq = serializer.serialize_seq(Some(rows.len()))?;
    for row in rows {
        // serde_json writes an f32 as its shortest round-trip text.
        let row: Vec<(u32, f32)> = row.iter().map(|&(h, w)| (h, w as f32)).collect();
        seq.serialize_element(&row)?;
    }
    seq.end()
}

/// How a document's JSON is laid out on disk.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JsonLayout {
    /// One line: the smallest file (default).
    #[default]
    Compact,
    /// Indented, one value per line: for reading and diffing by hand.
    Pretty,
}

/// What is wrong with a rig document.
#[derive(Debug, thiserror::Error)]
pub enum DocumentError {
    #[error("{path}: cannot read: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: cannot write: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not valid JSON: {reason}")]
    Json { path: PathBuf, reason: String },
    #[error("{path}: not a sinew rig (format is {found}, expected \"{RIG_FORMAT}\")")]
    WrongFormat { path: PathBuf, found: String },
    #[error("{path}: unsupported rig version {found} (this sinew reads version {RIG_VERSION})")]
    WrongVersion { path: PathBuf, found: String },
    #[error("{path}: {reason}")]
    Invalid { path: PathBuf, reason: String },
    #[error("{path}: {source}")]
    Animation { path: PathBuf, source: AnimError },
    /// A part image that leaves the document's folder ([`confine_images`]).
    #[error("{}: part '{part}' (parts[{index}].image): {problem}: {advice}", .path.display())]
    Confined {
        path: PathBuf,
        part: String,
        index: usize,
        problem: crate::io::PathError,
        /// What to do instead.
        advice: String,
    },
    /// `RIG.parts/`, where images outside the folder are copied, itself leads out of it.
    #[error("{}: cannot copy the images into the rig's folder: {problem}", .path.display())]
    PartsFolder {
        path: PathBuf,
        problem: crate::io::PathError,
    },
    #[error("{}: cannot copy part '{part}''s image {} into the rig's folder: {source}", .path.display(), .from.display())]
    CopyPart {
        path: PathBuf,
        part: String,
        from: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: cannot encode the image: {reason}", .path.display())]
    EncodePart { path: PathBuf, reason: String },
}

/// The `animations` map through [`crate::anim::animations_from_json`], whose messages name the
/// animation, the timeline and the key.
fn deserialize_animations<'de, D: Deserializer<'de>>(
    deserializer: D,
) -> Result<BTreeMap<String, Animation>, D::Error> {
    let value = serde_json::Value::deserialize(deserializer)?;
    crate::anim::animations_from_json(&value).map_err(serde::de::Error::custom)
}

impl From<&Mesh> for MeshDoc {
    fn from(mesh: &Mesh) -> Self {
        MeshDoc {
            vertices: mesh.vertices.clone(),
            triangles: mesh.triangles.clone(),
        }
    }
}

impl MeshDoc {
    pub fn to_mesh(&self) -> Mesh {
        Mesh {
            vertices: self.vertices.clone(),
            triangles: self.triangles.clone(),
        }
    }
}

impl RigDocument {
    /// An empty document for a canvas of `canvas` px.
    pub fn new(canvas: [u32; 2]) -> Self {
        RigDocument {
            format: RIG_FORMAT.into(),
            version: RIG_VERSION,
            canvas,
            parts: Vec::new(),
            handles: Handles::default(),
            animations: BTreeMap::new(),
            events: BTreeMap::new(),
            options: BuildOptions::default(),
            locked: Vec::new(),
            skins: BTreeMap::new(),
            autorig: None,
            target: None,
        }
    }

    /// Reads and checks the document at `path`; its part images must lie in its folder
    /// ([`confine_images`]: no absolute path, no `..` out of it, no link leading out).
    pub fn load(path: &Path) -> Result<Self, DocumentError> {
        let text = std::fs::read_to_string(path).map_err(|source| DocumentError::Read {
            path: path.into(),
            source,
        })?;
        let doc = Self::from_json(&text, path)?;
        confine_images(&doc, path)?;
        Ok(doc)
    }

    /// Parses and checks a document; `path` only names it in errors.
    pub fn from_json(text: &str, path: &Path) -> Result<Self, DocumentError> {
        let json_error = |e: serde_json::Error| DocumentError::Json {
            path: path.into(),
            reason: e.to_string(),
        };
        // Format and version first, so a newer document says so instead of failing on a field.
        let mut value: serde_json::Value = serde_json::from_str(text).map_err(json_error)?;
        let field = |name: &str| {
            value
                .get(name)
                .map(|v| v.to_string())
                .unwrap_or_else(|| "missing".into())
        };
        if value.get("format").and_then(|f| f.as_str()) != Some(RIG_FORMAT) {
            return Err(DocumentError::WrongFormat {
                path: path.into(),
                found: field("format"),
            });
        }
        if value.get("version").and_then(|v| v.as_u64()) != Some(RIG_VERSION as u64) {
            return Err(DocumentError::WrongVersion {
                path: path.into(),
                found: field("version"),
            });
        }
        // The animations on their own, for an error that keeps its place in them.
        let animations = match value.as_object_mut().and_then(|o| o.remove("animations")) {
            Some(animations) => {
                crate::anim::animations_from_json(&animations).map_err(|source| {
                    DocumentError::Animation {
                        path: path.into(),
                        source,
                    }
                })?
            }
            None => BTreeMap::new(),
        };
        // Valid JSON by now: what is left is a field of the wrong shape.
        let mut doc: RigDocument =
            serde_json::from_value(value).map_err(|e| DocumentError::Invalid {
                path: path.into(),
                reason: format!("not a valid rig document: {e}"),
            })?;
        doc.animations = animations;
        // A document with no part draws nothing (a blank PNG) and exports nothing; only the
        // editor makes one, before its first layer, and never saves it.
        if doc.parts.is_empty() {
            return Err(DocumentError::Invalid {
                path: path.into(),
                reason: "the rig has no parts (\"parts\": []): rig at least one image (sinew rig IMAGE...)".into(),
            });
        }
        doc.validate().map_err(|reason| DocumentError::Invalid {
            path: path.into(),
            reason,
        })?;
        // Image paths are relative to the document's folder and stay in it: the names alone
        // are checked here (empty, absolute, `..` out of the folder); `load` also follows the
        // links ([`confine_images`]).
        for (index, part) in doc.parts.iter().enumerate() {
            let image = Path::new(&part.image);
            let written = part.image.clone();
            let root = path.parent().unwrap_or(Path::new("")).to_path_buf();
            let problem = if image.as_os_str().is_empty() {
                Some(crate::io::PathError::Empty { written })
            } else if image.has_root() {
                Some(crate::io::PathError::Absolute { written, root })
            } else if parts::climbs_out(image) {
                Some(crate::io::PathError::Climbs { written, root })
            } else {
                None
            };
            if let Some(problem) = problem {
                return Err(DocumentError::Confined {
                    path: path.into(),
                    part: part.name.clone(),
                    index,
                    problem,
                    advice: parts::keep_inside(path),
                });
            }
        }
        Ok(doc)
    }

    /// Writes the document to `path` atomically and self-contained, as compact JSON
    /// ([`JsonLayout::Compact`]; see [`RigDocument::save_contained`]).
    pub fn save(&self, path: &Path) -> Result<(), DocumentError> {
        self.save_with(path, JsonLayout::Compact)
    }

    /// Writes the document to `path` atomically and self-contained in `layout`: part images
    /// outside the document's folder are copied into `RIG.parts/` with it
    /// ([`RigDocument::save_contained`]). Weights are written at f32 precision (the shortest
    /// text that reads back as the weight's nearest f32): a row then sums to one within 1e-7,
    /// well inside [`WEIGHT_TOLERANCE`]. The bundled character's document is 1.3 MB this way
    /// (compact), against 5.7 MB pretty-printed with f64 weights.
    pub fn save_with(&self, path: &Path, layout: JsonLayout) -> Result<(), DocumentError> {
        self.save_contained(path, layout, PartImages::default())
            .map(|_| ())
    }

    /// The document's JSON text in `layout`, ended by a newline.
    fn to_text(&self, path: &Path, layout: JsonLayout) -> Result<String, DocumentError> {
        let json_error = |e: serde_json::Error| DocumentError::Json {
            path: path.into(),
            reason: e.to_string(),
        };
        let mut text = match layout {
            JsonLayout::Compact => serde_json::to_string(self).map_err(json_error)?,
            JsonLayout::Pretty => serde_json::to_string_pretty(self).map_err(json_error)?,
        };
        text.push('\n');
        Ok(text)
    }

    /// Checks every animation against the handles and the parts: the names its timelines use,
    /// its cages' vertex counts, its draw orders (see [`Animation::check_rig`]). Not part of
    /// [`RigDocument::validate`]: an edited rig may drop a handle an animation still names, and
    /// the document must still open; what poses an animation checks it first.
    pub fn check_animations(&self) -> Result<(), AnimError> {
        let slots = self.slot_names();
        crate::anim::check_animations(&self.animations, &self.handles, &slots, &self.events)?;
        self.animations
            .iter()
            .try_for_each(|(name, animation)| animation.check_attachments(name, self))?;
        let sizes: Vec<(&str, usize)> = self
            .parts
            .iter()
            .map(|p| (p.name.as_str(), p.mesh.vertices.len()))
            .collect();
        crate::anim::deform::check_deform_sizes(&self.animations, &sizes)
    }

    /// The image of `part`, resolved against the folder of the document at `doc_path`.
    pub fn image_path(doc_path: &Path, part: &PartDoc) -> PathBuf {
        doc_path.parent().unwrap_or(Path::new("")).join(&part.image)
    }

    /// Everything a reader relies on, as a one-line reason.
    pub fn validate(&self) -> Result<(), String> {
        if self.canvas[0] == 0 || self.canvas[1] == 0 {
            return Err(format!(
                "canvas {}×{} is empty",
                self.canvas[0], self.canvas[1]
            ));
        }
        self.handles
            .validate()
            .map_err(|e: HandleError| format!("handles: {e}"))?;
        if let Some(name) = self
            .locked
            .iter()
            .find(|n| !self.handles.names().any(|h| h == n.as_str()))
        {
            return Err(format!("locked handle '{name}' is not a handle"));
        }
        for (name, event) in &self.events {
            event.check(name).map_err(|e| e.to_string())?;
        }
        let mut names = HashSet::new();
        for part in &self.parts {
            if !names.insert(part.name.as_str()) {
                return Err(format!("two parts are named '{}'", part.name));
            }
            validate_part(part).map_err(|e| format!("part '{}': {e}", part.name))?;
        }
        for (handle, parts) in &self.handles.bind {
            if let Some(part) = parts.iter().find(|p| !names.contains(p.as_str())) {
                return Err(format!(
                    "handles: 'bind' gives handle '{handle}' the part '{part}', which is not a part"
                ));
            }
        }
        super::slots::validate_slots(self)
    }
}

/// Mesh coordinates beyond this (px, either sign) are refused: no canvas is that large, and
/// skinning such a vertex overflows. The same limit as the handles'.
pub use crate::rig::handles::MAX_COORDINATE_PX;
/// How far a weight may lie outside [0, 1], and a row's sum from one, by rounding.
pub const WEIGHT_TOLERANCE: f64 = 1e-6;

fn validate_part(part: &PartDoc) -> Result<(), String> {
    let n = part.mesh.vertices.len();
    if let Some(i) = part
        .mesh
        .vertices
        .iter()
        .position(|v| !(v[0].is_finite() && v[1].is_finite()))
    {
        return Err(format!("vertex {i} is not finite"));
    }
    if let Some(i) = part
        .mesh
        .vertices
        .iter()
        .position(|v| v[0].abs() > MAX_COORDINATE_PX || v[1].abs() > MAX_COORDINATE_PX)
    {
        return Err(format!(
            "vertex {i} lies beyond ±{MAX_COORDINATE_PX} px of the canvas origin"
        ));
    }
    for (t, tri) in part.mesh.triangles.iter().enumerate() {
        if let Some(&i) = tri.iter().find(|&&i| i as usize >= n) {
            return Err(format!(
                "triangle {t} uses vertex {i}, but the mesh has {n} vertices"
            ));
        }
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
            return Err(format!("triangle {t} repeats a vertex: {tri:?}"));
        }
    }
    if let Some(w) = &part.weights {
        validate_weights(w, n)?;
    }
    if let Some(w) = &part.stale_weights {
        validate_weights(w, n).map_err(|e| format!("stale weights: {e}"))?;
    }
    Ok(())
}

/// Checks one weight table against a mesh of `n` vertices.
fn validate_weights(w: &WeightsDoc, n: usize) -> Result<(), String> {
    if w.rows.len() != n {
        return Err(format!("{} weight rows for {n} vertices", w.rows.len()));
    }
    for (i, row) in w.rows.iter().enumerate() {
        for &(h, value) in row {
            if h as usize >= w.handles.len() {
                return Err(format!(
                    "vertex {i} has a weight for handle {h} of {}",
                    w.handles.len()
                ));
            }
            if !value.is_finite() {
                return Err(format!("vertex {i} has a weight that is not finite"));
            }
            if !(-WEIGHT_TOLERANCE..=1.0 + WEIGHT_TOLERANCE).contains(&value) {
                return Err(format!(
                    "vertex {i} has weight {value} for handle {h}, outside [0, 1]"
                ));
            }
        }
        let mut columns: Vec<u32> = row.iter().map(|e| e.0).collect();
        columns.sort_unstable();
        if columns.windows(2).any(|p| p[0] == p[1]) {
            return Err(format!("vertex {i} lists a handle twice"));
        }
        if row.is_empty() {
            return Err(format!("vertex {i} has no weights"));
        }
        let sum: f64 = row.iter().map(|e| e.1).sum();
        if (sum - 1.0).abs() > WEIGHT_TOLERANCE {
            return Err(format!("vertex {i}'s weights sum to {sum}, not 1"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> RigDocument {
        let mut doc = RigDocument::new([4, 4]);
        doc.parts.push(PartDoc {
            name: "body".into(),
            slot: None,
            image: "body.png".into(),
            offset_px: [0, 0],
            mesh: MeshDoc {
                vertices: vec![
                    Point::new(0.0, 0.0),
                    Point::new(1.0, 0.0),
                    Point::new(0.0, 1.0),
                ],
                triangles: vec![[0, 1, 2]],
            },
            weights: None,
            stale_weights: None,
        });
        doc
    }

    #[test]
    fn round_trips_through_json() {
        let doc = sample();
        let text = serde_json::to_string(&doc).unwrap();
        assert_eq!(
            RigDocument::from_json(&text, Path::new("r.json")).unwrap(),
            doc
        );
    }

    #[test]
    fn the_autorig_record_round_trips_and_is_left_out_when_absent() {
        let mut doc = sample();
        let text = serde_json::to_string(&doc).unwrap();
        assert!(!text.contains("autorig"), "{text}");
        doc.autorig = Some(AutorigRecord {
            template: RecordedTemplate::Humanoid,
        });
        let text = serde_json::to_string(&doc).unwrap();
        assert!(
            text.contains(r#""autorig":{"template":"humanoid"}"#),
            "{text}"
        );
        assert_eq!(
            RigDocument::from_json(&text, Path::new("r.json")).unwrap(),
            doc
        );
        let wrong = text.replace("humanoid", "octopus");
        assert!(RigDocument::from_json(&wrong, Path::new("r.json")).is_err());
    }

    #[test]
    fn a_bind_naming_no_part_is_refused() {
        let mut doc = sample();
        doc.handles.bones.push(crate::rig::Bone {
            name: "b".into(),
            parent: None,
            head: Point::new(0.0, 0.0),
            tail: Point::new(1.0, 0.0),
        });
        doc.handles.bind.insert("b".into(), vec!["body".into()]);
        assert_eq!(doc.validate(), Ok(()));
        doc.handles
            .bind
            .insert("b".into(), vec!["body".into(), "wing".into()]);
        let reason = doc.validate().unwrap_err();
        assert!(reason.contains("'wing', which is not a part"), "{reason}");
    }

    /// Whether two JSON values say the same: numbers compared as numbers (`0` and `0.0` alike).
    fn same_json(a: &serde_json::Value, b: &serde_json::Value) -> bool {
        use serde_json::Value;
        match (a, b) {
            (Value::Number(x), Value::Number(y)) => x.as_f64() == y.as_f64(),
            (Value::Array(x), Value::Array(y)) => {
                x.len() == y.len() && x.iter().zip(y).all(|(x, y)| same_json(x, y))
            }
            (Value::Object(x), Value::Object(y)) => {
                x.len() == y.len()
                    && x.iter()
                        .all(|(k, v)| y.get(k).is_some_and(|w| same_json(v, w)))
            }
            _ => a == b,
        }
    }

    #[test]
    fn animations_are_read_once_and_written_back_as_they_were() {
        let file = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/assets/character/animations.json"
        );
        let text = std::fs::read_to_string(file).unwrap();
        let bundled: serde_json::Value = serde_json::from_str(&text).unwrap();
        // The animations file on its own.
        let parsed = crate::anim::animations_from_json(&bundled).unwrap();
        assert_eq!(parsed.len(), 4);
        assert!(same_json(&serde_json::to_value(&parsed).unwrap(), &bundled));
        // In a rig document: load, save, load.
        let mut v = serde_json::to_value(sample()).unwrap();
        v["animations"] = bundled.clone();
        let p = Path::new("r.json");
        let doc = RigDocument::from_json(&v.to_string(), p).unwrap();
        assert_eq!(doc.animations, parsed);
        let saved: serde_json::Value =
            serde_json::from_str(&serde_json::to_string_pretty(&doc).unwrap()).unwrap();
        assert!(same_json(&saved, &v), "{saved}");
        assert_eq!(RigDocument::from_json(&saved.to_string(), p).unwrap(), doc);
        // Through serde alone (no `from_json`), the same animations.
        let direct: RigDocument = serde_json::from_value(v).unwrap();
        assert_eq!(direct, doc);
        // The comparison sees a changed number.
        let mut changed = bundled;
        changed["walk"]["bones"]["hip"]["translate"][0]["time"] = 0.5.into();
        assert!(!same_json(
            &serde_json::to_value(&parsed).unwrap(),
            &changed
        ));
    }

    #[test]
    fn a_bad_animation_fails_the_document_with_its_place() {
        let p = Path::new("r.json");
        let mut v = serde_json::to_value(sample()).unwrap();
        v["animations"] = serde_json::json!({"go": {"bones": {"a": {"rotate": [
            {"time": 0, "value": 1}, {"time": 0, "value": 2}]}}}});
        let e = RigDocument::from_json(&v.to_string(), p)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "r.json: animation 'go', bones.a.rotate: key 1 at 0 s does not come after the \
             previous key at 0 s"
        );
        v["animations"] = serde_json::json!([1]);
        let e = RigDocument::from_json(&v.to_string(), p)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "r.json: animations: expected an object: name → animation"
        );
        // Serde alone gives the same reason.
        let e = serde_json::from_value::<RigDocument>(v)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "animations: expected an object: name → animation");
        // Names the rig lacks do not stop it loading; posing checks them.
        v = serde_json::to_value(sample()).unwrap();
        v["animations"] = serde_json::json!({"go": {"bones": {"a": {"rotate": [
            {"time": 0, "value": 1}]}}}});
        let doc = RigDocument::from_json(&v.to_string(), p).unwrap();
        assert_eq!(
            doc.check_animations().unwrap_err().to_string(),
            "animation 'go' names bone 'a', which the rig does not have"
        );
    }

    #[test]
    fn locks_are_optional_and_checked() {
        // A document without locks writes no `locked` field, so older readers load it.
        let doc = sample();
        let value = serde_json::to_value(&doc).unwrap();
        assert!(value.get("locked").is_none());
        let mut locked = doc.clone();
        locked.handles.points.push(crate::rig::PointHandle {
            name: "nose".into(),
            at: Point::new(1.0, 1.0),
            parent: None,
        });
        locked.locked = vec!["nose".into()];
        let text = serde_json::to_string(&locked).unwrap();
        assert_eq!(
            RigDocument::from_json(&text, Path::new("r.json")).unwrap(),
            locked
        );
        locked.locked = vec!["ear".into()];
        let e = RigDocument::from_json(
            &serde_json::to_string(&locked).unwrap(),
            Path::new("r.json"),
        )
        .unwrap_err()
        .to_string();
        assert_eq!(e, "r.json: locked handle 'ear' is not a handle");
    }

    #[test]
    fn rejects_wrong_format_version_and_indices() {
        let p = Path::new("r.json");
        let mut v = serde_json::to_value(sample()).unwrap();
        v["version"] = 2.into();
        let e = RigDocument::from_json(&v.to_string(), p)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "r.json: unsupported rig version 2 (this sinew reads version 1)"
        );
        v["version"] = 1.into();
        v["format"] = "spine".into();
        assert!(matches!(
            RigDocument::from_json(&v.to_string(), p),
            Err(DocumentError::WrongFormat { .. })
        ));
        v["format"] = RIG_FORMAT.into();
        v["parts"][0]["mesh"]["triangles"][0][2] = 3.into();
        let e = RigDocument::from_json(&v.to_string(), p)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "r.json: part 'body': triangle 0 uses vertex 3, but the mesh has 3 vertices"
        );
        assert!(matches!(
            RigDocument::from_json("{", p),
            Err(DocumentError::Json { .. })
        ));
    }

    #[test]
    fn rejects_weights_that_do_not_form_rows_summing_to_one_and_absurd_meshes() {
        let p = Path::new("r.json");
        let mut doc = sample();
        doc.parts[0].weights = Some(WeightsDoc {
            handles: vec!["a".into(), "b".into()],
            rows: vec![vec![(0, 1.0)], vec![(0, 0.25), (1, 0.75)], vec![(1, 1.0)]],
        });
        let good = serde_json::to_value(&doc).unwrap();
        assert!(RigDocument::from_json(&good.to_string(), p).is_ok());
        let reason = |edit: &dyn Fn(&mut serde_json::Value)| {
            let mut v = good.clone();
            edit(&mut v);
            RigDocument::from_json(&v.to_string(), p)
                .unwrap_err()
                .to_string()
        };
        assert!(reason(
            &|v| v["parts"][0]["weights"]["rows"][1] = serde_json::json!([[0, -5.0], [1, 6.0]])
        )
        .contains("outside [0, 1]"));
        assert!(reason(
            &|v| v["parts"][0]["weights"]["rows"][1] = serde_json::json!([[0, 0.25], [1, 0.5]])
        )
        .contains("sum to 0.75, not 1"));
        assert!(
            reason(&|v| v["parts"][0]["weights"]["rows"][1] = serde_json::json!([]))
                .contains("has no weights")
        );
        assert!(reason(
            &|v| v["parts"][0]["weights"]["rows"][1] = serde_json::json!([[1, 0.5], [1, 0.5]])
        )
        .contains("lists a handle twice"));
        assert!(
            reason(&|v| v["parts"][0]["mesh"]["vertices"][0] = serde_json::json!([1e300, 0]))
                .contains("beyond")
        );
        assert!(
            reason(&|v| v["parts"][0]["mesh"]["triangles"][0] = serde_json::json!([0, 0, 0]))
                .contains("repeats a vertex")
        );
    }
}
