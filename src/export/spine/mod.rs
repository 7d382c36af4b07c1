//! Spine export: a rig as Spine 4.2 (or 4.1, 4.3) skeleton JSON, a `.atlas` and its page PNGs,
//! which the official runtimes play where sinew draws the rig.
//!
//! In: a loaded [`Scene`] (the rig document, every part with weights), the parts' images
//! (straight-alpha RGBA8 on the canvas), a base name and [`SpineOptions`]. Out: a
//! [`SpineExport`] held in memory — `NAME.json`, `NAME.atlas`, `NAME.png` (and `NAME_2.png`, …)
//! — which [`SpineExport::write`] puts into a folder all at once or not at all.
//!
//! Stages, one module each:
//! - [`frame`]: canvas (y down) ↔ Spine world (y up), Spine's bone matrix;
//! - [`skeleton`]: every handle a bone, parents first, setup pose;
//! - [`mesh`]: a weighted mesh attachment per part (hull first, uvs, binds, influences);
//! - [`decimate`]: coarser runtime meshes carrying the fine mesh's weights;
//! - [`atlas`]: trimmed regions packed into pages, premultiplied, and the atlas text;
//! - [`timelines`]: sinew timelines as native Spine timelines with their curves;
//! - [`constraints`]: one- and two-bone IK constraints as Spine IK constraints;
//! - [`events`]: event definitions and event keys as Spine events;
//! - [`deform`]: deform keys as deform timelines (offsets in each influence's bone frame);
//! - [`physics`]: physics constraints as Spine 4.2 physics constraints;
//! - [`bake`]: what Spine cannot express, sampled at `bake_fps` through the one pose path.
//!
//! Spine facts relied on are in `docs/spine-format.md` (the "spine-format.md §N" cited in these
//! modules); what sinew writes is summed up in `docs/formats.md`;
//! `tests/spine_runtime.rs` checks the result against the official `spine-core` runtime.

pub mod atlas;
pub mod bake;
pub mod constraints;
pub mod decimate;
pub mod deform;
pub mod events;
pub mod frame;
pub mod mesh;
pub mod physics;
pub mod played;
pub mod skeleton;
pub mod skins;
pub mod timelines;

pub use atlas::AtlasOptions;
pub use bake::BakeMode;
pub use frame::SpineFrame;

use crate::anim::{self, AnimError};
use crate::geom::Point;
use crate::io::{self, RigDocument};
use crate::pipeline::{PipelineError, Scene};
use crate::rig::{handle_columns, Pose};
use image::RgbaImage;
use mesh::{mesh_attachment, MeshAttachment, RegionRect, WeightedMesh};
use serde::{Deserialize, Serialize};
use serde_json::{json, Map, Value};
use skeleton::{build_skeleton, Skeleton};
use std::path::{Path, PathBuf};
use timelines::num;

/// The Spine editor line the JSON is written for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum SpineVersion {
    /// 4.1: the same subset; only the version string differs.
    #[serde(rename = "4.1")]
    V4_1,
    /// 4.2 (default): what most engines ship today.
    #[default]
    #[serde(rename = "4.2")]
    V4_2,
    /// 4.3: IK constraints in the one typed `constraints` array (update order = array order);
    /// the rest of what sinew writes reads the same (spine-format.md §11).
    #[serde(rename = "4.3")]
    V4_3,
}

impl SpineVersion {
    /// Parses `4.1`, `4.2` or `4.3` (what `--spine-version` takes).
    pub fn parse(text: &str) -> Result<Self, SpineError> {
        match text.trim() {
            "4.1" => Ok(SpineVersion::V4_1),
            "4.2" => Ok(SpineVersion::V4_2),
            "4.3" => Ok(SpineVersion::V4_3),
            other => Err(SpineError::UnsupportedVersion(other.to_string())),
        }
    }

    /// The editor line as [`SpineVersion::parse`] reads it (`4.2`): its inverse.
    pub fn name(self) -> &'static str {
        match self {
            SpineVersion::V4_1 => "4.1",
            SpineVersion::V4_2 => "4.2",
            SpineVersion::V4_3 => "4.3",
        }
    }

    /// The `skeleton.spine` string. Runtimes check major.minor only (spine-format.md §1).
    pub fn version_string(self) -> &'static str {
        match self {
            SpineVersion::V4_1 => "4.1.0",
            SpineVersion::V4_2 => "4.2.0",
            SpineVersion::V4_3 => "4.3.0",
        }
    }
}

/// How a rig is exported.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpineOptions {
    /// Default 4.2.
    pub version: SpineVersion,
    /// Keys per second of baked motion. Default 30.
    pub bake_fps: f64,
    /// What is baked. Default [`BakeMode::Auto`].
    pub bake: BakeMode,
    /// How far (px, at the corners of the rig's bounding box) the pose path may move a handle
    /// away from forward kinematics of the keyed pose before the handle is baked. Default 1e-6.
    pub bake_tolerance_px: f64,
    /// Keep the K strongest weights per vertex, renormalized. Default: all.
    pub max_influences: Option<usize>,
    /// Decimate each part's mesh to at most this many vertices. Default: the fine mesh.
    pub max_vertices: Option<usize>,
    /// Transparent px around each mesh's box in its atlas region. Default 2.
    pub region_margin_px: u32,
    pub atlas: AtlasOptions,
    /// Name of the root bone every skeleton hangs from. Default `root`.
    pub root_bone: String,
}

impl Default for SpineOptions {
    fn default() -> Self {
        SpineOptions {
            version: SpineVersion::default(),
            bake_fps: 30.0,
            bake: BakeMode::default(),
            bake_tolerance_px: 1e-6,
            max_influences: None,
            max_vertices: None,
            region_margin_px: 2,
            atlas: AtlasOptions::default(),
            root_bone: "root".into(),
        }
    }
}

/// A named set of [`SpineOptions`] for a kind of target; explicit options override its fields.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum SpinePreset {
    /// Every vertex and influence of the rig: the export plays exactly what sinew draws.
    #[default]
    Full,
    /// For shipping in a game: each part's mesh decimated to at most
    /// [`GAME_PRESET_MAX_VERTICES`] vertices, at most [`GAME_PRESET_MAX_INFLUENCES`]
    /// influences per vertex. The bundled character's JSON drops from 1.94 MB to 0.53 MB,
    /// plays within 0.5 px of sinew's preview at the kept vertices and draws within 45 dB of
    /// the full export at every checked time (`tests/spine_runtime.rs` checks all three against
    /// spine-core).
    Game,
}

/// Vertices per part in [`SpinePreset::Game`].
pub const GAME_PRESET_MAX_VERTICES: usize = 250;

/// Influences per vertex in [`SpinePreset::Game`].
pub const GAME_PRESET_MAX_INFLUENCES: usize = 4;

impl SpinePreset {
    /// The preset's options with the limits given explicitly in their place (the rest of the
    /// preset's options kept): how `sinew export spine --preset P --max-vertices N` and a batch
    /// export job read.
    pub fn options_with(
        self,
        max_influences: Option<usize>,
        max_vertices: Option<usize>,
    ) -> SpineOptions {
        let preset = self.options();
        SpineOptions {
            max_influences: max_influences.or(preset.max_influences),
            max_vertices: max_vertices.or(preset.max_vertices),
            ..preset
        }
    }

    /// The preset's options (the rest default).
    pub fn options(self) -> SpineOptions {
        match self {
            SpinePreset::Full => SpineOptions::default(),
            SpinePreset::Game => SpineOptions {
                max_influences: Some(GAME_PRESET_MAX_INFLUENCES),
                max_vertices: Some(GAME_PRESET_MAX_VERTICES),
                ..SpineOptions::default()
            },
        }
    }
}

/// Most times an animation is sampled to decide what to bake (duration × bake fps): a typo'd
/// key time (1e6 s) would otherwise fill the memory.
pub const MAX_BAKE_SAMPLES: f64 = 100_000.0;

/// Highest bake rate accepted; a typo (`--fps 3000`) would otherwise write huge files.
pub const MAX_BAKE_FPS: f64 = 240.0;

/// What stops an export.
#[derive(Debug, thiserror::Error)]
pub enum SpineError {
    #[error(
        "animation '{animation}' would be sampled {samples:.3e} times (duration × bake fps): at \
         most {MAX_BAKE_SAMPLES}"
    )]
    TooLong { animation: String, samples: f64 },
    #[error("part '{0}' has no weights: rig it with handles (sinew rig --handles) before exporting to Spine")]
    NoWeights(String),
    #[error("part '{part}': vertex {vertex} has no positive weight")]
    UnweightedVertex { part: String, vertex: usize },
    #[error("part '{part}' has weights for handle '{handle}', which the rig does not have")]
    UnknownWeightHandle { part: String, handle: String },
    #[error("{kind} name {name:?} cannot be used in Spine: {reason}")]
    BadName {
        kind: &'static str,
        name: String,
        reason: &'static str,
    },
    #[error("two Spine bones would be named '{name}' (the root bone, or a cage vertex 'cage.k')")]
    NameTaken { name: String },
    #[error("Spine version '{0}' is not supported (4.1, 4.2 or 4.3)")]
    UnsupportedVersion(String),
    #[error("the bake rate must be a number in (0, {MAX_BAKE_FPS}] keys per second, not {0}")]
    Fps(f64),
    #[error("--max-influences must be at least 1")]
    MaxInfluences,
    #[error("--max-vertices must be at least 3, not {0}")]
    MaxVertices(usize),
    #[error("part '{part}' needs a {}×{} px atlas region, larger than a page ({max_page_px} px)", size[0], size[1])]
    RegionTooLarge {
        part: String,
        size: [u32; 2],
        max_page_px: u32,
    },
    #[error("part '{part}': its mesh reaches past its {}×{} px image placed at {offset_px:?} (was the image replaced by one of another size?)", got[0], got[1])]
    ImageSize {
        part: String,
        got: [u32; 2],
        offset_px: [i32; 2],
    },
    #[error("the transformation of '{0}' is singular")]
    Singular(String),
    #[error("two IK constraints are named '{0}'; Spine needs unique constraint names")]
    DuplicateConstraint(String),
    #[error(transparent)]
    Anim(#[from] AnimError),
    #[error("baking: {0}")]
    Pose(PipelineError),
    #[error("cannot encode atlas page {0}: {1}")]
    Png(String, String),
    #[error("{path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// One exported part.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportedPart {
    /// Attachment and atlas region name: the part's name (its slot: the part's own name, or its
    /// `slot` field when it is another attachment of a slot).
    pub name: String,
    pub mesh: MeshAttachment,
}

/// A finished export, in memory.
#[derive(Clone, Debug)]
pub struct SpineExport {
    /// File base name (`NAME.json`, `NAME.atlas`).
    pub name: String,
    pub frame: SpineFrame,
    pub skeleton: Skeleton,
    pub parts: Vec<ExportedPart>,
    /// Per animation, the bones whose motion was baked.
    pub baked: Vec<(String, Vec<String>)>,
    pub json: String,
    pub atlas: String,
    /// Page file names and PNG bytes.
    pub pages: Vec<(String, Vec<u8>)>,
}

/// Names go into JSON strings and atlas lines: no control characters, no surrounding blanks, and
/// for atlas lines (part and file names) no `:`, which would read as an atlas entry
/// (spine-format.md §12).
fn check_name(kind: &'static str, name: &str, in_atlas: bool) -> Result<(), SpineError> {
    let bad = |reason| {
        Err(SpineError::BadName {
            kind,
            name: name.to_string(),
            reason,
        })
    };
    if name.is_empty() {
        return bad("it is empty");
    }
    if name.chars().any(char::is_control) {
        return bad("it contains a control character (a line break?)");
    }
    if name.trim() != name {
        return bad("it starts or ends with a blank");
    }
    if in_atlas && name.contains(':') {
        return bad("the atlas format reads ':' as a key/value separator");
    }
    Ok(())
}

/// Refuses a bake rate outside (0, [`MAX_BAKE_FPS`]] keys per second.
fn check_bake_fps(bake_fps: f64) -> Result<(), SpineError> {
    if bake_fps.is_finite() && bake_fps > 0.0 && bake_fps <= MAX_BAKE_FPS {
        Ok(())
    } else {
        Err(SpineError::Fps(bake_fps))
    }
}

/// What the export bakes of one animation: the bake times, the animation's frames there (pose
/// and transformations, through the one pose path), the skeleton bones whose keys are baked, and
/// the exported IK constraints switched off because a bone of their chain is baked.
pub struct BakePlan {
    pub times: Vec<f64>,
    pub samples: Vec<(Pose, Vec<crate::rig::Affine>)>,
    pub baked: std::collections::BTreeSet<usize>,
    pub switched_off: Vec<usize>,
}

/// The [`BakePlan`] of `animation` (named `name`) on `scene` exported as `skeleton`.
pub fn plan_bake(
    scene: &Scene,
    name: &str,
    animation: &anim::Animation,
    skeleton: &Skeleton,
    options: &SpineOptions,
) -> Result<BakePlan, SpineError> {
    let doc = &scene.doc;
    check_bake_fps(options.bake_fps)?;
    let samples = animation.duration_s() * options.bake_fps;
    if samples.is_nan() || samples > MAX_BAKE_SAMPLES {
        return Err(SpineError::TooLong {
            animation: name.to_string(),
            samples,
        });
    }
    // Spine solves one- and two-bone constraints itself; longer chains are baked.
    let exported_ik = constraints::exported(&doc.handles);
    let spine_handles = constraints::with_constraints(&doc.handles, &exported_ik);
    // Where a handle's transformation is compared when deciding what to bake.
    let corners = crate::playback::rest_corners(doc);
    let times = bake::bake_times(animation.duration_s(), options.bake_fps);
    let native_physics = physics::native(options.version);
    let samples =
        bake::sample_path(scene, animation, &times, native_physics).map_err(SpineError::Pose)?;
    let mut baked = bake::bones_to_bake(
        options.bake,
        &spine_handles,
        skeleton,
        &samples,
        &corners,
        options.bake_tolerance_px,
    )?;
    // A carried point's offsets turn into its parent's axes; with different time handles per
    // channel no Bézier expresses that turn, so the point is baked.
    for (i, point) in doc.handles.points.iter().enumerate() {
        let translate = animation
            .points
            .get(&point.name)
            .and_then(|t| t.translate.as_ref());
        let mixed = translate.is_some_and(|k| !timelines::channels_share_time_handles(k));
        if mixed && doc.handles.point_parent(i).is_some() {
            baked.insert(skeleton.column_bone[doc.handles.bones.len() + i]);
        }
    }
    let switched_off =
        constraints::switch_off_baked(&doc.handles, skeleton, &exported_ik, &mut baked);
    Ok(BakePlan {
        times,
        samples,
        baked,
        switched_off,
    })
}

/// Exports `scene` as `name`. `images` are the parts' images in part order.
pub fn export_spine(
    scene: &Scene,
    images: &[RgbaImage],
    name: &str,
    options: &SpineOptions,
) -> Result<SpineExport, SpineError> {
    let doc = &scene.doc;
    // Refused as render refuses it (`scene::Playhead::frame`), with or without animations.
    if !doc.handles.physics.is_empty() && !doc.options.ik.momentum.is_empty() {
        return Err(SpineError::Pose(PipelineError::PhysicsWithMomentum));
    }
    check_bake_fps(options.bake_fps)?;
    if options.max_influences == Some(0) {
        return Err(SpineError::MaxInfluences);
    }
    if let Some(n) = options.max_vertices.filter(|&n| n < 3) {
        return Err(SpineError::MaxVertices(n));
    }
    check_name("file", name, true)?;
    if name.contains(['/', '\\']) {
        return Err(SpineError::BadName {
            kind: "file",
            name: name.to_string(),
            reason: "a file name cannot contain / or \\ (the output folder is -o)",
        });
    }
    if name.starts_with('.') {
        return Err(SpineError::BadName {
            kind: "file",
            name: name.to_string(),
            reason: "a name starting with '.' makes hidden files ('..json' for '.'); start it with a letter or digit",
        });
    }
    check_name("root bone", &options.root_bone, false)?;
    for part in &doc.parts {
        check_name("part", &part.name, true)?;
        if part.weights.is_none() {
            return Err(SpineError::NoWeights(part.name.clone()));
        }
    }
    for column in handle_columns(&doc.handles) {
        check_name("handle", &column, false)?;
    }
    for animation in doc.animations.keys() {
        check_name("animation", animation, false)?;
    }
    for (c, constraint) in doc.handles.ik.iter().enumerate() {
        check_name("IK constraint", &constraint.name, false)?;
        if doc.handles.ik[..c]
            .iter()
            .any(|k| k.name == constraint.name)
        {
            return Err(SpineError::DuplicateConstraint(constraint.name.clone()));
        }
    }
    for event in doc.events.keys() {
        check_name("event", event, false)?;
    }
    let exported_ik = constraints::exported(&doc.handles);
    for c in &doc.handles.physics {
        check_name("physics constraint", &c.name, false)?;
    }
    let physics = physics::physics_entries(&doc.handles, exported_ik.len(), options.version);
    let frame = SpineFrame::for_canvas(doc.canvas);
    let skeleton = build_skeleton(&doc.handles, &frame, &options.root_bone)?;
    let columns = handle_columns(&doc.handles);

    // Meshes and regions.
    let mut parts = Vec::with_capacity(doc.parts.len());
    let mut regions = Vec::with_capacity(doc.parts.len());
    let reach_px = f64::from(crate::scene::texture_border_px(doc));
    for (part, image) in doc.parts.iter().zip(images) {
        let got = [image.width(), image.height()];
        if !part.image_holds_mesh(got, reach_px) {
            return Err(SpineError::ImageSize {
                part: part.name.clone(),
                got,
                offset_px: part.offset_px,
            });
        }
        let Some(weights) = &part.weights else {
            return Err(SpineError::NoWeights(part.name.clone()));
        };
        let rows = crate::export::joints::column_rows(part, weights, &columns).map_err(|e| {
            SpineError::UnknownWeightHandle {
                part: e.0,
                handle: e.1,
            }
        })?;
        let fine = part.mesh.to_mesh();
        let (kept, triangles) = match options.max_vertices {
            Some(n) if n < fine.vertices.len() => {
                let detail = decimate::TextureDetail::new(image, part.offset_px);
                decimate::decimate_textured(&fine, &rows, n, Some(&detail))
            }
            _ => ((0..fine.vertices.len()).collect(), fine.triangles.clone()),
        };
        let vertices: Vec<Point> = kept.iter().map(|&v| fine.vertices[v]).collect();
        let kept_rows: Vec<Vec<(usize, f64)>> = kept.iter().map(|&v| rows[v].clone()).collect();
        let region = RegionRect::around(&vertices, options.region_margin_px);
        let mut mesh = mesh_attachment(
            &part.name,
            WeightedMesh {
                vertices: &vertices,
                triangles: &triangles,
                rows: &kept_rows,
            },
            &skeleton,
            &frame,
            &region,
            options.max_influences,
        )?;
        // Vertex sources are indices into the fine mesh.
        for v in &mut mesh.vertex_source {
            *v = kept[*v];
        }
        regions.push((part.name.clone(), image, part.offset_px, region));
        parts.push(ExportedPart {
            name: part.name.clone(),
            mesh,
        });
    }
    let atlas = atlas::pack_atlas(name, &regions, &options.atlas)?;

    // Animations: native timelines, and baked keys for what they cannot express.
    doc.check_animations()?;
    let animations = &doc.animations;
    // Draw order keys and slot timelines name slots.
    let part_names: Vec<String> = doc.slot_names().into_iter().map(String::from).collect();
    let mut animations_json = Map::new();
    let mut baked_report = Vec::new();
    for (anim_name, animation) in animations {
        let BakePlan {
            times,
            samples,
            baked,
            switched_off,
        } = plan_bake(scene, anim_name, animation, &skeleton, options)?;
        let timelines::NativeTimelines {
            mut bones,
            slots,
            draw_order,
        } = timelines::native_timelines(
            animation,
            &doc.handles,
            &part_names,
            &skeleton,
            &frame,
            &baked,
        );
        bones.extend(bake::baked_timelines(
            &skeleton, &frame, &baked, &times, &samples,
        )?);
        let mut a = Map::new();
        if !bones.is_empty() {
            a.insert(
                "bones".into(),
                Value::Object(
                    bones
                        .into_iter()
                        .map(|(k, v)| (k, Value::Object(v)))
                        .collect(),
                ),
            );
        }
        if !slots.is_empty() {
            a.insert("slots".into(), Value::Object(slots));
        }
        if !switched_off.is_empty() {
            a.insert(
                "ik".into(),
                Value::Object(
                    switched_off
                        .iter()
                        .map(|&c| (doc.handles.ik[c].name.clone(), constraints::off_timeline()))
                        .collect(),
                ),
            );
        }
        if let Some(d) = draw_order {
            a.insert("drawOrder".into(), d);
        }
        if !animation.deform.is_empty() {
            let mut slots = Map::new();
            for (part, keys) in &animation.deform {
                let Some(index) = parts.iter().position(|p| &p.name == part) else {
                    continue;
                };
                let exported = &parts[index];
                // Keys that change nothing are left out (deform.rs), a timeline of them too.
                let Some(timeline) =
                    deform::deform_timeline(keys, &exported.mesh, &skeleton, &frame)?
                else {
                    continue;
                };
                // Keyed on the part's mesh in the default skin, in the slot it belongs to
                // (an attachment part lives in another part's slot); skins' linked meshes of
                // it follow the same keys.
                let slot = slots
                    .entry(doc.slot_of(index).to_string())
                    .or_insert_with(|| Value::Object(Map::new()));
                slot[part.as_str()] = json!({ "deform": timeline });
            }
            if !slots.is_empty() {
                a.insert("attachments".into(), json!({ "default": slots }));
            }
        }
        if !animation.events.is_empty() {
            a.insert(
                "events".into(),
                events::event_timeline(&animation.events, &doc.events),
            );
        }
        animations_json.insert(anim_name.clone(), Value::Object(a));
        baked_report.push((
            anim_name.clone(),
            baked
                .iter()
                .map(|&b| skeleton.bones[b].name.clone())
                .collect(),
        ));
    }

    let json = skeleton_json(
        doc,
        name,
        options,
        &frame,
        &skeleton,
        &parts,
        &atlas,
        &exported_ik,
        physics,
        animations_json,
    );
    let mut pages = Vec::with_capacity(atlas.pages.len());
    for page in &atlas.pages {
        pages.push((
            page.file_name.clone(),
            png_bytes(&page.image, &page.file_name)?,
        ));
    }
    Ok(SpineExport {
        name: name.to_string(),
        frame,
        skeleton,
        parts,
        baked: baked_report,
        json,
        atlas: atlas.text(),
        pages,
    })
}

/// `image` encoded as PNG (an atlas page named `file`, for the error).
pub(crate) fn png_bytes(image: &RgbaImage, file: &str) -> Result<Vec<u8>, SpineError> {
    let mut out = std::io::Cursor::new(Vec::new());
    image
        .write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| SpineError::Png(file.to_string(), e.to_string()))?;
    Ok(out.into_inner())
}

/// The skeleton JSON (spine-format.md §2–§7).
#[allow(clippy::too_many_arguments)]
fn skeleton_json(
    doc: &RigDocument,
    name: &str,
    options: &SpineOptions,
    frame: &SpineFrame,
    skeleton: &Skeleton,
    parts: &[ExportedPart],
    atlas: &atlas::Atlas,
    exported_ik: &[usize],
    physics: Vec<Value>,
    animations: Map<String, Value>,
) -> String {
    // Bounds of the setup pose: the rest meshes in Spine's world.
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in doc.parts.iter().flat_map(|p| &p.mesh.vertices) {
        let q = frame.spine_from_canvas(*v);
        lo = [lo[0].min(q[0]), lo[1].min(q[1])];
        hi = [hi[0].max(q[0]), hi[1].max(q[1])];
    }
    if !lo[0].is_finite() {
        (lo, hi) = ([0.0; 2], [0.0; 2]);
    }
    let bones: Vec<Value> = skeleton
        .bones
        .iter()
        .map(|b| {
            let mut m = Map::new();
            m.insert("name".into(), json!(b.name));
            if let Some(p) = b.parent {
                m.insert("parent".into(), json!(skeleton.bones[p].name));
            }
            let s = &b.setup;
            for (key, value, default) in [
                ("length", b.length, 0.0),
                ("x", s.x, 0.0),
                ("y", s.y, 0.0),
                ("rotation", s.rotation_deg, 0.0),
                ("scaleX", s.scale_x, 1.0),
                ("scaleY", s.scale_y, 1.0),
                ("shearX", s.shear_x_deg, 0.0),
                ("shearY", s.shear_y_deg, 0.0),
            ] {
                if value != default {
                    m.insert(key.into(), num(value));
                }
            }
            Value::Object(m)
        })
        .collect();
    let root = &skeleton.bones[0].name;
    let mesh_json = |part: &ExportedPart| {
        let m = &part.mesh;
        let region = atlas.regions.iter().find(|r| r.name == part.name);
        let mut vertices = Vec::new();
        for influences in &m.influences {
            vertices.push(json!(influences.len()));
            for i in influences {
                vertices.extend([json!(i.bone), num(i.bind[0]), num(i.bind[1]), num(i.weight)]);
            }
        }
        json!({
            "type": "mesh",
            "uvs": m.uvs.iter().flat_map(|uv| [num(uv[0]), num(uv[1])]).collect::<Vec<_>>(),
            "triangles": m.triangles,
            "vertices": vertices,
            "hull": m.hull,
            "edges": m.edges,
            "width": region.map_or(0, |r| r.width),
            "height": region.map_or(0, |r| r.height),
        })
    };
    let linked_by_source = options.version == SpineVersion::V4_3;
    let (slots, skins) = skins::slots_and_skins(doc, parts, root, &mesh_json, linked_by_source);
    // Update order = file order, as sinew applies them.
    let ik: Vec<Value> = exported_ik
        .iter()
        .enumerate()
        .map(|(order, &c)| constraints::ik_entry(&doc.handles, c, order, options.version))
        .collect();
    let mut out = json!({
        "skeleton": {
            "spine": options.version.version_string(),
            "x": num(lo[0]),
            "y": num(lo[1]),
            "width": num(hi[0] - lo[0]),
            "height": num(hi[1] - lo[1]),
            "images": "./",
            "fps": num(options.bake_fps),
            "hash": content_hash(name, &bones, &ik, &physics, &skins, &animations),
        },
        "bones": bones,
        "slots": slots,
        "skins": skins,
        "animations": animations,
    });
    if !ik.is_empty() {
        out[constraints::block_key(options.version)] = Value::from(ik);
    }
    if !physics.is_empty() {
        out["physics"] = Value::from(physics);
    }
    if !doc.events.is_empty() {
        out["events"] = events::event_defs_json(&doc.events);
    }
    // serde_json writes f64 as the shortest text that reads back exactly: lossless, and the
    // same bytes for the same rig. Compact: the weighted vertex arrays are long.
    serde_json::to_string(&out).unwrap_or_default() + "\n"
}

/// A content hash for tools (`skeleton.hash`; runtimes only store it): FNV-1a over the data.
fn content_hash(
    name: &str,
    bones: &[Value],
    ik: &[Value],
    physics: &[Value],
    skins: &[Value],
    animations: &Map<String, Value>,
) -> String {
    let mut text = format!(
        "{name}{}{}{}{}",
        Value::from(bones.to_vec()),
        Value::from(ik.to_vec()),
        // The default skin's attachments alone when it is the only skin (as before skins).
        match skins {
            [only] => only["attachments"].clone(),
            _ => Value::from(skins.to_vec()),
        },
        Value::Object(animations.clone())
    );
    // Left out when empty: the hashes of rigs without physics stay as they were.
    if !physics.is_empty() {
        text += &Value::from(physics.to_vec()).to_string();
    }
    let mut h: u64 = 0xcbf29ce484222325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x100000001b3);
    }
    format!("{h:016x}")
}

impl SpineExport {
    /// The names of the export's files, in [`SpineExport::files`]' order.
    pub fn file_names(&self) -> Vec<String> {
        let mut names = vec![
            format!("{}.json", self.name),
            format!("{}.atlas", self.name),
        ];
        names.extend(self.pages.iter().map(|(name, _)| name.clone()));
        names
    }

    /// The files of the export: name and bytes.
    pub fn files(&self) -> Vec<(String, Vec<u8>)> {
        let bytes = [self.json.as_bytes(), self.atlas.as_bytes()]
            .into_iter()
            .chain(self.pages.iter().map(|(_, png)| png.as_slice()));
        self.file_names()
            .into_iter()
            .zip(bytes)
            .map(|(name, bytes)| (name, bytes.to_vec()))
            .collect()
    }

    /// Writes every file into `dir` (created if missing; a symbolic link to a folder is
    /// followed) as one set ([`io::atomic::write_set`]): a failure while writing (a refused
    /// target, disk full, no permission) leaves `dir` without any new or half-written file;
    /// temporaries a killed run left there are removed. The pages are renamed into place
    /// first, then the atlas that names them, then the skeleton that names the atlas. Returns
    /// the paths written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, SpineError> {
        let real_dir =
            io::atomic::resolve_output(dir, io::atomic::OutputKind::Folder).map_err(|source| {
                SpineError::Write {
                    path: dir.to_path_buf(),
                    source,
                }
            })?;
        std::fs::create_dir_all(&real_dir).map_err(|source| SpineError::Write {
            path: dir.to_path_buf(),
            source,
        })?;
        // files() lists the skeleton, the atlas, then the pages: written in reverse.
        let files: Vec<(PathBuf, Vec<u8>)> = self
            .files()
            .into_iter()
            .rev()
            .map(|(name, bytes)| (dir.join(name), bytes))
            .collect();
        io::atomic::write_set(&files)
            .map_err(|(path, source)| SpineError::Write { path, source })?;
        Ok(files.into_iter().rev().map(|(path, _)| path).collect())
    }
}
