//! [`Scene`]: a rig document with its parts' textures, render state and precomputed solvers:
//! the object every consumer poses and draws through (see the module above).
//!
//! In: a [`RigDocument`] and one RGBA texture per part (canvas-sized). Out: per-column handle
//! transforms for a [`Pose`], posed vertex positions (canvas px, one list per part), and frames
//! drawn with tiny-skia.

use crate::geom::Point;
use crate::ik::{RigIk, SkinnedMesh};
use crate::io::{self, RigDocument, WeightsDoc};
use crate::pipeline::PipelineError;
use crate::render::{self, MeshRenderer, PartDraw, RenderError, RenderPart, Texture};
use crate::rig::pose::{bone_stretches_under, Affine};
use crate::rig::{handle_columns, handle_transforms, Pose};
use crate::skin::{skin, stretchable_blend, Blend, LbsPlan, PlanError, SkinWeights};
use image::RgbaImage;
use std::borrow::Borrow;
use std::path::{Path, PathBuf};

/// Transparent pixels around each texture beyond the trace padding, so bilinear sampling at
/// the mesh's outermost points reads transparency.
const TEXTURE_BORDER_MARGIN_PX: u32 = 2;

/// The transparent frame each part's texture gets: the trace padding plus a margin.
pub(crate) fn texture_border_px(doc: &RigDocument) -> u32 {
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

/// Each part's skinning plan, or the first part whose weights could not be planned.
type PartPlans = Result<Vec<Option<LbsPlan>>, (String, PlanError)>;

/// A skinning failure of `part`.
fn skin_error(part: &io::PartDoc, source: PlanError) -> PipelineError {
    PipelineError::Skin {
        part: part.name.clone(),
        source,
    }
}

/// A document with its textures and per-part render state, ready to draw.
pub struct Scene {
    pub doc: RigDocument,
    /// Shared by the scenes that differ only in weights ([`Scene::with_part_weights`]).
    parts: std::sync::Arc<Vec<RenderPart>>,
    /// The skinning-IK precomputation, made the first time a pose has drags.
    ik: std::sync::OnceLock<Result<RigIk, crate::ik::IkError>>,
    /// Each part's packed skinning plan (none for parts without weights), made on first pose;
    /// shared by the scenes that keep the weights.
    plans: std::sync::Arc<std::sync::OnceLock<PartPlans>>,
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
        let border = texture_border_px(&doc);
        for (part, image) in doc.parts.iter().zip(images) {
            let image: &RgbaImage = image.borrow();
            let got = [image.width(), image.height()];
            if !part.image_holds_mesh(got, f64::from(border)) {
                return Err(PipelineError::TextureSize {
                    part: part.name.clone(),
                    got,
                    offset_px: part.offset_px,
                });
            }
            // Meshes reach past the opaque pixels by up to the trace padding; a transparent
            // frame around the texture keeps the sampler from smearing edge pixels out there.
            // Texture px = canvas px − the image's offset + the frame.
            let [ox, oy] = part.offset_px.map(f64::from);
            let canvas_to_uv = crate::geom::Vec2::new(border as f64 - ox, border as f64 - oy);
            let mesh = part.mesh.to_mesh();
            let uv_px: Vec<Point> = mesh.vertices.iter().map(|p| p + canvas_to_uv).collect();
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
            plans: Default::default(),
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
            plans: Default::default(),
            skins: self.skins.clone(),
        })
    }

    /// This scene with every vertex keeping its `max_influences` strongest weights,
    /// renormalized ([`crate::skin::strongest_influences`]): what a runtime that skins with
    /// that many influences draws (glTF's four). Handles, meshes and textures are kept and
    /// shared; the skinning plans are made afresh.
    pub fn with_influences_limited(&self, max_influences: usize) -> Scene {
        let mut doc = self.doc.clone();
        for weights in doc.parts.iter_mut().filter_map(|p| p.weights.as_mut()) {
            for row in &mut weights.rows {
                *row = crate::skin::strongest_influences(row, Some(max_influences));
            }
        }
        Scene {
            doc,
            parts: self.parts.clone(),
            ik: std::sync::OnceLock::new(),
            plans: Default::default(),
            skins: self.skins.clone(),
        }
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
            plans: Default::default(),
            skins: self.skins.clone(),
        }
    }

    /// This scene without its physics constraints, textures shared: what the Spine export bakes
    /// from (the runtime simulates physics itself).
    pub fn without_physics(&self) -> Scene {
        self.with_physics(Vec::new())
    }

    /// This scene with `physics` as its physics constraints (checked by the caller), textures,
    /// weights and skinning plans shared: the constraints move no weights.
    pub fn with_physics(&self, physics: Vec<crate::rig::PhysicsConstraint>) -> Scene {
        let mut doc = self.doc.clone();
        doc.handles.physics = physics;
        Scene {
            doc,
            parts: self.parts.clone(),
            ik: std::sync::OnceLock::new(),
            plans: self.plans.clone(),
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

    /// This scene drawing `skins` (see [`Scene::set_skins`]), everything else shared or kept.
    pub fn with_skins(&self, skins: &[String]) -> Result<Scene, io::SlotError> {
        self.doc.check_skins(skins)?;
        let ik = std::sync::OnceLock::new();
        if let Some(Ok(solver)) = self.ik.get() {
            // The same meshes and handles: the solver's precomputation carries over.
            let _ = ik.set(Ok(solver.clone()));
        }
        Ok(Scene {
            doc: self.doc.clone(),
            parts: self.parts.clone(),
            ik,
            plans: self.plans.clone(),
            skins: skins.to_vec(),
        })
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
            .map(|p| p.mesh.vertices.clone())
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
    /// [`handle_transforms`] or the skinning IK). [`Blend::Linear`] skins with each part's
    /// packed f32 plan ([`LbsPlan`], every influence kept; made once per scene): the f32
    /// displacement is added to the f64 rest point, so the rest pose is exact and posed
    /// positions carry f32 rounding (about 1e-4 px on a 1000 px canvas) like the runtimes'. With
    /// [`Blend::Stretch`], a bone the pose scales along its length stretches from its transform
    /// in `transforms`, solved or not (f64, as is [`Blend::Dqs`]).
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
        let plans = self.plans()?;
        let mut out = self.rest_positions();
        for (index, (part, positions)) in self.doc.parts.iter().zip(out.iter_mut()).enumerate() {
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
            // The rest mesh skinned: the document's own vertices, read in place (no copy per
            // frame), or, under deform offsets, this pose's moved copy.
            let deformed_rest: Vec<Point>;
            let rest: &[Point] = match pose.deform.get(&part.name) {
                Some(offsets) => {
                    if offsets.len() != positions.len() {
                        return Err(PipelineError::DeformSize {
                            part: part.name.clone(),
                            got: offsets.len(),
                            expected: positions.len(),
                        });
                    }
                    // Deform offsets move the rest mesh before skinning (crate::anim::deform).
                    for (p, o) in positions.iter_mut().zip(offsets) {
                        *p += *o;
                    }
                    deformed_rest = positions.clone();
                    &deformed_rest
                }
                None => &part.mesh.vertices,
            };
            match blend {
                Blend::Linear => {
                    let deformed;
                    let plan = if pose.deform.contains_key(&part.name) {
                        // The deformed rest is this pose's alone: plan it for this call.
                        let skin_weights = SkinWeights::from_rows(&weights.rows);
                        deformed = LbsPlan::precompute_exact(rest, &skin_weights)
                            .map_err(|source| skin_error(part, source))?;
                        &deformed
                    } else {
                        match plans.get(index).and_then(Option::as_ref) {
                            Some(plan) => plan,
                            None => continue,
                        }
                    };
                    let mut posed = vec![[0.0f32; 2]; rest.len()];
                    plan.solve(&part_transforms, &mut posed)
                        .map_err(|source| skin_error(part, source))?;
                    // The f32 displacement on the f64 rest point: identity transforms give
                    // back the rest positions exactly (the plan returns its f32 rest bit for
                    // bit, so the displacement is exactly zero).
                    for ((p, r), q) in positions.iter_mut().zip(rest).zip(&posed) {
                        let moved = |rest: f64, posed: f32| {
                            rest + (f64::from(posed) - f64::from(rest as f32))
                        };
                        *p = Point::new(moved(r.x, q[0]), moved(r.y, q[1]));
                    }
                }
                Blend::Stretch => stretchable_blend(
                    rest,
                    &SkinWeights::from_rows(&weights.rows),
                    &part_transforms,
                    &part_stretches,
                    positions,
                ),
                Blend::Dqs => skin(
                    rest,
                    &SkinWeights::from_rows(&weights.rows),
                    &part_transforms,
                    blend,
                    positions,
                ),
            }
        }
        Ok(out)
    }

    /// Every part's packed skinning plan, made once per set of weights.
    fn plans(&self) -> Result<&[Option<LbsPlan>], PipelineError> {
        let made = self.plans.get_or_init(|| {
            self.doc
                .parts
                .iter()
                .map(|part| {
                    let Some(weights) = &part.weights else {
                        return Ok(None);
                    };
                    let rest = part.mesh.to_mesh().vertices;
                    LbsPlan::precompute_exact(&rest, &SkinWeights::from_rows(&weights.rows))
                        .map(Some)
                        .map_err(|source| (part.name.clone(), source))
                })
                .collect()
        });
        match made {
            Ok(plans) => Ok(plans),
            Err((part, source)) => Err(PipelineError::Skin {
                part: part.clone(),
                source: source.clone(),
            }),
        }
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
