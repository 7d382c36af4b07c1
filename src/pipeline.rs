//! The stages wired together, for the command line and the editor alike.
//!
//! - [`load_layers`]: image files → [`Layer`]s on one canvas (same size, unique names).
//! - [`build_rig`]: layers + [`BuildOptions`] + [`Handles`] → a [`RigDocument`] (trace, mesh
//!   with the handles' geometry embedded, weights, per part).
//! - [`Scene`] (defined in [`crate::scene`], re-exported here): a loaded document with its
//!   textures: poses it (forward kinematics + skinning)
//!   and draws any vertex positions.
//! - [`keep_locked_weights`]: a rebuilt document keeps the locked handles' previous weights.

use crate::geom::Point;
use crate::io::{self, BuildOptions, ImageError, MeshDoc, PartDoc, RigDocument, WeightsDoc};
use crate::mesh::{self, HandleGeometry, MeshError, MeshStats};
use crate::render::RenderError;
use crate::rig::{handle_columns, HandleError, Handles, PoseError};
use crate::trace::{self, TraceError};
use crate::weights::{self, WeightError};
use image::RgbaImage;
use std::borrow::Borrow;
use std::collections::{BTreeSet, HashSet};
use std::path::{Path, PathBuf};

pub use crate::scene::{load_part_images, Scene};

/// One input image: a part of the rig, placed on the rig's canvas.
#[derive(Clone, Debug)]
pub struct Layer {
    /// The part's name: the file name without extension.
    pub name: String,
    pub path: PathBuf,
    /// Straight-alpha RGBA8: a whole canvas for a PNG layer, or trimmed to the layer's opaque
    /// pixels for a layer of a layered file.
    pub image: RgbaImage,
    /// Canvas position of the image's top-left pixel, px (y down).
    pub offset_px: [i32; 2],
    /// The size of the canvas the layer lies on, px.
    pub canvas_px: [u32; 2],
}

impl Layer {
    /// A layer whose image is the whole canvas (a PNG layer).
    pub fn whole(name: impl Into<String>, path: impl Into<PathBuf>, image: RgbaImage) -> Self {
        let canvas_px = [image.width(), image.height()];
        Layer {
            name: name.into(),
            path: path.into(),
            image,
            offset_px: [0, 0],
            canvas_px,
        }
    }
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
    #[error(
        "{}: no layer to rig: {hidden} hidden, {outside} outside the canvas or fully \
         transparent (show a layer, or move it onto the canvas)", .path.display()
    )]
    NoVisibleLayers {
        path: PathBuf,
        hidden: usize,
        outside: usize,
    },
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
    #[error("momentum is simulated from the animation's start: time {} s lies outside [0, {max}] s", crate::shown::Shown(*.0), max = crate::scene::MAX_SIMULATED_S)]
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
    #[error("part '{part}': skinning: {source}")]
    Skin {
        part: String,
        source: crate::skin::PlanError,
    },
    #[error("part '{part}': its mesh reaches past its {}×{} px image placed at {offset_px:?} (was the image replaced by one of another size?)", got[0], got[1])]
    TextureSize {
        part: String,
        got: [u32; 2],
        offset_px: [i32; 2],
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
        layers.push(Layer::whole(name, path.clone(), image));
    }
    checked_layers(layers)
}

/// `layers` when they can be the parts of one rig: at least one, on canvases of the first
/// one's size, each canvas at least [`MIN_SPRITE_SIDE_PX`] on a side, names unique.
pub fn checked_layers(layers: Vec<Layer>) -> Result<Vec<Layer>, PipelineError> {
    let mut names = HashSet::new();
    let canvas = match layers.first() {
        Some(first) => first.canvas_px,
        None => return Err(PipelineError::NoImages),
    };
    for layer in &layers {
        let path = &layer.path;
        let got = layer.canvas_px;
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
    build_rig_with_progress(layers, doc_dir, options, handles, &mut |_, _, _| {})
}

/// [`build_rig`], calling `progress(parts_done, parts_in_all, part_name)` before each part and
/// once at the end (with an empty name), for progress bars.
pub fn build_rig_with_progress<L: Borrow<Layer>>(
    layers: &[L],
    doc_dir: &Path,
    options: &BuildOptions,
    handles: &Handles,
    progress: &mut dyn FnMut(usize, usize, &str),
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
    progress: &mut dyn FnMut(usize, usize, &str),
    cancel: &std::sync::atomic::AtomicBool,
) -> Result<(RigDocument, Vec<PartReport>), PipelineError> {
    let first: &Layer = layers.first().ok_or(PipelineError::NoImages)?.borrow();
    let canvas = first.canvas_px;
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
        progress(done, layers.len(), &layer.name);
        let outlines = trace::trace(&layer.image, &options.trace)
            .map(|o| trace::translated(o, layer.offset_px))
            .map_err(|source| PipelineError::Trace {
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
                    .map(|_| vertex_colors(layer, &mesh.domain.vertices))
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
            offset_px: layer.offset_px,
            mesh: MeshDoc::from(&mesh),
            weights,
            stale_weights: None,
        });
    }
    progress(layers.len(), layers.len(), "");
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
    HandleGeometry {
        points: handles.points.iter().map(|p| p.at).collect(),
        segments: handles.bones.iter().map(|b| [b.head, b.tail]).collect(),
        polygons: handles
            .cages
            .iter()
            .map(|c| c.polygon.clone())
            .chain(handles.regions.iter().map(|r| r.polygon.clone()))
            .collect(),
        domain_extensions: handles.cages.iter().map(|c| c.polygon.clone()).collect(),
    }
}

/// Premultiplied RGB in [0, 1] of the layer's pixel under each vertex (canvas px; nearest
/// pixel, clamped to the canvas; black where the layer's image has no pixel), for
/// content-aware weights.
pub fn vertex_colors(layer: &Layer, vertices: &[Point]) -> Vec<[f64; 3]> {
    let [cw, ch] = layer.canvas_px.map(i64::from);
    let [ox, oy] = layer.offset_px.map(i64::from);
    vertices
        .iter()
        .map(|p| {
            // Clamped to the canvas, then read from the layer's image (transparent outside it).
            let x = (p.x.floor() as i64).clamp(0, cw - 1) - ox;
            let y = (p.y.floor() as i64).clamp(0, ch - 1) - oy;
            let inside = x >= 0
                && y >= 0
                && x < i64::from(layer.image.width())
                && y < i64::from(layer.image.height());
            if !inside {
                return [0.0; 3];
            }
            let px = layer.image.get_pixel(x as u32, y as u32);
            let a = px[3] as f64 / 255.0;
            [0, 1, 2].map(|c| a * px[c] as f64 / 255.0)
        })
        .collect()
}

/// `target` as a path relative to `dir` (with `/` separators) when both resolve; otherwise
/// `target` as given. Either may not exist yet (a part image written with the document):
/// its nearest existing folder is resolved and the rest appended
/// ([`crate::io::document::relative_to`]).
pub fn relative_path(dir: &Path, target: &Path) -> String {
    match crate::io::document::relative_to(dir, target) {
        Some(rel) => rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join("/"),
        None => target.to_string_lossy().into_owned(),
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
        let tmp = crate::test_scratch::scratch("rel");
        let dir = tmp.path();
        std::fs::create_dir_all(dir.join("a/b")).unwrap();
        std::fs::create_dir_all(dir.join("c")).unwrap();
        std::fs::write(dir.join("c/x.png"), b"").unwrap();
        assert_eq!(
            relative_path(&dir.join("a/b"), &dir.join("c/x.png")),
            "../../c/x.png"
        );
        assert_eq!(relative_path(&dir.join("c"), &dir.join("c/x.png")), "x.png");
        // A part image not written yet, under a folder not made yet (`sinew rig art.psd -o
        // out/rig.json` writes `out/rig.parts/…` with the document).
        assert_eq!(
            relative_path(&dir.join("c"), &dir.join("c/./rig.parts/arm/hand.png")),
            "rig.parts/arm/hand.png"
        );
        let cwd_relative = dir.strip_prefix(std::env::current_dir().unwrap());
        if let Ok(from_cwd) = cwd_relative {
            assert_eq!(
                relative_path(&from_cwd.join("c"), &from_cwd.join("c/rig.parts/x.png")),
                "rig.parts/x.png"
            );
        }
    }
}
