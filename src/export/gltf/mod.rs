//! glTF export: a rig as one binary glTF 2.0 file (`.glb`) with skinned meshes, its textures
//! and its animations baked, which Godot 4, Bevy, Unity, Blender and three.js import.
//!
//! In: a loaded [`Scene`] (every part with weights), the parts' images (straight-alpha RGBA8
//! on the canvas) and [`GltfOptions`]. Out: a [`GltfExport`] held in memory; [`GltfExport::write`]
//! puts it in place atomically.
//!
//! What is written:
//! - one joint per weight column ([`joints`]), as a pivot node and a joint node so that any 2D
//!   affine map (shear included) is carried exactly ([`frame::Trsr`]); joints hang from a root
//!   node as bones hang from bones;
//! - one skinned mesh per part drawn in the setup pose, back to front along z
//!   ([`GltfOptions::layer_spacing`]), with at most [`MAX_INFLUENCES`] influences per vertex
//!   (the strongest, renormalized: [`crate::skin::strongest_influences`]); its deform keys as
//!   morph targets;
//! - the parts' images packed into straight-alpha atlas pages, one unlit, double-sided,
//!   alpha-blended material per page;
//! - every animation sampled at [`GltfOptions::bake_fps`] through the one pose path (skinning IK,
//!   bone IK, momentum and physics included) as linear keys of every joint, plus morph weights;
//!   its events in the animation's `extras`.
//!
//! What glTF cannot carry is listed in [`GltfExport::left_out`]: colour, visibility and
//! attachment keys, draw-order keys, parts hidden in the setup pose.
//!
//! At the bake times the runtime's skinned vertices are sinew's with the four kept influences
//! ([`Scene::with_influences_limited`]); `tests/gltf_runtime.rs` checks that with three.js and
//! the Khronos validator.

mod animation;
pub mod frame;
pub mod glb;
pub mod played;

use crate::anim::{self, AnimError};
use crate::export::spine::atlas::{self, AtlasOptions};
use crate::export::spine::mesh::RegionRect;
use crate::export::spine::SpineError;
use crate::geom::Vec2;
use crate::pipeline::{PipelineError, Scene};
use crate::rig::{handle_columns, Affine, Pose};
use animation::{bake_animation, unexpressed};
use frame::{z_quaternion, GltfFrame, Trsr};
use glb::{Buffer, ARRAY_BUFFER};
use image::RgbaImage;
use serde::{Deserialize, Serialize};
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

/// Influences per vertex: what glTF's `JOINTS_0`/`WEIGHTS_0` hold and every engine skins.
pub const MAX_INFLUENCES: usize = 4;

/// Highest bake rate accepted, keys per second.
pub const MAX_BAKE_FPS: f64 = crate::export::spine::MAX_BAKE_FPS;

/// How a rig is exported to glTF.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GltfOptions {
    /// Canvas px per glTF unit (a metre to most engines), > 0. Default 100, Unity's sprite
    /// default: a 500 px character stands 5 units tall.
    pub px_per_unit: f64,
    /// Keys per second of the baked animations, in (0, [`MAX_BAKE_FPS`]]. Default 30.
    pub bake_fps: f64,
    /// Distance along z between consecutive parts of the draw order, glTF units, ≥ 0; the
    /// front part is nearest +z. Default 0.001 (0.1 px at the default scale).
    pub layer_spacing: f64,
    /// Transparent px around each mesh's box in its atlas region. Default 2.
    pub region_margin_px: u32,
    /// Atlas packing; pages are always straight alpha (glTF's colour is not premultiplied).
    pub atlas: AtlasOptions,
    /// Name of the node the joints hang from. Default `root`.
    pub root_node: String,
}

impl Default for GltfOptions {
    fn default() -> Self {
        GltfOptions {
            px_per_unit: 100.0,
            bake_fps: 30.0,
            layer_spacing: 0.001,
            region_margin_px: 2,
            atlas: AtlasOptions {
                premultiplied_alpha: false,
                ..AtlasOptions::default()
            },
            root_node: "root".into(),
        }
    }
}

/// What stops a glTF export.
#[derive(Debug, thiserror::Error)]
pub enum GltfError {
    #[error(
        "part '{0}' has no weights: rig it with handles (sinew rig --handles) before exporting"
    )]
    NoWeights(String),
    #[error("part '{part}': vertex {vertex} has no positive weight")]
    UnweightedVertex { part: String, vertex: usize },
    #[error("part '{part}' has weights for handle '{handle}', which the rig does not have")]
    UnknownWeightHandle { part: String, handle: String },
    #[error("the bake rate must be a number in (0, {MAX_BAKE_FPS}] keys per second, not {0}")]
    Fps(f64),
    #[error("--px-per-unit must be a positive number, not {0}")]
    PxPerUnit(f64),
    #[error("the layer spacing must be a finite number ≥ 0, not {0}")]
    LayerSpacing(f64),
    #[error("the rig has {0} handle columns; glTF joint indices hold at most 65,535")]
    TooManyJoints(usize),
    #[error(
        "animation '{animation}' would be sampled {samples:.3e} times (duration × bake fps): at \
         most {}",
        crate::export::spine::MAX_BAKE_SAMPLES
    )]
    TooLong { animation: String, samples: f64 },
    #[error("the transformation of '{0}' is singular (a zero scale?)")]
    Singular(String),
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
pub struct GltfExport {
    /// The `.glb` file's bytes.
    pub glb: Vec<u8>,
    pub frame: GltfFrame,
    /// One per weight column.
    pub joints: Vec<crate::export::joints::Joint>,
    /// The parts written, back to front.
    pub parts: Vec<String>,
    /// The morph targets of the parts that have some (canvas px offsets, one per vertex).
    pub morph_targets: std::collections::BTreeMap<String, Vec<Vec<Vec2>>>,
    /// Per animation, its keys as written ([`played`] plays them as the runtimes do).
    pub animations: Vec<played::GltfAnimation>,
    /// What the rig has that glTF does not carry, one line each.
    pub left_out: Vec<String>,
}

impl GltfExport {
    /// Writes the file at `path` atomically (a failed write leaves what was there).
    pub fn write(&self, path: &Path) -> Result<(), GltfError> {
        crate::io::atomic::write_atomic(path, &self.glb).map_err(|source| GltfError::Write {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// One part as written: which part, its layer and its morph targets (deform offsets, canvas px).
struct WrittenPart {
    part: usize,
    targets: Vec<Vec<Vec2>>,
}

/// Exports `scene` (`images`: the parts' images in part order) as glTF.
pub fn export_gltf(
    scene: &Scene,
    images: &[RgbaImage],
    options: &GltfOptions,
) -> Result<GltfExport, GltfError> {
    let doc = &scene.doc;
    // Refused as render refuses it (`scene::Playhead::frame`), with or without animations.
    if !doc.handles.physics.is_empty() && !doc.options.ik.momentum.is_empty() {
        return Err(GltfError::Pose(Box::new(
            PipelineError::PhysicsWithMomentum,
        )));
    }
    check_options(options)?;
    let columns = handle_columns(&doc.handles);
    if columns.len() > usize::from(u16::MAX) {
        return Err(GltfError::TooManyJoints(columns.len()));
    }
    doc.check_animations()?;
    let frame = GltfFrame::for_canvas(doc.canvas, options.px_per_unit);
    let joints = crate::export::joints::joints(&doc.handles, &frame);
    let mut left_out = Vec::new();

    let written = setup_parts(scene);
    let hidden: Vec<&str> = doc
        .parts
        .iter()
        .enumerate()
        .filter(|(i, _)| !written.iter().any(|w| w.part == *i))
        .map(|(_, p)| p.name.as_str())
        .collect();
    if !hidden.is_empty() {
        left_out.push(format!(
            "parts not drawn in the setup pose (other attachments or skins, hidden slots): {}",
            hidden.join(", ")
        ));
    }

    // Atlas pages.
    let reach_px = f64::from(crate::scene::texture_border_px(doc));
    let mut regions = Vec::with_capacity(written.len());
    for w in &written {
        let part = &doc.parts[w.part];
        let image = &images[w.part];
        let got = [image.width(), image.height()];
        if !part.image_holds_mesh(got, reach_px) {
            return Err(GltfError::ImageSize {
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
    let atlas = atlas::pack_atlas("page", &regions, &atlas_options)
        .map_err(|e| GltfError::Atlas(Box::new(e)))?;

    let mut buffer = Buffer::default();
    let mut document = Map::new();
    document.insert(
        "asset".into(),
        json!({ "version": "2.0", "generator": concat!("sinew ", env!("CARGO_PKG_VERSION")) }),
    );
    document.insert("extensionsUsed".into(), json!(["KHR_materials_unlit"]));

    // Textures and materials, one per page.
    let mut images_json = Vec::new();
    for page in &atlas.pages {
        let png = crate::export::spine::png_bytes(&page.image, &page.file_name)
            .map_err(|e| GltfError::Atlas(Box::new(e)))?;
        let view = buffer.view(&png, None);
        images_json
            .push(json!({ "bufferView": view, "mimeType": "image/png", "name": page.file_name }));
    }
    let pages = atlas.pages.len();
    document.insert("images".into(), Value::Array(images_json));
    document.insert(
        "samplers".into(),
        json!([{ "magFilter": 9729, "minFilter": 9987, "wrapS": 33071, "wrapT": 33071 }]),
    );
    document.insert(
        "textures".into(),
        Value::Array(
            (0..pages)
                .map(|p| json!({ "sampler": 0, "source": p }))
                .collect(),
        ),
    );
    document.insert(
        "materials".into(),
        Value::Array(
            (0..pages)
                .map(|p| {
                    json!({
                        "name": format!("page{}", p + 1),
                        "pbrMetallicRoughness": {
                            "baseColorTexture": { "index": p },
                            "metallicFactor": 0.0,
                            "roughnessFactor": 1.0,
                        },
                        "alphaMode": "BLEND",
                        "doubleSided": true,
                        "extensions": { "KHR_materials_unlit": {} },
                    })
                })
                .collect(),
        ),
    );

    // Meshes.
    let mut meshes = Vec::with_capacity(written.len());
    for (layer, w) in written.iter().enumerate() {
        let part = &doc.parts[w.part];
        let packed = &atlas.regions[layer];
        let page = &atlas.pages[packed.page].image;
        let (_, _, _, region) = regions[layer];
        let z = layer as f64 * options.layer_spacing;
        let mut positions = Vec::with_capacity(part.mesh.vertices.len() * 3);
        let mut uvs = Vec::with_capacity(part.mesh.vertices.len() * 2);
        for &p in &part.mesh.vertices {
            let q = frame.from_canvas(p);
            positions.extend([q.x as f32, q.y as f32, z as f32]);
            let uv = region.uv(p);
            uvs.extend([
                ((f64::from(packed.x) + uv.x * f64::from(region.width)) / f64::from(page.width()))
                    as f32,
                ((f64::from(packed.y) + uv.y * f64::from(region.height)) / f64::from(page.height()))
                    as f32,
            ]);
        }
        let (joint_ids, weights) = influences(part, &columns)?;
        let triangles: Vec<u32> = part.mesh.to_mesh().triangles.concat();
        let position = buffer.floats(&positions, "VEC3", true, Some(ARRAY_BUFFER));
        let texcoord = buffer.floats(&uvs, "VEC2", false, Some(ARRAY_BUFFER));
        let joints_accessor = buffer.joints(&joint_ids);
        let weights_accessor = buffer.floats(&weights, "VEC4", false, Some(ARRAY_BUFFER));
        let indices = buffer.indices(&triangles);
        let mut primitive = json!({
            "attributes": {
                "POSITION": position,
                "TEXCOORD_0": texcoord,
                "JOINTS_0": joints_accessor,
                "WEIGHTS_0": weights_accessor,
            },
            "indices": indices,
            "material": packed.page,
            "mode": 4,
        });
        let mut mesh = json!({ "name": part.name, "primitives": [] });
        if !w.targets.is_empty() {
            let targets: Vec<Value> = w
                .targets
                .iter()
                .map(|offsets| {
                    let data: Vec<f32> = offsets
                        .iter()
                        .flat_map(|&o| {
                            let v = frame.vector(o);
                            [v.x as f32, v.y as f32, 0.0]
                        })
                        .collect();
                    json!({ "POSITION": buffer.floats(&data, "VEC3", true, Some(ARRAY_BUFFER)) })
                })
                .collect();
            primitive["targets"] = Value::Array(targets);
            mesh["weights"] = json!(vec![0.0; w.targets.len()]);
        }
        mesh["primitives"] = json!([primitive]);
        meshes.push(mesh);
    }
    document.insert("meshes".into(), Value::Array(meshes));

    // Nodes: the root, each joint's pivot and joint, then the meshes.
    let pivot_node = |j: usize| 1 + 2 * j;
    let joint_node = |j: usize| 2 + 2 * j;
    let mesh_node = |k: usize| 1 + 2 * joints.len() + k;
    let rest_locals = crate::export::joints::rest_locals(&joints);
    let mut nodes = Vec::with_capacity(1 + 2 * joints.len() + written.len());
    let top: Vec<usize> = (0..joints.len())
        .filter(|&j| joints[j].parent.is_none())
        .map(pivot_node)
        .collect();
    let mut root = json!({ "name": options.root_node });
    if !top.is_empty() {
        root["children"] = json!(top);
    }
    nodes.push(root);
    for (j, joint) in joints.iter().enumerate() {
        let t = Trsr::from_affine(&rest_locals[j], None);
        nodes.push(json!({
            "name": format!("{}.pivot", joint.name),
            "translation": [t.translation.x, t.translation.y, 0.0],
            "rotation": z_quaternion(t.pivot_rad),
            "scale": [t.scale[0], t.scale[1], 1.0],
            "children": [joint_node(j)],
        }));
        let mut node = json!({ "name": joint.name, "rotation": z_quaternion(t.joint_rad) });
        let children: Vec<usize> = (0..joints.len())
            .filter(|&c| joints[c].parent == Some(j))
            .map(pivot_node)
            .collect();
        if !children.is_empty() {
            node["children"] = json!(children);
        }
        nodes.push(node);
    }
    for (k, w) in written.iter().enumerate() {
        nodes.push(json!({ "name": doc.parts[w.part].name, "mesh": k, "skin": 0 }));
    }
    document.insert("nodes".into(), Value::Array(nodes));
    let mut scene_nodes = vec![0];
    scene_nodes.extend((0..written.len()).map(mesh_node));
    document.insert(
        "scenes".into(),
        json!([{ "name": "sinew", "nodes": scene_nodes }]),
    );
    document.insert("scene".into(), json!(0));

    // The skin: inverse bind matrices B⁻¹.
    let mut ibm = Vec::with_capacity(16 * joints.len());
    for joint in &joints {
        let inv = joint
            .rest
            .inverse()
            .ok_or_else(|| GltfError::Singular(joint.name.clone()))?;
        ibm.extend(mat4(&inv));
    }
    let ibm_accessor = buffer.floats(&ibm, "MAT4", false, None);
    document.insert(
        "skins".into(),
        json!([{
            "inverseBindMatrices": ibm_accessor,
            "joints": (0..joints.len()).map(joint_node).collect::<Vec<_>>(),
            "skeleton": 0,
        }]),
    );

    // Animations.
    let mut animations = Vec::new();
    let mut report = Vec::new();
    for (name, animation) in &doc.animations {
        let baked = bake_animation(
            scene,
            name,
            animation,
            &joints,
            &rest_locals,
            &frame,
            &written,
            options,
            &mut buffer,
        )?;
        report.push(baked.played);
        let mut channels = Vec::new();
        let mut samplers = Vec::new();
        for (node, path, output) in baked.channels {
            channels.push(
                json!({ "sampler": samplers.len(), "target": { "node": node, "path": path } }),
            );
            samplers
                .push(json!({ "input": baked.input, "output": output, "interpolation": "LINEAR" }));
        }
        let mut a = json!({ "name": name, "channels": channels, "samplers": samplers });
        if !animation.events.is_empty() {
            a["extras"] = json!({ "events": animation.events });
        }
        animations.push(a);
        left_out.extend(unexpressed(name, animation));
    }
    if !animations.is_empty() {
        document.insert("animations".into(), Value::Array(animations));
    }
    Ok(GltfExport {
        glb: buffer.into_glb(document),
        frame,
        joints,
        morph_targets: written
            .iter()
            .filter(|w| !w.targets.is_empty())
            .map(|w| (doc.parts[w.part].name.clone(), w.targets.clone()))
            .collect(),
        parts: written
            .iter()
            .map(|w| doc.parts[w.part].name.clone())
            .collect(),
        animations: report,
        left_out,
    })
}

/// What a glTF runtime plays of `animation` (named `name`) exported with `options`, without
/// writing the file: the keys [`export_gltf`] writes for it (`--match-runtime gltf`).
pub fn playback(
    scene: &Scene,
    name: &str,
    animation: &crate::anim::Animation,
    options: &GltfOptions,
) -> Result<played::GltfPlayback, GltfError> {
    let doc = &scene.doc;
    check_options(options)?;
    let frame = GltfFrame::for_canvas(doc.canvas, options.px_per_unit);
    let joints = crate::export::joints::joints(&doc.handles, &frame);
    let rest_locals = crate::export::joints::rest_locals(&joints);
    let written = setup_parts(scene);
    let baked = bake_animation(
        scene,
        name,
        animation,
        &joints,
        &rest_locals,
        &frame,
        &written,
        options,
        &mut Buffer::default(),
    )?;
    Ok(played::GltfPlayback {
        frame,
        morph_targets: written
            .iter()
            .filter(|w| !w.targets.is_empty())
            .map(|w| (doc.parts[w.part].name.clone(), w.targets.clone()))
            .collect(),
        joints,
        animation: baked.played,
    })
}

/// The parts the setup pose draws, back to front, with their morph targets.
fn setup_parts(scene: &Scene) -> Vec<WrittenPart> {
    let doc = &scene.doc;
    let rest = scene.rest_positions();
    crate::playback::pose_draws(scene, &rest, &Pose::default())
        .iter()
        .filter(|draw| draw.visible)
        .map(|draw| WrittenPart {
            part: draw.part,
            targets: morph_targets(doc, &doc.parts[draw.part].name),
        })
        .collect()
}

fn check_options(options: &GltfOptions) -> Result<(), GltfError> {
    let fps = options.bake_fps;
    if !(fps.is_finite() && fps > 0.0 && fps <= MAX_BAKE_FPS) {
        return Err(GltfError::Fps(fps));
    }
    let ppu = options.px_per_unit;
    if !(ppu.is_finite() && ppu > 0.0) {
        return Err(GltfError::PxPerUnit(ppu));
    }
    let spacing = options.layer_spacing;
    if !(spacing.is_finite() && spacing >= 0.0) {
        return Err(GltfError::LayerSpacing(spacing));
    }
    Ok(())
}

/// The distinct non-zero deform keys of `part` over every animation, in animation then key
/// order: its morph targets.
fn morph_targets(doc: &crate::io::RigDocument, part: &str) -> Vec<Vec<Vec2>> {
    let mut targets: Vec<Vec<Vec2>> = Vec::new();
    for animation in doc.animations.values() {
        for key in animation.deform.get(part).into_iter().flatten() {
            let zero = key.value.iter().all(|o| o.x == 0.0 && o.y == 0.0);
            if !zero && !targets.contains(&key.value) {
                targets.push(key.value.clone());
            }
        }
    }
    targets
}

/// The morph weights of `targets` at `time_s` of `keys`: each key's offsets as a one-hot vector
/// over the targets, sampled with the keys' own curves, so Σ weight·target is the deform the
/// pose path samples.
fn morph_weights(keys: &anim::deform::DeformKeys, targets: &[Vec<Vec2>], time_s: f64) -> Vec<f64> {
    let one_hot: anim::deform::DeformKeys = keys
        .iter()
        .map(|key| {
            let mut value = vec![Vec2::zeros(); targets.len()];
            if let Some(i) = targets.iter().position(|t| *t == key.value) {
                value[i] = Vec2::new(1.0, 0.0);
            }
            anim::timeline::Key {
                time: key.time,
                value,
                curve: key.curve.clone(),
            }
        })
        .collect();
    anim::sample::sample_keys(&one_hot, time_s)
        .map(|v| v.iter().map(|w| w.x).collect())
        .unwrap_or_else(|| vec![0.0; targets.len()])
}

/// A part's joints and weights, four per vertex (unused slots joint 0, weight 0), the weights
/// summing to one in f32.
fn influences(
    part: &crate::io::PartDoc,
    columns: &[String],
) -> Result<(Vec<u16>, Vec<f32>), GltfError> {
    let Some(weights) = &part.weights else {
        return Err(GltfError::NoWeights(part.name.clone()));
    };
    let rows = crate::export::joints::column_rows(part, weights, columns).map_err(|e| {
        GltfError::UnknownWeightHandle {
            part: e.0,
            handle: e.1,
        }
    })?;
    let mut joint_ids = Vec::with_capacity(weights.rows.len() * 4);
    let mut out = Vec::with_capacity(weights.rows.len() * 4);
    for (vertex, row) in rows.iter().enumerate() {
        let kept = crate::skin::strongest_influences(row, Some(MAX_INFLUENCES));
        if kept.is_empty() {
            return Err(GltfError::UnweightedVertex {
                part: part.name.clone(),
                vertex,
            });
        }
        let mut ids = [0u16; 4];
        let mut w = [0f32; 4];
        for (k, &(h, weight)) in kept.iter().enumerate() {
            ids[k] = h as u16;
            w[k] = weight as f32;
        }
        // The strongest weight takes the f32 rounding of the sum.
        let rest: f32 = w[1..].iter().sum();
        w[0] = 1.0 - rest;
        joint_ids.extend(ids);
        out.extend(w);
    }
    Ok((joint_ids, out))
}

/// A 2D affine map as a column-major 4×4 matrix (z untouched).
fn mat4(a: &Affine) -> [f32; 16] {
    let m = a.linear;
    let t = a.translation;
    [
        m[(0, 0)] as f32,
        m[(1, 0)] as f32,
        0.0,
        0.0,
        m[(0, 1)] as f32,
        m[(1, 1)] as f32,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
        0.0,
        t.x as f32,
        t.y as f32,
        0.0,
        1.0,
    ]
}
