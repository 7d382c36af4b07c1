//! The stages wired together, for the command line and the editor alike.
//!
//! - [`load_layers`]: image files → [`Layer`]s on one canvas (same size, unique names).
//! - [`build_rig`]: layers + [`BuildOptions`] + [`Handles`] → a [`RigDocument`] (trace, mesh
//!   with the handles' geometry embedded, weights, per part).
//! - [`Scene`]: a loaded document with its textures: poses it (forward kinematics + skinning)
//!   and draws any vertex positions.
//! - [`keep_locked_weights`]: a rebuilt document keeps the locked handles' previous weights.

use crate::geom::{Point, Vec2};
use crate::ik::{RigIk, SkinnedMesh};
use crate::io::{self, BuildOptions, ImageError, MeshDoc, PartDoc, RigDocument, WeightsDoc};
use crate::mesh::{self, HandleGeometry, MeshError, MeshStats};
use crate::render::{self, MeshRenderer, PartDraw, RenderError, RenderPart, Texture};
use crate::rig::pose::{bone_stretches_under, Affine};
use crate::rig::{handle_columns, handle_transforms, HandleError, Handles, Pose, PoseError};
use crate::skin::{skin, stretchable_blend, Blend, SkinWeights};
use crate::trace::{self, TraceError};
use crate::weights::{self, WeightError};
use image::RgbaImage;
use std::borrow::Borrow;
use std::collections::{BTreeSet, HashSet};
use std::path::{Path, PathBuf};

/// One input image: a part of the rig.
#[derive(Clone, Debug)]
pub struct Layer {
    /// The part's name: the file name without extension.
    pub name: String,
    pub path: PathBuf,
    pub image: RgbaImage,
}

/// What went wrong between the input files and a rig.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    #[error(transparent)]
    Image(#[from] ImageError),
    #[error(transparent)]
    Document(#[from] io::DocumentError),
    #[error(transparent)]
    Layered(#[from] io::layered::LayeredFileError),
    #[error("{path}: image is {}×{} px, too small to rig (at least {MIN_SPRITE_SIDE_PX}×{MIN_SPRITE_SIDE_PX})", got[0], got[1])]
    TooSmall { path: PathBuf, got: [u32; 2] },
    #[error("no input images")]
    NoImages,
    #[error("cancelled")]
    Cancelled,
    #[error(
        "the pose deforms part '{part}' with {got} offsets but its mesh has {expected} vertices"
    )]
    DeformSize {
        part: String,
        got: usize,
        expected: usize,
    },
    #[error(
        "physics constraints cannot be combined with the skinning IK's momentum yet (turn \
         momentum off, or remove the physics constraints)"
    )]
    PhysicsWithMomentum,
    #[error("the pose deforms part '{0}', which the rig does not have")]
    DeformUnknownPart(String),
    #[error("momentum is simulated from the animation's start: time {0:e} s lies outside [0, {max}] s", max = crate::scene::MAX_SIMULATED_S)]
    SimulatedTime(f64),
    #[error("{path}: image is {got:?} px but the canvas (from the first image) is {canvas:?} px; all layers must share one canvas")]
    SizeMismatch {
        path: PathBuf,
        got: [u32; 2],
        canvas: [u32; 2],
    },
    #[error(
        "{path}: a part named '{name}' already exists (part names come from file and layer names)"
    )]
    DuplicatePart { path: PathBuf, name: String },
    #[error("{path}: {source}")]
    Trace { path: PathBuf, source: TraceError },
    #[error("{path}: no opaque region of at least {min_area_px2} px² (see --alpha-threshold)")]
    NoShape { path: PathBuf, min_area_px2: f64 },
    #[error("{path}: {source}")]
    Mesh { path: PathBuf, source: MeshError },
    #[error("handles: cage '{cage}': {problem}")]
    Cage { cage: String, problem: String },
    #[error("part '{part}': {source}")]
    Render { part: String, source: RenderError },
    #[error("part '{part}': image is {got:?} px but the rig's canvas is {canvas:?} px")]
    TextureSize {
        part: String,
        got: [u32; 2],
        canvas: [u32; 2],
    },
    #[error("part '{part}': {got} vertex positions for a mesh of {expected} vertices")]
    PositionCount {
        part: String,
        got: usize,
        expected: usize,
    },
    #[error("handles: {0}")]
    Handles(#[from] HandleError),
    #[error("handle '{0}' lies outside every part it may weigh")]
    HandleOutside(String),
    #[error("handles: 'bind' gives handle '{handle}' the part '{part}', which is not a layer")]
    UnknownBindPart { handle: String, part: String },
    #[error("{path}: weights: {source}")]
    Weights { path: PathBuf, source: WeightError },
    #[error("pose: {0}")]
    Pose(#[from] PoseError),
    #[error(transparent)]
    Ik(#[from] crate::ik::IkError),
    #[error("cannot bake: played back, the rig's bone IK constraints ({0}) would solve again and not reproduce the baked motion (skinning IK moved a constrained chain)")]
    BakeBoneIk(String),
    #[error("part '{part}' has weights for handle '{handle}', which the rig does not have")]
    UnknownWeightHandle { part: String, handle: String },
    #[error("canvas {0:?} px is too large to draw")]
    Canvas([u32; 2]),
    #[error("part '{part}': keeping locked weights: {source}")]
    Locked {
        part: String,
        source: weights::LockError,
    },
    #[error("there is no part {0}")]
    UnknownPart(usize),
}

/// What building one part found, for the report a person reads.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PartReport {
    pub mesh: MeshStats,
    /// Handles whose bounded weights stopped at the iteration limit (accurate to about 1e-3).
    pub unconverged: Vec<String>,
    /// Handles that pieces no handle touches were bound to rigidly.
    pub bound_to_nearest: Vec<String>,
    /// How many mesh vertices those pieces have.
    pub bound_vertices: usize,
}

/// Images narrower or lower than this (px) are too small to trace and rig.
pub const MIN_SPRITE_SIDE_PX: u32 = 4;

/// Loads image files as the layers of one canvas, in the given (draw) order.
pub fn load_layers(paths: &[PathBuf]) -> Result<Vec<Layer>, PipelineError> {
    let mut layers: Vec<Layer> = Vec::with_capacity(paths.len());
    for path in paths {
        let image = io::load_png(path)?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        layers.push(Layer {
            name,
            path: path.clone(),
            image,
        });
    }
    checked_layers(layers)
}

/// `layers` when they can be the parts of one rig: at least one, each at least
/// [`MIN_SPRITE_SIDE_PX`] on a side, all of the first one's size, names unique.
pub fn checked_layers(layers: Vec<Layer>) -> Result<Vec<Layer>, PipelineError> {
    let mut names = HashSet::new();
    let canvas = match layers.first() {
        Some(first) => [first.image.width(), first.image.height()],
        None => return Err(PipelineError::NoImages),
    };
    for layer in &layers {
        let path = &layer.path;
        let got = [layer.image.width(), layer.image.height()];
        if got[0] < MIN_SPRITE_SIDE_PX || got[1] < MIN_SPRITE_SIDE_PX {
            return Err(PipelineError::TooSmall {
                path: path.clone(),
                got,
            });
        }
        if got != canvas {
            return Err(PipelineError::SizeMismatch {
                path: path.clone(),
                got,
                canvas,
            });
        }
        if !names.insert(layer.name.clone()) {
            return Err(PipelineError::DuplicatePart {
                path: path.clone(),
                name: layer.name.clone(),
            });
        }
    }
    Ok(layers)
}

/// Traces and meshes every layer and, when there are handles, embeds their geometry in every
/// mesh and computes weights. `doc_dir` is the folder the document will be saved in: image
/// paths are stored relative to it. Returns the document and each part's mesh statistics.
/// `layers` may be owned or shared (`Arc<Layer>`, as the editor keeps them): nothing is copied.
pub fn build_rig<L: Borrow<Layer>>(
    layers: &[L],
    doc_dir: &Path,
    options: &BuildOptions,
    handles: &Handles,
) -> Result<(RigDocument, Vec<PartReport>), PipelineError> {
    build_rig_with_progress(layers, doc_dir, options, handles, &mut |_, _| {})
}

/// [`build_rig`], calling `progress(parts_done, part_name)` before each part and once at the
/// end (with an empty name), for progress bars.
pub fn build_rig_with_progress<L: Borrow<Layer>>(
    layers: &[L],
    doc_dir: &Path,
    options: &BuildOptions,
    handles: &Handles,
    progress: &mut dyn FnMut(usize, &str),
) -> Result<(RigDocument, Vec<PartReport>), PipelineError> {
    let never = std::sync::atomic::AtomicBool::new(false);
    build_rig_cancellable(layers, doc_dir, options, handles, progress, &never)
}

/// [`build_rig_with_progress`] that stops with [`PipelineError::Cancelled`] before the next
/// part once `cancel` is set (the editor builds rigs on a background thread).
pub fn build_rig_cancellable<L: Borrow<Layer>>(
    layers: &[L],
    doc_dir: &Path,
    options: &BuildOptions,
    handles: &Handles,
    progress: &mut dyn FnMut(usize, &str),
    cancel: &std::sync::atomic::AtomicBool,
) -> Result<(RigDocument, Vec<PartReport>), PipelineError> {
    let first: &Layer = layers.first().ok_or(PipelineError::NoImages)?.borrow();
    let canvas = [first.image.width(), first.image.height()];
    let canvas_area = canvas[0] as f64 * canvas[1] as f64;
    let mut doc = RigDocument::new(canvas);
    doc.options = options.clone();
    doc.handles = handles.clone();
    handles.validate()?;
    let columns = handle_columns(handles);
    if let Some((handle, part)) = handles.bind.iter().find_map(|(handle, parts)| {
        parts
            .iter()
            .find(|p| !layers.iter().any(|l| &l.borrow().name == *p))
            .map(|p| (handle, p))
    }) {
        return Err(PipelineError::UnknownBindPart {
            handle: handle.clone(),
            part: part.clone(),
        });
    }
    let mut touched = vec![0usize; columns.len()];
    let mut stats = Vec::with_capacity(layers.len());
    for (done, layer) in layers.iter().enumerate() {
        let layer: &Layer = layer.borrow();
        if cancel.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(PipelineError::Cancelled);
        }
        progress(done, &layer.name);
        let outlines =
            trace::trace(&layer.image, &options.trace).map_err(|source| PipelineError::Trace {
                path: layer.path.clone(),
                source,
            })?;
        if outlines.is_empty() {
            let min_area_px2 = options.trace.min_area_px2;
            return Err(PipelineError::NoShape {
                path: layer.path.clone(),
                min_area_px2,
            });
        }
        let mut notes = PartReport::default();
        let mesh_error = |source| PipelineError::Mesh {
            path: layer.path.clone(),
            source,
        };
        let (mesh, weights) = if columns.is_empty() {
            (
                mesh::triangulate(&outlines, canvas_area, &options.mesh).map_err(mesh_error)?,
                None,
            )
        } else {
            let bound = handles.for_part(&layer.name);
            let geometry = handle_geometry(&bound);
            let embedded =
                mesh::triangulate_with_handles(&outlines, &geometry, canvas_area, &options.mesh)
                    .map_err(|e| cage_error(&bound, e).unwrap_or_else(mesh_error))?;
            let binding = handles.columns_binding(&layer.name);
            let coarse = coarse_weight_mesh(&embedded, &outlines, &geometry, canvas_area, options)
                .map_err(|e| cage_error(&bound, e).unwrap_or_else(mesh_error))?;
            let colors = |mesh: &mesh::EmbeddedMesh| {
                options
                    .weights
                    .content_aware
                    .map(|_| vertex_colors(&layer.image, &mesh.domain.vertices))
            };
            let part = match &coarse {
                Some(coarse) => weights::two_level::two_level_weights(
                    &embedded,
                    coarse,
                    handles,
                    &binding,
                    colors(&embedded).as_deref(),
                    colors(coarse).as_deref(),
                    &options.weights,
                ),
                None => weights::part::bound_part_weights(
                    &embedded,
                    handles,
                    &binding,
                    colors(&embedded).as_deref(),
                    &options.weights,
                ),
            }
            .map_err(|source| PipelineError::Weights {
                path: layer.path.clone(),
                source,
            })?;
            for (t, n) in touched.iter_mut().zip(&part.touched) {
                *t += n;
            }
            let name = |j: &usize| columns[*j].clone();
            notes.unconverged = part.unconverged.iter().map(name).collect();
            notes.bound_to_nearest = part.bound_to_nearest.iter().map(name).collect();
            notes.bound_vertices = part.bound_vertices;
            let weights = WeightsDoc {
                handles: columns.clone(),
                rows: part.rows,
            };
            (embedded.shape_mesh().0, Some(weights))
        };
        stats.push(PartReport {
            mesh: mesh.stats(),
            ..notes
        });
        doc.parts.push(PartDoc {
            name: layer.name.clone(),
            slot: None,
            image: relative_path(doc_dir, &layer.path),
            mesh: MeshDoc::from(&mesh),
            weights,
            stale_weights: None,
        });
    }
    progress(layers.len(), "");
    if let Some(column) = touched.iter().position(|&n| n == 0) {
        return Err(PipelineError::HandleOutside(columns[column].clone()));
    }
    Ok((doc, stats))
}

/// The coarse mesh of the same weight domain that two-level weights solve on
/// ([`weights::part::TwoLevelOptions`]), or `None` for the exact solve on `fine` (two-level off,
/// or `fine` not more than [`weights::part::TWO_LEVEL_MIN_RATIO`] times the target). Its
/// largest triangle area is the domain's area over the target vertex count (a refined
/// Delaunay mesh has about two triangles per vertex, at about half the largest area each).
fn coarse_weight_mesh(
    fine: &mesh::EmbeddedMesh,
    outlines: &[trace::Outline],
    geometry: &mesh::HandleGeometry,
    canvas_area_px2: f64,
    options: &BuildOptions,
) -> Result<Option<mesh::EmbeddedMesh>, mesh::MeshError> {
    let Some(target) = options
        .weights
        .two_level
        .as_ref()
        .map(|t| t.coarse_vertices)
    else {
        return Ok(None);
    };
    if fine.domain.vertices.len() <= target.saturating_mul(weights::part::TWO_LEVEL_MIN_RATIO) {
        return Ok(None);
    }
    let area_px2: f64 = fine
        .domain
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| fine.domain.vertices[v as usize]);
            0.5 * crate::geom::triangle_area2(a, b, c).abs()
        })
        .sum();
    let coarse = mesh::MeshOptions {
        max_area_fraction: area_px2 / target.max(1) as f64 / canvas_area_px2,
        ..options.mesh.clone()
    };
    mesh::triangulate_with_handles(outlines, geometry, canvas_area_px2, &coarse).map(Some)
}

/// A mesh error that concerns a cage, named (the image is not at fault); others back as they are.
fn cage_error(handles: &Handles, error: MeshError) -> Result<PipelineError, MeshError> {
    let name = |i: usize| {
        handles
            .cages
            .get(i)
            .map_or("?", |c| c.name.as_str())
            .to_string()
    };
    match error {
        MeshError::CageAlongOutline { cage, edge } => Ok(PipelineError::Cage {
            cage: name(cage),
            problem: format!(
                "its edge {edge} (vertices {edge}–{}) runs along the drawing's outline: move \
                 that edge's vertices off the outline",
                (edge + 1) % handles.cages[cage].polygon.len()
            ),
        }),
        MeshError::CagesCross { first, second } => Ok(PipelineError::Cage {
            cage: name(first),
            problem: format!("it crosses cage '{}': cages must not overlap", name(second)),
        }),
        other => Err(other),
    }
}

/// The geometry every mesh must carry for the handles: bone segments, point positions, cage
/// and region outlines (cage insides also join the weight domain).
pub fn handle_geometry(handles: &Handles) -> HandleGeometry {
    let pt = |a: &[f64; 2]| Point::new(a[0], a[1]);
    let ring = |poly: &Vec<[f64; 2]>| poly.iter().map(pt).collect::<Vec<_>>();
    HandleGeometry {
        points: handles.points.iter().map(|p| pt(&p.at)).collect(),
        segments: handles
            .bones
            .iter()
            .map(|b| [pt(&b.head), pt(&b.tail)])
            .collect(),
        polygons: handles
            .cages
            .iter()
            .map(|c| ring(&c.polygon))
            .chain(handles.regions.iter().map(|r| ring(&r.polygon)))
            .collect(),
        domain_extensions: handles.cages.iter().map(|c| ring(&c.polygon)).collect(),
    }
}

/// Premultiplied RGB in [0, 1] of the pixel under each vertex (nearest pixel, clamped to the
/// image), for content-aware weights.
pub fn vertex_colors(image: &RgbaImage, vertices: &[Point]) -> Vec<[f64; 3]> {
    let (w, h) = (image.width() as i64, image.height() as i64);
    vertices
        .iter()
        .map(|p| {
            let x = (p.x.floor() as i64).clamp(0, w - 1) as u32;
            let y = (p.y.floor() as i64).clamp(0, h - 1) as u32;
            let px = image.get_pixel(x, y);
            let a = px[3] as f64 / 255.0;
            [0, 1, 2].map(|c| a * px[c] as f64 / 255.0)
        })
        .collect()
}

/// `target` as a path relative to `dir` (with `/` separators) when both resolve; otherwise
/// `target` made absolute.
pub fn relative_path(dir: &Path, target: &Path) -> String {
    let absolute = |p: &Path| std::fs::canonicalize(p).ok();
    let (Some(dir), Some(target)) = (absolute(dir), absolute(target)) else {
        return target.to_string_lossy().into_owned();
    };
    let common = dir
        .components()
        .zip(target.components())
        .take_while(|(a, b)| a == b)
        .count();
    let ups = dir.components().count() - common;
    let parts: Vec<String> = std::iter::repeat_n("..".to_string(), ups)
        .chain(
            target
                .components()
                .skip(common)
                .map(|c| c.as_os_str().to_string_lossy().into_owned()),
        )
        .collect();
    parts.join("/")
}

/// Transparent pixels around each texture beyond the trace padding, so bilinear sampling at
/// the mesh's outermost points reads transparency.
const TEXTURE_BORDER_MARGIN_PX: u32 = 2;

/// The transparent frame each part's texture gets: the trace padding plus a margin.
fn texture_border_px(doc: &RigDocument) -> u32 {
    let padding = doc.options.trace.padding_px;
    let padding = if padding.is_finite() {
        padding.clamp(0.0, crate::trace::MAX_PADDING_PX)
    } else {
        0.0
    };
    padding.ceil() as u32 + TEXTURE_BORDER_MARGIN_PX
}

/// Every part's image of the document saved at `path` (image paths are relative to its folder),
/// in part order.
pub fn load_part_images(path: &Path, doc: &RigDocument) -> Result<Vec<RgbaImage>, PipelineError> {
    doc.parts
        .iter()
        .map(|part| Ok(io::load_png(&RigDocument::image_path(path, part))?))
        .collect()
}

/// A document with its textures and per-part render state, ready to draw.
pub struct Scene {
    pub doc: RigDocument,
    /// Shared by the scenes that differ only in weights ([`Scene::with_part_weights`]).
    parts: std::sync::Arc<Vec<RenderPart>>,
    /// The skinning-IK precomputation, made the first time a pose has drags.
    ik: std::sync::OnceLock<Result<RigIk, crate::ik::IkError>>,
    /// The skins drawn, combined in order (see [`crate::io::slots`]); none: each slot's own part.
    skins: Vec<String>,
}

impl Scene {
    /// Loads the document at `path` and every part's image.
    pub fn load(path: &Path) -> Result<Self, PipelineError> {
        let doc = RigDocument::load(path)?;
        let images = load_part_images(path, &doc)?;
        Scene::new(doc, &images)
    }

    /// A scene from a document and its parts' images (in part order; owned or borrowed: they
    /// are only read).
    pub fn new<I: Borrow<RgbaImage>>(
        doc: RigDocument,
        images: &[I],
    ) -> Result<Self, PipelineError> {
        let mut parts = Vec::with_capacity(images.len());
        for (part, image) in doc.parts.iter().zip(images) {
            let image: &RgbaImage = image.borrow();
            let got = [image.width(), image.height()];
            if got != doc.canvas {
                return Err(PipelineError::TextureSize {
                    part: part.name.clone(),
                    got,
                    canvas: doc.canvas,
                });
            }
            // Meshes reach past the canvas by up to the trace padding; a transparent frame
            // around the texture keeps the sampler from smearing edge pixels out there.
            let border = texture_border_px(&doc);
            let offset = crate::geom::Vec2::new(border as f64, border as f64);
            let mesh = part.mesh.to_mesh();
            let uv_px: Vec<Point> = mesh.vertices.iter().map(|p| p + offset).collect();
            let mut framed =
                RgbaImage::new(image.width() + 2 * border, image.height() + 2 * border);
            image::imageops::replace(&mut framed, image, i64::from(border), i64::from(border));
            let render_error = |source| PipelineError::Render {
                part: part.name.clone(),
                source,
            };
            parts.push(RenderPart {
                mesh: MeshRenderer::new(&uv_px, &mesh.triangles).map_err(render_error)?,
                texture: Texture::from_rgba(&framed).map_err(render_error)?,
            });
        }
        Ok(Scene {
            doc,
            parts: std::sync::Arc::new(parts),
            ik: std::sync::OnceLock::new(),
            skins: Vec::new(),
        })
    }

    /// This scene with part `part`'s weights replaced (meshes, handles and textures kept and
    /// shared, so painting weights does not copy pixels); the skinning-IK precomputation
    /// starts afresh. The weights must fit the part's mesh and the handles.
    pub fn with_part_weights(
        &self,
        part: usize,
        weights: WeightsDoc,
    ) -> Result<Scene, PipelineError> {
        let mut doc = self.doc.clone();
        doc.parts
            .get_mut(part)
            .ok_or(PipelineError::UnknownPart(part))?
            .weights = Some(weights);
        doc.validate().map_err(|reason| {
            PipelineError::Document(io::DocumentError::Invalid {
                path: PathBuf::from(&doc.parts[part].name),
                reason,
            })
        })?;
        Ok(Scene {
            doc,
            parts: self.parts.clone(),
            ik: std::sync::OnceLock::new(),
            skins: self.skins.clone(),
        })
    }

    /// This scene with the weight columns named in `renamed` (old name → new name) renamed in
    /// every part, textures shared: after a handle is renamed, the weights computed before
    /// still name its column, so a recompute can keep them if it is locked. Only the weights'
    /// column names change (not `doc.handles`): such a scene is stale until recomputed.
    pub fn with_columns_renamed(
        &self,
        renamed: &std::collections::HashMap<String, String>,
    ) -> Scene {
        let mut doc = self.doc.clone();
        for weights in doc.parts.iter_mut().filter_map(|p| p.weights.as_mut()) {
            for name in &mut weights.handles {
                if let Some(to) = renamed.get(name) {
                    name.clone_from(to);
                }
            }
        }
        Scene {
            doc,
            parts: self.parts.clone(),
            ik: std::sync::OnceLock::new(),
            skins: self.skins.clone(),
        }
    }

    /// This scene without its physics constraints, textures shared: what the Spine export bakes
    /// from (the runtime simulates physics itself).
    pub fn without_physics(&self) -> Scene {
        let mut doc = self.doc.clone();
        doc.handles.physics.clear();
        Scene {
            doc,
            parts: self.parts.clone(),
            ik: std::sync::OnceLock::new(),
            skins: self.skins.clone(),
        }
    }

    /// Draws `skins` from now on, combined in order (a later skin overrides an earlier one on
    /// the same slot); empty: every slot shows its own part. Fails on a skin the rig lacks.
    pub fn set_skins(&mut self, skins: &[String]) -> Result<(), io::SlotError> {
        self.doc.check_skins(skins)?;
        self.skins = skins.to_vec();
        Ok(())
    }

    /// The skins drawn (see [`Scene::set_skins`]).
    pub fn skins(&self) -> &[String] {
        &self.skins
    }

    /// Every part's rest vertex positions.
    pub fn rest_positions(&self) -> Vec<Vec<Point>> {
        self.doc
            .parts
            .iter()
            .map(|p| p.mesh.to_mesh().vertices)
            .collect()
    }

    /// One transformation per handle column (in [`handle_columns`] order) for `pose`: the one
    /// path from a pose to what skinning blends, used for drawing and for the Spine export's
    /// baking alike: forward kinematics (bone IK constraints included), then the skinning IK
    /// when the pose has drags, solved from the forward-kinematics pose (no warm start).
    pub fn handle_transforms(&self, pose: &Pose) -> Result<Vec<Affine>, PipelineError> {
        self.handle_transforms_with(&mut None, pose)
    }

    /// [`Scene::handle_transforms`] with a solver kept in `ik` (made on first need) for its
    /// factorization only: [`RigIk::solve_pose`] starts every solve from the forward-kinematics
    /// pose, so the answer is the same as with a fresh solver.
    pub fn handle_transforms_with(
        &self,
        ik: &mut Option<RigIk>,
        pose: &Pose,
    ) -> Result<Vec<Affine>, PipelineError> {
        if pose.ik.is_empty() {
            return Ok(handle_transforms(&self.doc.handles, pose)?);
        }
        let solver = match ik {
            Some(solver) => solver,
            None => ik.insert(self.rig_ik()?),
        };
        Ok(solver.solve_pose(pose)?.transforms)
    }

    /// Every part's vertex positions in `pose` (forward kinematics, then linear blend
    /// skinning; skinning IK first when the pose has drags). Parts without weights stay at rest.
    pub fn pose_positions(&self, pose: &Pose) -> Result<Vec<Vec<Point>>, PipelineError> {
        self.pose_positions_with(pose, Blend::Linear)
    }

    /// [`Scene::pose_positions`] with a choice of blending. A pose with IK drags is solved from
    /// its forward-kinematics pose (no warm start), so the result depends on this pose only.
    pub fn pose_positions_with(
        &self,
        pose: &Pose,
        blend: Blend,
    ) -> Result<Vec<Vec<Point>>, PipelineError> {
        let transforms = self.handle_transforms(pose)?;
        self.positions_from_transforms(&transforms, pose, blend)
    }

    /// The rig's meshes as the skinning IK sees them: slots' own parts with weights, back to
    /// front, their weights mapped onto the rig's handle columns.
    pub fn skinned_meshes(&self) -> Result<Vec<SkinnedMesh>, PipelineError> {
        let columns = handle_columns(&self.doc.handles);
        let mut meshes = Vec::new();
        // A slot's other attachments are not solved: the solve is the same whichever skin or
        // attachment is drawn (they follow the handles as skinned).
        for part in self.doc.parts.iter().filter(|p| p.slot.is_none()) {
            let Some(weights) = &part.weights else {
                continue;
            };
            let map = self.column_map(&part.name, &weights.handles, &columns)?;
            let mesh = part.mesh.to_mesh();
            meshes.push(SkinnedMesh {
                rest: mesh.vertices,
                triangles: mesh.triangles,
                weights: weights
                    .rows
                    .iter()
                    .map(|row| {
                        row.iter()
                            .map(|&(k, w)| (map[k as usize] as u32, w))
                            .collect()
                    })
                    .collect(),
            });
        }
        Ok(meshes)
    }

    /// A skinning-IK solver for this rig with no warm start (the precomputation is shared).
    pub fn rig_ik(&self) -> Result<RigIk, PipelineError> {
        let cached = self.ik.get_or_init(|| {
            let meshes = self
                .skinned_meshes()
                .map_err(|_| crate::ik::IkError::NoWeights)?;
            if meshes.is_empty() {
                return Err(crate::ik::IkError::NoWeights);
            }
            RigIk::precompute(&self.doc.handles, meshes, self.doc.options.ik.clone())
        });
        match cached {
            Ok(ik) => {
                let mut fresh = ik.clone();
                fresh.solver.reset();
                Ok(fresh)
            }
            Err(e) => Err(PipelineError::Ik(e.clone())),
        }
    }

    /// For each of a part's weight columns (by name), its index among the rig's columns.
    fn column_map(
        &self,
        part: &str,
        names: &[String],
        columns: &[String],
    ) -> Result<Vec<usize>, PipelineError> {
        names
            .iter()
            .map(|name| {
                columns.iter().position(|c| c == name).ok_or_else(|| {
                    PipelineError::UnknownWeightHandle {
                        part: part.to_string(),
                        handle: name.clone(),
                    }
                })
            })
            .collect()
    }

    /// Every part's vertex positions under per-column skinning `transforms` (from
    /// [`handle_transforms`] or the skinning IK). With [`Blend::Stretch`], a bone the pose
    /// scales along its length stretches from its transform in `transforms`, solved or not.
    pub fn positions_from_transforms(
        &self,
        transforms: &[Affine],
        pose: &Pose,
        blend: Blend,
    ) -> Result<Vec<Vec<Point>>, PipelineError> {
        // Bones come first among the columns, so bone i's stretch is column i's.
        let stretches = match blend {
            Blend::Stretch => bone_stretches_under(&self.doc.handles, pose, transforms)?,
            Blend::Linear | Blend::Dqs => Vec::new(),
        };
        let columns = handle_columns(&self.doc.handles);
        if let Some(part) = pose
            .deform
            .keys()
            .find(|name| !self.doc.parts.iter().any(|p| &p.name == *name))
        {
            return Err(PipelineError::DeformUnknownPart(part.clone()));
        }
        let mut out = self.rest_positions();
        for (part, positions) in self.doc.parts.iter().zip(out.iter_mut()) {
            let Some(weights) = &part.weights else {
                continue;
            };
            // The document names its columns; map them onto this rig's transform order.
            let map = self.column_map(&part.name, &weights.handles, &columns)?;
            let part_transforms: Vec<Affine> = map.iter().map(|&j| transforms[j]).collect();
            let part_stretches: Vec<_> = map
                .iter()
                .map(|&j| stretches.get(j).copied().flatten())
                .collect();
            let mut rest = positions.clone();
            if let Some(offsets) = pose.deform.get(&part.name) {
                if offsets.len() != rest.len() {
                    return Err(PipelineError::DeformSize {
                        part: part.name.clone(),
                        got: offsets.len(),
                        expected: rest.len(),
                    });
                }
                // Deform offsets move the rest mesh before skinning (crate::anim::deform).
                for (p, o) in rest.iter_mut().zip(offsets) {
                    *p += Vec2::new(o[0], o[1]);
                }
                *positions = rest.clone();
            }
            let skin_weights = SkinWeights::from_rows(&weights.rows);
            match blend {
                Blend::Stretch => stretchable_blend(
                    &rest,
                    &skin_weights,
                    &part_transforms,
                    &part_stretches,
                    positions,
                ),
                Blend::Linear | Blend::Dqs => {
                    skin(&rest, &skin_weights, &part_transforms, blend, positions)
                }
            }
        }
        Ok(out)
    }

    /// Draws every slot's part (as the skins choose it) at `positions` (one list per part,
    /// canvas px) onto a transparent canvas of the rig's size.
    pub fn render(&self, positions: &[Vec<Point>]) -> Result<tiny_skia::Pixmap, PipelineError> {
        let [w, h] = self.doc.canvas;
        let mut canvas =
            tiny_skia::Pixmap::new(w, h).ok_or(PipelineError::Canvas(self.doc.canvas))?;
        self.draw(&mut canvas, positions, tiny_skia::Transform::identity())?;
        Ok(canvas)
    }

    /// Draws every slot's part (as the skins choose it) at `positions` onto `canvas` through
    /// `canvas_from_world`.
    pub fn draw(
        &self,
        canvas: &mut tiny_skia::Pixmap,
        positions: &[Vec<Point>],
        canvas_from_world: tiny_skia::Transform,
    ) -> Result<(), PipelineError> {
        let mut draws = Vec::with_capacity(self.doc.parts.len());
        // Each slot's part as the skins choose it, in the document's order.
        let shown = self
            .doc
            .slot_names()
            .into_iter()
            .filter_map(|slot| self.doc.shown_part(slot, None, &self.skins));
        for i in shown {
            let part = &self.doc.parts[i];
            let expected = part.mesh.vertices.len();
            let part_positions = positions.get(i).map(Vec::as_slice).unwrap_or_default();
            if part_positions.len() != expected {
                return Err(PipelineError::PositionCount {
                    part: part.name.clone(),
                    got: part_positions.len(),
                    expected,
                });
            }
            draws.push(PartDraw::new(i, part_positions));
        }
        self.draw_parts(canvas, &draws, canvas_from_world)
    }

    /// Draws `draws` in the listed order (first = furthest back) onto `canvas` through
    /// `canvas_from_world`; each names a part by its index in the document and brings its
    /// positions (world px), tint and visibility. Draws nothing if a visible draw names no part
    /// or brings the wrong number of positions.
    pub fn draw_parts(
        &self,
        canvas: &mut tiny_skia::Pixmap,
        draws: &[PartDraw],
        canvas_from_world: tiny_skia::Transform,
    ) -> Result<(), PipelineError> {
        render::draw_parts(canvas, &self.parts, draws, canvas_from_world).map_err(|source| {
            let index = match source {
                RenderError::UnknownPart { part, .. } | RenderError::PositionCount { part, .. } => {
                    part
                }
                _ => usize::MAX,
            };
            let part = self
                .doc
                .parts
                .get(index)
                .map_or_else(|| format!("#{index}"), |p| p.name.clone());
            PipelineError::Render { part, source }
        })
    }
}

/// For each weight column named in `columns`, whether its handle is in `locked` (a cage's
/// columns `CAGE.k` follow the cage). Columns no handle has are not locked.
pub fn locked_columns(
    handles: &Handles,
    locked: &BTreeSet<String>,
    columns: &[String],
) -> Vec<bool> {
    let owners = column_owners(handles);
    columns
        .iter()
        .map(|c| {
            owners
                .iter()
                .find(|(column, _)| column == c)
                .is_some_and(|(_, owner)| locked.contains(owner))
        })
        .collect()
}

/// Every weight column of `handles` (in [`handle_columns`] order) with the handle it belongs to.
fn column_owners(handles: &Handles) -> Vec<(String, String)> {
    let owners = handles
        .bones
        .iter()
        .map(|b| &b.name)
        .chain(handles.points.iter().map(|p| &p.name))
        .chain(
            handles
                .cages
                .iter()
                .flat_map(|c| std::iter::repeat_n(&c.name, c.polygon.len())),
        )
        .chain(handles.regions.iter().map(|r| &r.name));
    handle_columns(handles)
        .into_iter()
        .zip(owners.cloned())
        .collect()
}

/// Gives the freshly built `fresh` the weights of the `locked` handles that `previous` had,
/// part by part (matched by name): per vertex, locked columns keep their previous values and
/// the fresh unlocked columns are rescaled to fill the rest (see [`weights::keep_locked`]).
/// A part whose mesh changed (a re-trace) gets the previous rows carried over by locating its
/// vertices in the previous mesh ([`weights::transfer_rows`]). A locked handle the previous
/// part had no weights for, or that may no longer weigh the part (`bind`), is recomputed.
/// Rows keep the document's influence limit (`max_influences`) as far as the locked weights
/// allow.
pub fn keep_locked_weights(
    fresh: &mut RigDocument,
    previous: &RigDocument,
    locked: &BTreeSet<String>,
) -> Result<(), PipelineError> {
    if locked.is_empty() {
        return Ok(());
    }
    let owners = column_owners(&fresh.handles);
    for part in &mut fresh.parts {
        let Some(weights) = part.weights.as_mut() else {
            continue;
        };
        let Some((old, old_weights)) = previous
            .parts
            .iter()
            .find(|p| p.name == part.name)
            .and_then(|p| Some((p, p.weights.as_ref()?)))
        else {
            continue;
        };
        // The previous columns' places among the fresh ones.
        let place: Vec<Option<u32>> = old_weights
            .handles
            .iter()
            .map(|h| {
                weights
                    .handles
                    .iter()
                    .position(|c| c == h)
                    .map(|i| i as u32)
            })
            .collect();
        let mask: Vec<bool> = weights
            .handles
            .iter()
            .map(|c| {
                owners
                    .iter()
                    .find(|(column, _)| column == c)
                    .is_some_and(|(_, owner)| {
                        locked.contains(owner) && fresh.handles.binds(owner, &part.name)
                    })
                    && old_weights.handles.contains(c)
            })
            .collect();
        if !mask.iter().any(|&m| m) {
            continue;
        }
        let mapped: Vec<Vec<(u32, f64)>> = old_weights
            .rows
            .iter()
            .map(|row| {
                let mut r: Vec<(u32, f64)> = row
                    .iter()
                    .filter_map(|&(c, w)| Some((place.get(c as usize).copied().flatten()?, w)))
                    .collect();
                r.sort_by_key(|e| e.0);
                r
            })
            .collect();
        let error = |source| PipelineError::Locked {
            part: part.name.clone(),
            source,
        };
        let before = if old.mesh == part.mesh {
            mapped
        } else {
            weights::transfer_rows(
                &old.mesh.vertices,
                &old.mesh.triangles,
                &mapped,
                &part.mesh.vertices,
            )
            .map_err(error)?
        };
        weights::keep_locked(
            &mut weights.rows,
            &before,
            &mask,
            fresh.options.weights.max_influences,
        )
        .map_err(error)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths() {
        let dir = std::env::temp_dir().join(format!("sinew-rel-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("a/b")).unwrap();
        std::fs::create_dir_all(dir.join("c")).unwrap();
        std::fs::write(dir.join("c/x.png"), b"").unwrap();
        assert_eq!(
            relative_path(&dir.join("a/b"), &dir.join("c/x.png")),
            "../../c/x.png"
        );
        assert_eq!(relative_path(&dir.join("c"), &dir.join("c/x.png")), "x.png");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
