//! DragonBones export: a rig as DragonBones 5.5 JSON (`NAME_ske.json`), its texture atlas
//! (`NAME_tex.json`) and page (`NAME_tex.png`), which the DragonBones runtimes (Cocos Creator,
//! Egret, Pixi, Phaser, three.js, Unity) play without any licence.
//!
//! In: a loaded [`Scene`] (every part with weights), the parts' images (straight-alpha RGBA8 on
//! the canvas), a base name and [`DragonBonesOptions`]. Out: a [`DragonBonesExport`] in memory;
//! [`DragonBonesExport::write`] puts its three files into a folder all at once or not at all.
//!
//! What is written (format facts: docs/dragonbones-format.md):
//! - a root bone and one bone per weight column, hanging as the handles hang
//!   ([`crate::export::joints`]), each with its rest transform;
//! - a slot per sinew slot in draw order, its attachments as mesh displays of the default skin,
//!   each a weighted mesh with every influence (bone poses are the bones' rest frames, the slot
//!   pose the identity, so the runtime's skinning is sinew's linear blend);
//! - every animation baked at [`DragonBonesOptions::frame_rate`] through the one pose path
//!   (curves, skinning IK, bone IK, momentum and physics included): each bone's transform on
//!   every frame with linear tweens (`tweenEasing: 0`, relative to the setup pose), slot display,
//!   colour and deform (FFD) frames where they are keyed, draw order frames, events on the frame
//!   nearest their time; `playTimes` 0 for an animation that loops.
//!
//! Because every motion is baked, IK constraints, physics and the authored curves are not
//! written as such; [`DragonBonesExport::left_out`] lists what the format did not carry.
//! [`played::as_played`] reproduces what the runtime plays from the export (`--match-runtime
//! dragonbones`); `tests/dragonbones_runtime.rs` checks both with the official runtime.

mod animation;
pub mod played;
pub mod transform;

use crate::anim::AnimError;
use crate::export::joints::{self, Joint};
use crate::export::spine::atlas::{self, AtlasOptions};
use crate::export::spine::mesh::RegionRect;
use crate::export::spine::SpineError;
use crate::io;
use crate::pipeline::{PipelineError, Scene};
use crate::rig::{handle_columns, Affine};
pub use animation::BakedAnimation;
use image::RgbaImage;
use serde::{Deserialize, Serialize};
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};
use transform::{DbFrame, DbTransform};

/// The format version written.
pub const VERSION: &str = "5.5";

/// Highest frame rate accepted, frames per second.
pub const MAX_FRAME_RATE: f64 = 240.0;

/// How a rig is exported to DragonBones.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DragonBonesOptions {
    /// The armature's frame rate: every motion is keyed on each of its frames. A whole number
    /// in [1, [`MAX_FRAME_RATE`]]. Default 30.
    pub frame_rate: u32,
    /// Transparent px around each mesh's box in its atlas region. Default 2.
    pub region_margin_px: u32,
    /// Atlas packing; the one page is straight alpha. Default: 2 px padding, pages up to
    /// 4096 px (a rig that needs more than one page is refused).
    pub atlas: AtlasOptions,
    /// Name of the bone every bone hangs from. Default `root`.
    pub root_bone: String,
    /// Decimate each part's mesh to at most this many vertices (weights carried from the fine
    /// mesh, as the Spine export's `--preset game`). The runtime addresses a file's numbers with
    /// 16-bit offsets ([`MAX_MESH_FLOATS`]), which fine meshes overflow. Default
    /// [`DEFAULT_MAX_VERTICES`]; `None`: the fine mesh.
    pub max_vertices: Option<usize>,
    /// Keep the K strongest weights per vertex, renormalized. Default
    /// [`DEFAULT_MAX_INFLUENCES`]; `None`: all.
    pub max_influences: Option<usize>,
}

/// Vertices per part by default: the Spine export's game preset's.
pub const DEFAULT_MAX_VERTICES: usize = crate::export::spine::GAME_PRESET_MAX_VERTICES;

/// Influences per vertex by default.
pub const DEFAULT_MAX_INFLUENCES: usize = crate::export::spine::GAME_PRESET_MAX_INFLUENCES;

/// The runtime keeps where each mesh's numbers start in a 16-bit array: every mesh must start
/// below this many numbers (vertices, uvs and influences of the meshes before it;
/// docs/dragonbones-format.md).
pub const MAX_MESH_FLOATS: usize = 65_536;

/// Where an animation's deform timelines start is kept in a signed 16-bit array: the key
/// values before an animation's last deform timeline stay below this many numbers.
pub const MAX_ANIMATION_FLOATS: usize = 32_768;

impl Default for DragonBonesOptions {
    fn default() -> Self {
        DragonBonesOptions {
            frame_rate: 30,
            region_margin_px: 2,
            atlas: AtlasOptions {
                premultiplied_alpha: false,
                ..AtlasOptions::default()
            },
            root_bone: "root".into(),
            max_vertices: Some(DEFAULT_MAX_VERTICES),
            max_influences: Some(DEFAULT_MAX_INFLUENCES),
        }
    }
}

/// What stops a DragonBones export.
#[derive(Debug, thiserror::Error)]
pub enum DragonBonesError {
    #[error(
        "part '{0}' has no weights: rig it with handles (sinew rig --handles) before exporting"
    )]
    NoWeights(String),
    #[error("part '{part}': vertex {vertex} has no positive weight")]
    UnweightedVertex { part: String, vertex: usize },
    #[error("part '{part}' has weights for handle '{handle}', which the rig does not have")]
    UnknownWeightHandle { part: String, handle: String },
    #[error(
        "the frame rate must be a whole number in [1, {MAX_FRAME_RATE}] frames per second, not {0}"
    )]
    FrameRate(u32),
    #[error(
        "animation '{animation}' would have {frames:.3e} frames (duration × frame rate): at most {}",
        crate::export::spine::MAX_BAKE_SAMPLES
    )]
    TooLong { animation: String, frames: f64 },
    #[error("the transformation of '{0}' is singular (a zero scale?)")]
    Singular(String),
    #[error("a bone would be named '{0}' twice (the root bone, or a cage vertex 'cage.k')")]
    NameTaken(String),
    #[error("the parts need {0} atlas pages; DragonBones reads one: raise the page size")]
    Pages(usize),
    #[error(
        "part '{part}' would start at number {start} of the file's meshes; the DragonBones \
         runtime addresses at most {MAX_MESH_FLOATS}: lower --max-vertices or --max-influences"
    )]
    MeshesTooLarge { part: String, start: usize },
    #[error(
        "animation '{animation}' keys {floats} numbers before its last deform timeline; the \
         DragonBones runtime addresses at most {MAX_ANIMATION_FLOATS}: lower --fps or --max-vertices"
    )]
    AnimationTooLarge { animation: String, floats: usize },
    #[error("--max-vertices must be at least 3, and --max-influences at least 1")]
    Limits,
    #[error("part '{part}': its mesh reaches past its {}×{} px image placed at {offset_px:?} (was the image replaced by one of another size?)", got[0], got[1])]
    ImageSize {
        part: String,
        got: [u32; 2],
        offset_px: [i32; 2],
    },
    #[error("{0}")]
    Atlas(Box<SpineError>),
    #[error(transparent)]
    Anim(#[from] AnimError),
    #[error("baking: {0}")]
    Pose(Box<PipelineError>),
    #[error("{path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// A finished export, in memory.
#[derive(Clone, Debug)]
pub struct DragonBonesExport {
    /// File base name (`NAME_ske.json`, `NAME_tex.json`, `NAME_tex.png`).
    pub name: String,
    pub frame: DbFrame,
    pub frame_rate: u32,
    /// The bones below the root, in column order.
    pub joints: Vec<Joint>,
    /// Their setup transforms (relative to the parent bone).
    pub setup: Vec<DbTransform>,
    /// Per animation, what was keyed on each frame (as written, f32).
    pub animations: Vec<BakedAnimation>,
    /// Per part (document order), the fine-mesh vertex each written vertex is.
    pub vertex_source: Vec<Vec<usize>>,
    /// What the rig has that the export did not carry, one line each.
    pub left_out: Vec<String>,
    pub ske: String,
    pub tex: String,
    pub png: Vec<u8>,
}

impl DragonBonesExport {
    /// The files' names and bytes: skeleton, atlas, page.
    pub fn files(&self) -> Vec<(String, Vec<u8>)> {
        vec![
            (
                format!("{}_ske.json", self.name),
                self.ske.clone().into_bytes(),
            ),
            (
                format!("{}_tex.json", self.name),
                self.tex.clone().into_bytes(),
            ),
            (format!("{}_tex.png", self.name), self.png.clone()),
        ]
    }

    /// Writes the three files into `dir` (created if missing) as one set
    /// ([`io::atomic::write_set`]): the page first, then the atlas, then the skeleton. Returns
    /// the paths written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, DragonBonesError> {
        let failed = |source| DragonBonesError::Write {
            path: dir.to_path_buf(),
            source,
        };
        let real =
            io::atomic::resolve_output(dir, io::atomic::OutputKind::Folder).map_err(failed)?;
        std::fs::create_dir_all(&real).map_err(failed)?;
        let files: Vec<(PathBuf, Vec<u8>)> = self
            .files()
            .into_iter()
            .rev()
            .map(|(name, bytes)| (dir.join(name), bytes))
            .collect();
        io::atomic::write_set(&files)
            .map_err(|(path, source)| DragonBonesError::Write { path, source })?;
        Ok(files.into_iter().rev().map(|(path, _)| path).collect())
    }
}

/// Exports `scene` as `name` (`images`: the parts' images in part order).
pub fn export_dragonbones(
    scene: &Scene,
    images: &[RgbaImage],
    name: &str,
    options: &DragonBonesOptions,
) -> Result<DragonBonesExport, DragonBonesError> {
    let doc = &scene.doc;
    // Refused as render refuses it (`scene::Playhead::frame`), with or without animations.
    if !doc.handles.physics.is_empty() && !doc.options.ik.momentum.is_empty() {
        return Err(DragonBonesError::Pose(Box::new(
            PipelineError::PhysicsWithMomentum,
        )));
    }
    if options.frame_rate == 0 || f64::from(options.frame_rate) > MAX_FRAME_RATE {
        return Err(DragonBonesError::FrameRate(options.frame_rate));
    }
    if options.max_vertices.is_some_and(|n| n < 3) || options.max_influences == Some(0) {
        return Err(DragonBonesError::Limits);
    }
    doc.check_animations()?;
    let columns = handle_columns(&doc.handles);
    if let Some(taken) = columns.iter().find(|c| **c == options.root_bone) {
        return Err(DragonBonesError::NameTaken(taken.clone()));
    }
    let frame = DbFrame::for_canvas(doc.canvas);
    let joints = joints::joints(&doc.handles, &frame);
    let rest_locals = joints::rest_locals(&joints);
    let setup: Vec<DbTransform> = rest_locals
        .iter()
        .map(|a| DbTransform::from_affine(a, None))
        .collect();
    let mut left_out = Vec::new();
    if !doc.skins.is_empty() {
        left_out.push(format!(
            "skins ({}): the default skin holds every attachment; the export shows the skins \
             this scene draws",
            doc.skins.keys().cloned().collect::<Vec<_>>().join(", ")
        ));
    }
    if !doc.handles.ik.is_empty() || !doc.handles.physics.is_empty() {
        left_out.push(
            "IK and physics constraints: their motion is baked into every animation's bone frames"
                .into(),
        );
    }

    // Bones: the root, then one per column.
    let bone_index = |j: usize| j + 1;
    let mut bones = vec![json!({ "name": options.root_bone })];
    for (j, joint) in joints.iter().enumerate() {
        let mut bone = Map::new();
        bone.insert("name".into(), json!(joint.name));
        let parent = match joint.parent {
            Some(p) => joints[p].name.as_str(),
            None => options.root_bone.as_str(),
        };
        bone.insert("parent".into(), json!(parent));
        if let Some(b) = doc.handles.bones.get(j) {
            bone.insert("length".into(), num((b.tail - b.head).norm()));
        }
        bone.insert("transform".into(), transform_json(&setup[j]));
        bones.push(Value::Object(bone));
    }

    // Slots and their displays; the atlas.
    let slots = doc.slot_names();
    let reach_px = f64::from(crate::scene::texture_border_px(doc));
    let mut regions = Vec::new();
    for (i, part) in doc.parts.iter().enumerate() {
        let image = &images[i];
        let got = [image.width(), image.height()];
        if !part.image_holds_mesh(got, reach_px) {
            return Err(DragonBonesError::ImageSize {
                part: part.name.clone(),
                got,
                offset_px: part.offset_px,
            });
        }
        let region = RegionRect::around(&part.mesh.vertices, options.region_margin_px);
        regions.push((part.name.clone(), image, part.offset_px, region));
    }
    let atlas_options = AtlasOptions {
        premultiplied_alpha: false,
        ..options.atlas.clone()
    };
    let tex_name = format!("{name}_tex");
    let atlas = atlas::pack_atlas(&tex_name, &regions, &atlas_options)
        .map_err(|e| DragonBonesError::Atlas(Box::new(e)))?;
    if atlas.pages.len() != 1 {
        return Err(DragonBonesError::Pages(atlas.pages.len()));
    }
    let page = &atlas.pages[0].image;
    let meshes = doc
        .parts
        .iter()
        .map(|part| written_mesh(part, &columns, options))
        .collect::<Result<Vec<_>, _>>()?;
    let mut start = 0;
    for (part, mesh) in doc.parts.iter().zip(&meshes) {
        if start >= MAX_MESH_FLOATS {
            return Err(DragonBonesError::MeshesTooLarge {
                part: part.name.clone(),
                start,
            });
        }
        start += mesh.floats();
    }
    let mut slots_json = Vec::new();
    let mut skin_slots = Vec::new();
    for slot in &slots {
        let attachments = doc.attachments_of(slot);
        let shown = doc.shown_part(slot, None, scene.skins());
        let display_index = shown
            .and_then(|s| attachments.iter().position(|&a| a == s))
            .map_or(-1, |k| k as i64);
        slots_json.push(json!({
            "name": slot,
            "parent": options.root_bone,
            "displayIndex": display_index,
        }));
        let mut displays = Vec::new();
        for &i in &attachments {
            let (_, _, _, region) = regions[i];
            displays.push(mesh_json(
                &doc.parts[i],
                &meshes[i],
                &region,
                &joints,
                &frame,
                bone_index,
            ));
        }
        skin_slots.push(json!({ "name": slot, "display": displays }));
    }

    // Animations.
    let mut animations_json = Vec::new();
    let mut baked = Vec::new();
    for (anim_name, animation) in &doc.animations {
        let sources: Vec<&[usize]> = meshes.iter().map(|m| m.kept.as_slice()).collect();
        let influences: Vec<usize> = meshes
            .iter()
            .map(|m| m.influences.iter().map(Vec::len).sum())
            .collect();
        let (json, b) = animation::bake(
            scene,
            anim_name,
            animation,
            &joints,
            &setup,
            &frame,
            &sources,
            &influences,
            options,
        )?;
        left_out.extend(b.left_out.iter().cloned());
        animations_json.push(json);
        baked.push(b);
    }

    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in doc.parts.iter().flat_map(|p| &p.mesh.vertices) {
        let q = frame.from_canvas(*v);
        lo = [lo[0].min(q.x), lo[1].min(q.y)];
        hi = [hi[0].max(q.x), hi[1].max(q.y)];
    }
    if !lo[0].is_finite() {
        (lo, hi) = ([0.0; 2], [0.0; 2]);
    }
    let armature = json!({
        "type": "Armature",
        "name": name,
        "frameRate": options.frame_rate,
        "aabb": { "x": num(lo[0]), "y": num(lo[1]), "width": num(hi[0] - lo[0]), "height": num(hi[1] - lo[1]) },
        "bone": bones,
        "slot": slots_json,
        "skin": [{ "name": "default", "slot": skin_slots }],
        "animation": animations_json,
        "defaultActions": doc.animations.keys().next().map(|a| vec![json!({ "gotoAndPlay": a })]).unwrap_or_default(),
    });
    let ske = json!({
        "frameRate": options.frame_rate,
        "name": name,
        "version": VERSION,
        "compatibleVersion": VERSION,
        "armature": [armature],
    });
    let sub_textures: Vec<Value> = atlas
        .regions
        .iter()
        .map(
            |r| json!({ "name": r.name, "x": r.x, "y": r.y, "width": r.width, "height": r.height }),
        )
        .collect();
    let tex = json!({
        "name": name,
        "imagePath": format!("{tex_name}.png"),
        "width": page.width(),
        "height": page.height(),
        "SubTexture": sub_textures,
    });
    let png = crate::export::spine::png_bytes(page, &format!("{tex_name}.png"))
        .map_err(|e| DragonBonesError::Atlas(Box::new(e)))?;
    Ok(DragonBonesExport {
        name: name.to_string(),
        frame,
        frame_rate: options.frame_rate,
        joints,
        setup,
        animations: baked,
        vertex_source: meshes.into_iter().map(|m| m.kept).collect(),
        left_out,
        ske: ske.to_string(),
        tex: tex.to_string(),
        png,
    })
}

/// What the DragonBones runtime plays of `animation` (named `name`) exported with `options`,
/// without writing the files: the frames [`export_dragonbones`] writes for it (`--match-runtime
/// dragonbones`). Meshes are not decimated here: sinew draws its own (as for Spine's game
/// preset), with the runtime's motion.
pub fn playback(
    scene: &Scene,
    name: &str,
    animation: &crate::anim::Animation,
    options: &DragonBonesOptions,
) -> Result<played::DbPlayback, DragonBonesError> {
    let doc = &scene.doc;
    if options.frame_rate == 0 || f64::from(options.frame_rate) > MAX_FRAME_RATE {
        return Err(DragonBonesError::FrameRate(options.frame_rate));
    }
    let frame = DbFrame::for_canvas(doc.canvas);
    let joints = joints::joints(&doc.handles, &frame);
    let setup: Vec<DbTransform> = joints::rest_locals(&joints)
        .iter()
        .map(|a| DbTransform::from_affine(a, None))
        .collect();
    let sources: Vec<Vec<usize>> = doc
        .parts
        .iter()
        .map(|p| (0..p.mesh.vertices.len()).collect())
        .collect();
    let sources: Vec<&[usize]> = sources.iter().map(Vec::as_slice).collect();
    let influences = vec![0; doc.parts.len()];
    let (_, baked) = animation::bake(
        scene,
        name,
        animation,
        &joints,
        &setup,
        &frame,
        &sources,
        &influences,
        options,
    )?;
    let slots = doc
        .slot_names()
        .into_iter()
        .map(|slot| {
            let names = doc
                .attachments_of(slot)
                .into_iter()
                .map(|i| doc.parts[i].name.clone())
                .collect();
            (slot.to_string(), names)
        })
        .collect();
    Ok(played::DbPlayback {
        frame_rate: options.frame_rate,
        frame,
        joints,
        setup,
        animation: baked,
        slots,
    })
}

/// A number as written: f32 precision (what the runtime keeps), shortest text.
pub(crate) fn num(v: f64) -> Value {
    let f = v as f32;
    if f == f.trunc() && f.abs() < 1e9 {
        json!(f as i64)
    } else {
        json!(f)
    }
}

/// A bone or frame transform as the file writes it (degrees; defaults left out).
fn transform_json(t: &DbTransform) -> Value {
    let mut m = Map::new();
    for (key, value, default) in [
        ("x", t.x, 0.0),
        ("y", t.y, 0.0),
        ("skX", (t.rotation_rad + t.skew_rad).to_degrees(), 0.0),
        ("skY", t.rotation_rad.to_degrees(), 0.0),
        ("scX", t.scale_x, 1.0),
        ("scY", t.scale_y, 1.0),
    ] {
        if value != default {
            m.insert(key.into(), num(value));
        }
    }
    Value::Object(m)
}

/// A part's mesh as written: the kept fine-mesh vertices, triangles over them, and each kept
/// vertex's influences (bone column, weight).
struct WrittenMesh {
    kept: Vec<usize>,
    triangles: Vec<[u32; 3]>,
    influences: Vec<Vec<(usize, f64)>>,
}

impl WrittenMesh {
    /// The numbers the runtime stores for it: vertices, uvs and three per influence.
    fn floats(&self) -> usize {
        4 * self.kept.len() + 3 * self.influences.iter().map(Vec::len).sum::<usize>()
    }
}

/// `part`'s mesh decimated and its influences limited as `options` say.
fn written_mesh(
    part: &io::PartDoc,
    columns: &[String],
    options: &DragonBonesOptions,
) -> Result<WrittenMesh, DragonBonesError> {
    let Some(weights) = &part.weights else {
        return Err(DragonBonesError::NoWeights(part.name.clone()));
    };
    let rows = joints::column_rows(part, weights, columns).map_err(|e| {
        DragonBonesError::UnknownWeightHandle {
            part: e.0,
            handle: e.1,
        }
    })?;
    let fine = part.mesh.to_mesh();
    let (kept, triangles) = match options.max_vertices {
        Some(n) if n < fine.vertices.len() => {
            crate::export::spine::decimate::decimate(&fine, &rows, n)
        }
        _ => ((0..fine.vertices.len()).collect(), fine.triangles.clone()),
    };
    let mut influences = Vec::with_capacity(kept.len());
    for &v in &kept {
        let row = crate::skin::strongest_influences(&rows[v], options.max_influences);
        if row.is_empty() {
            return Err(DragonBonesError::UnweightedVertex {
                part: part.name.clone(),
                vertex: v,
            });
        }
        influences.push(row);
    }
    Ok(WrittenMesh {
        kept,
        triangles,
        influences,
    })
}

/// A part's weighted mesh display: vertices in armature coordinates (the slot pose is the
/// identity), uvs over its region, its influences, and the bind poses of the bones they use.
fn mesh_json(
    part: &io::PartDoc,
    mesh: &WrittenMesh,
    region: &RegionRect,
    joints: &[Joint],
    frame: &DbFrame,
    bone_index: impl Fn(usize) -> usize,
) -> Value {
    let mut vertices = Vec::with_capacity(2 * mesh.kept.len());
    let mut uvs = Vec::with_capacity(2 * mesh.kept.len());
    for &v in &mesh.kept {
        let p = part.mesh.vertices[v];
        let q = frame.from_canvas(p);
        vertices.extend([num(q.x), num(q.y)]);
        let uv = region.uv(p);
        uvs.extend([num(uv.x), num(uv.y)]);
    }
    let mut weights_json = Vec::new();
    let mut used = std::collections::BTreeSet::new();
    for row in &mesh.influences {
        weights_json.push(json!(row.len()));
        let mut by_bone: Vec<(usize, f64)> = row.iter().map(|&(c, w)| (bone_index(c), w)).collect();
        by_bone.sort_by_key(|&(b, _)| b);
        for (bone, w) in by_bone {
            used.insert(bone);
            weights_json.extend([json!(bone), num(w)]);
        }
    }
    let mut bone_pose = Vec::new();
    for &bone in &used {
        let rest: &Affine = &joints[bone - 1].rest;
        let m = rest.linear;
        bone_pose.extend([
            json!(bone),
            num(m[(0, 0)]),
            num(m[(1, 0)]),
            num(m[(0, 1)]),
            num(m[(1, 1)]),
            num(rest.translation.x),
            num(rest.translation.y),
        ]);
    }
    json!({
        "type": "mesh",
        "name": part.name,
        "path": part.name,
        "width": region.width,
        "height": region.height,
        "vertices": vertices,
        "uvs": uvs,
        "triangles": mesh.triangles.concat(),
        "weights": weights_json,
        "slotPose": [1, 0, 0, 1, 0, 0],
        "bonePose": bone_pose,
    })
}
