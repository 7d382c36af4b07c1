//! The editable document behind `sinew edit`, with its commands and undo history.
//!
//! In: a rig file (or nothing) and [`Command`]s. Out: the current [`State`] — the layers (the
//! parts' images), the handles, the build options, the animations, the rig built from them
//! (meshes and weights) when it has been built, and the pose being edited — saved atomically as
//! a rig document, with an autosave side file.
//!
//! Every edit is a [`Command`] given to [`Document::apply`], which checks it against the
//! current state first: a command that fails leaves the document exactly as it was. The state
//! before each successful command goes on the undo stack. States share their images and built
//! rig through `Arc`s, so an undo step costs the handles, options and pose, not the pixels.
//!
//! Editing the handles, the layers or the build options makes the built rig *stale*: it is kept
//! (its meshes are still shown) but cannot be posed until the weights are computed again. The
//! editor computes them off the UI thread with [`compute_rig`] and hands the result back as
//! [`Command::SetRig`], which is refused when the inputs changed in the meantime.
//!
//! Weights can be painted ([`Command::PaintWeights`], one stroke per command) and handles
//! locked ([`Command::SetLocked`]): painting leaves locked handles' weights alone, and
//! [`compute_rig`] keeps them from the previous rig while it recomputes the others.

use crate::anim::edit::{self, put_key, CopiedKey, KeyRef};
use crate::anim::{Animation, Curve, IkTimeline, Key};
use crate::geom::Point;
use crate::io::{self, BuildOptions, DocumentError as RigFileError, RigDocument};
use crate::pipeline::{self, Layer, PipelineError, Scene};
use crate::rig::{Bone, Cage, HandleError, Handles, PointHandle, Pose, Region};
use crate::weights::{BrushMode, BrushOptions, PaintMesh, PaintTarget};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

#[path = "document_animations.rs"]
pub mod animations;
pub use animations::{unused_animation_name, AnimationEdit};
#[path = "document_apply.rs"]
mod apply;
use apply::{apply_to, rig_inputs_of};
#[path = "document_events.rs"]
pub mod events;
pub use events::EventEdit;
#[path = "document_keys.rs"]
mod keys;
pub(crate) use keys::key_drag;
pub use keys::{animation_named, key_times};
use keys::{check_key_time, edit_animation, key_pose, keys_at, store_animation};
#[path = "document_paint.rs"]
mod paint;
use paint::paint_weights;
pub use paint::part_weights_for_painting;
#[path = "document_save.rs"]
mod save;
pub use save::{autosave_path, side_file, SaveJob};
use save::{rig_document, same_layers, swap_in};

/// Undo steps kept; older ones are forgotten.
pub const UNDO_LIMIT: usize = 200;

/// What a command or a file operation got wrong. The document is unchanged.
#[derive(Debug, thiserror::Error)]
pub enum DocumentError {
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
    #[error(transparent)]
    RigFile(#[from] RigFileError),
    #[error(transparent)]
    Handles(#[from] HandleError),
    #[error("there is no handle named '{0}'")]
    UnknownHandle(String),
    #[error("there is no layer named '{0}'")]
    UnknownLayer(String),
    #[error("'{parent}' cannot be the parent of '{bone}': it is '{bone}' or hangs below it")]
    ReparentCycle { bone: String, parent: String },
    #[error("a layer named '{0}' already exists")]
    DuplicateLayer(String),
    #[error("layer '{name}' is {got:?} px but the canvas is {canvas:?} px")]
    LayerSize {
        name: String,
        got: [u32; 2],
        canvas: [u32; 2],
    },
    #[error("the weights were computed for handles, layers or options that have changed since")]
    OutdatedRig,
    #[error("the rig has no weights for the current handles: compute them first")]
    NoWeights,
    #[error("the document has no layers to save")]
    NothingToSave,
    #[error("cannot write {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("slots and skins: {0}")]
    Slots(String),
    #[error("computing the weights was cancelled")]
    Cancelled,
    #[error(transparent)]
    Animation(#[from] crate::anim::AnimError),
    #[error("a key time must be a finite number of seconds ≥ 0, not {0}")]
    KeyTime(f64),
    #[error(
        "nothing to key at {0} s: the keys there already hold this pose (pose a bone or drag a \
         point first)"
    )]
    NothingToKey(f64),
    #[error("'{name}' has {expected} vertices, not {got}")]
    PolygonSize {
        name: String,
        got: usize,
        expected: usize,
    },
    #[error("handle '{0}' is locked: unlock it to paint its weights")]
    LockedHandle(String),
    #[error("painting weights: {0}")]
    Paint(#[from] crate::weights::PaintError),
    #[error("the stroke changed no weights{}", at_limit_note(*.at_limit, *.limit))]
    NothingPainted {
        at_limit: usize,
        limit: Option<usize>,
    },
    #[error(transparent)]
    KeyEdit(#[from] crate::anim::edit::EditError),
    #[error("there is no animation named '{0}'")]
    UnknownAnimation(String),
    #[error("an animation named '{0}' already exists")]
    AnimationExists(String),
    #[error("'{0}' cannot name an animation: give it a name without leading or trailing spaces")]
    AnimationName(String),
    #[error("there is no event named '{name}' (defined: {known})")]
    UnknownEvent { name: String, known: String },
    #[error("an event named '{0}' is already defined")]
    EventExists(String),
    #[error("animation '{animation}' has no such event at {time_s} s")]
    NoEventAt { animation: String, time_s: f64 },
    #[error(transparent)]
    EventDef(#[from] crate::anim::event::EventDefError),
}

/// Why a stroke may change nothing: the vertices the influence limit held back.
fn at_limit_note(at_limit: usize, limit: Option<usize>) -> String {
    match limit {
        Some(k) if at_limit > 0 => format!(
            " ({at_limit} vertex dabs were held back by the influence limit of {k}: paint \
             harder, or take a handle off those vertices first)"
        ),
        _ => String::new(),
    }
}

/// Everything an edit can change; one undo step restores one of these.
#[derive(Clone)]
pub struct State {
    /// The parts' images, back to front; all share the canvas size.
    pub layers: Vec<Arc<Layer>>,
    pub handles: Handles,
    pub options: BuildOptions,
    /// Animations by name, each checked on its own (names the rig lacks are checked where an
    /// animation is rendered or exported).
    pub animations: BTreeMap<String, Animation>,
    /// Event definitions the animations fire ([`Command::Events`] edits them).
    pub events: crate::anim::EventDefs,
    /// The rig last built from layers, handles and options (meshes, weights, textures).
    pub rig: Option<Arc<Scene>>,
    /// Whether `rig` was built from exactly the current layers, handles and options.
    pub rig_current: bool,
    /// The pose shown and edited in pose mode.
    pub pose: Pose,
    /// Handles whose weights painting and recomputing keep (see [`Command::SetLocked`]).
    pub locked: BTreeSet<String>,
    /// Which parts are other attachments of a slot, and the skins: kept as opened and given to
    /// every rig built (the editor does not edit them yet).
    pub slots: SlotLayout,
    /// What the last automatic rig installed followed ([`Command::Propose`]); saved with the
    /// document (`autorig`), so the editor offers the same template on reopen.
    pub autorig: Option<io::AutorigRecord>,
    /// The runtime the rig is made for, saved with the document (`target`); the editor plays
    /// and names it.
    pub target: Option<io::RuntimeTarget>,
}

/// A document's slots and skins (see [`crate::io::slots`]): each part that is another
/// attachment of a slot (part → slot) and the skins by name.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SlotLayout {
    pub attachments: BTreeMap<String, String>,
    pub skins: io::Skins,
    /// The skins the posed rig draws, combined in order (a view choice, not saved).
    pub shown: Vec<String>,
}

impl SlotLayout {
    /// The slots and skins of `doc`.
    pub fn of(doc: &RigDocument) -> Self {
        SlotLayout {
            attachments: doc
                .parts
                .iter()
                .filter_map(|p| Some((p.name.clone(), p.slot.clone()?)))
                .collect(),
            skins: doc.skins.clone(),
            shown: Vec::new(),
        }
    }

    /// Gives `doc` (a rig built from layers, whose parts are all slots) these slots and skins.
    pub fn apply_to(&self, doc: &mut RigDocument) -> Result<(), DocumentError> {
        doc.set_slots(&self.attachments, self.skins.clone())
            .map_err(DocumentError::Slots)
    }

    /// Forgets part `name`: as an attachment, and wherever a skin shows it.
    fn remove_part(&mut self, name: &str) {
        self.attachments.remove(name);
        // Attachments of a removed slot go with it.
        self.attachments.retain(|_, slot| slot != name);
        for skin in self.skins.values_mut() {
            skin.retain(|slot, part| slot != name && part != name);
        }
    }
}

/// The inputs a rig is built from, copied out for a background build.
#[derive(Clone)]
pub struct RigInputs {
    pub layers: Vec<Arc<Layer>>,
    pub handles: Handles,
    pub options: BuildOptions,
    /// Handles whose weights the build keeps from `previous`.
    pub locked: BTreeSet<String>,
    /// The rig built before (current or stale): where locked weights come from.
    pub previous: Option<Arc<Scene>>,
    /// The slots and skins the built rig gets.
    pub slots: SlotLayout,
}

/// One edit of the document.
#[derive(Clone)]
pub enum Command {
    /// Adds a layer in front of the others (its image must have the canvas size).
    AddLayer(Layer),
    RemoveLayer {
        name: String,
    },
    /// Adds a bone; a bone without a parent starts a new skeleton.
    AddBone(Bone),
    /// Moves a bone's head and tail (canvas px).
    MoveBone {
        name: String,
        head: Point,
        tail: Point,
    },
    AddPoint(PointHandle),
    MovePoint {
        name: String,
        at: Point,
    },
    /// Renames a handle everywhere it is referred to (parents, bindings, IK constraints, pose).
    Rename {
        from: String,
        to: String,
    },
    /// Gives a bone another parent (`None`: it becomes a skeleton's root), or a point handle
    /// another bone to carry it (`None`: it becomes loose).
    Reparent {
        handle: String,
        parent: Option<String>,
    },
    /// Deletes a handle; a deleted bone's children move up to its parent.
    Delete {
        name: String,
    },
    SetOptions(BuildOptions),
    /// Installs a rig built by [`compute_rig`] from the current inputs.
    SetRig(Arc<Scene>, Box<RigInputsKey>),
    SetPose(Pose),
    /// Draws the posed rig in these skins, combined in order (none: each slot's own part).
    ShowSkins(Vec<String>),
    /// *Set key*: keys `pose` into `animation` at `time_s` (creating the animation). Keyed are
    /// the bone and point channels (rotate, translate, scale, shear) where `pose` differs, by
    /// more than [`animations::KEY_CHANGE_TOLERANCE`], from what the animation shows there
    /// (sampled with `sampling`), every channel of each handle in `keep` (the selection, so a
    /// selected handle gets an explicit hold key; an unposed one its rest values), and every
    /// IK drag of `pose` (a key of the drag timeline with the same rest point). A key already at
    /// that time is replaced; nothing to key in an existing animation is refused.
    SetKey {
        animation: String,
        time_s: f64,
        pose: Pose,
        keep: Vec<String>,
        sampling: crate::anim::SampleOptions,
    },
    /// Keys which attachment slot `slot` shows from `time_s` on in `animation` (a stepped
    /// key of `parts.SLOT.attachment`; `None`: the slot shows nothing). A key already at that
    /// time is replaced; an attachment the slot does not have is refused.
    KeyAttachment {
        animation: String,
        slot: String,
        time_s: f64,
        attachment: Option<String>,
    },
    /// Keys the deform offsets of part `part` (one per vertex of its mesh, canvas px in the
    /// rest frame) at `time_s` in `animation`, as [`Command::SetKey`] keys a pose (a key inside
    /// a segment splits its curve). A part the rig lacks, or a wrong count, is refused.
    KeyDeform {
        animation: String,
        part: String,
        time_s: f64,
        offsets: Vec<crate::geom::Vec2>,
    },
    /// Removes every key of `animation` at `time_s`.
    DeleteKeys {
        animation: String,
        time_s: f64,
    },
    /// Replaces every handle; the pose forgets handles that are gone.
    SetHandles(Handles),
    /// Installs an automatic rig's proposal: replaces every handle, as [`Command::SetHandles`]
    /// does, and records what the proposal followed (its template) in the document, in one
    /// undo step.
    Propose {
        handles: Handles,
        record: io::AutorigRecord,
    },
    /// Sets the parts (layer names) handle `handle` may weigh ([`Handles::bind`]): none
    /// unbinds it, so it weighs every part again. A part that is not a layer, or a handle that
    /// does not exist, is refused. The weights need computing again.
    SetBind {
        handle: String,
        parts: Vec<String>,
    },
    /// Adds a cage: a closed polygon (canvas px) whose vertices are handles.
    AddCage(Cage),
    /// Adds a region: a closed polygon (canvas px) whose inside moves rigidly.
    AddRegion(Region),
    /// Moves a cage's or region's polygon (same vertex count, canvas px).
    SetPolygon {
        name: String,
        polygon: Vec<Point>,
    },
    /// Paints one brush stroke (press to release) on `handle`'s weights over `part` (see
    /// [`crate::weights::paint`]): one undo step. Needs current weights; locked handles keep
    /// theirs, and a locked `handle` is refused. Rows keep the document's influence limit
    /// (`max_influences`). A stroke that changes no weight is refused.
    PaintWeights {
        part: String,
        handle: String,
        mode: BrushMode,
        /// The pointer's path, canvas px.
        samples_px: Vec<Point>,
        options: BrushOptions,
    },
    /// Replaces the physics constraint of the same name (its parameters, see
    /// [`crate::rig::physics`]); checked as the handles file is (a NaN, a mass ≤ 0, … refused).
    /// The constraints move no weights: the built rig takes them and stays as current as it was.
    SetPhysics(crate::rig::PhysicsConstraint),
    /// Locks or unlocks a handle's weights. The built rig stays current.
    SetLocked {
        handle: String,
        locked: bool,
    },
    /// Moves keys of `animation` by `delta_s` seconds, all or none: a key would land on another
    /// key of its timeline or before 0 → refused (see [`crate::anim::edit`]).
    MoveKeys {
        animation: String,
        keys: Vec<KeyRef>,
        delta_s: f64,
    },
    /// Writes copied keys at `at_s` plus their offsets, replacing keys at the same times.
    PasteKeys {
        animation: String,
        at_s: f64,
        keys: Vec<CopiedKey>,
    },
    /// Removes the named keys (timeline by timeline, unlike [`Command::DeleteKeys`]).
    DeleteTimelineKeys {
        animation: String,
        keys: Vec<KeyRef>,
    },
    /// Sets the curve of a key's outgoing segment.
    SetCurve {
        animation: String,
        key: KeyRef,
        curve: Curve,
    },
    /// Sets the curves of several keys' outgoing segments: one undo step, all or none.
    SetCurves {
        animation: String,
        curves: Vec<(KeyRef, Curve)>,
    },
    /// Adds, renames, duplicates or deletes an animation, or stores a computed one under a name
    /// (*Apply motion…*'s retargeted capture, [`AnimationEdit::Put`]).
    Animations(AnimationEdit),
    /// Defines events, adds event keys, sets their payloads.
    Events(EventEdit),
    /// Auto-key: keys at `time_s` only the channels where `pose` differs from `before` (the
    /// animation's pose there), see [`animations::key_changes`]. Nothing changed → refused.
    KeyChanges {
        animation: String,
        time_s: f64,
        before: Pose,
        pose: Pose,
    },
}

/// Keys closer in time than this (s) are the same key.
pub const KEY_TIME_TOLERANCE_S: f64 = crate::anim::edit::KEY_TIME_TOLERANCE_S;

/// Identifies the inputs a rig was built from, to refuse a result that arrives after an edit.
#[derive(Clone, Debug, PartialEq)]
pub struct RigInputsKey {
    layer_names: Vec<String>,
    handles: Handles,
    options: BuildOptions,
    locked: BTreeSet<String>,
}

impl RigInputs {
    pub fn key(&self) -> RigInputsKey {
        RigInputsKey {
            layer_names: self.layers.iter().map(|l| l.name.clone()).collect(),
            handles: self.handles.clone(),
            options: self.options.clone(),
            locked: self.locked.clone(),
        }
    }
}

/// The document: the current state, where it is saved, and its undo history.
pub struct Document {
    state: State,
    /// Where the document is saved; image paths in the file are relative to its folder.
    pub path: Option<PathBuf>,
    /// Earlier states with their revisions (the last is the one before the current state).
    undo: Vec<(State, u64)>,
    redo: Vec<(State, u64)>,
    /// The revision of the current state: every command makes a new one; undo and redo bring
    /// back the revision of the state they restore.
    revision: u64,
    /// The last revision handed out.
    last_revision: u64,
    /// The revision last saved (or opened); `None` when no state of this document is on disk.
    saved_revision: Option<u64>,
}

impl Default for Document {
    fn default() -> Self {
        Document::new()
    }
}

impl Document {
    /// An empty document: no layers, no handles.
    pub fn new() -> Self {
        Document {
            state: State {
                layers: Vec::new(),
                handles: Handles::default(),
                options: BuildOptions::default(),
                animations: BTreeMap::new(),
                events: BTreeMap::new(),
                rig: None,
                rig_current: true,
                pose: Pose::default(),
                locked: BTreeSet::new(),
                slots: SlotLayout::default(),
                autorig: None,
                target: None,
            },
            path: None,
            undo: Vec::new(),
            redo: Vec::new(),
            revision: 0,
            last_revision: 0,
            // An empty document has nothing worth saving.
            saved_revision: Some(0),
        }
    }

    /// Opens a rig file and its images. A rig whose parts all have weights for its handles
    /// opens ready to pose.
    pub fn open(path: &Path) -> Result<Self, DocumentError> {
        let mut doc = RigDocument::load(path)?;
        let layers: Vec<Arc<Layer>> = doc
            .parts
            .iter()
            .zip(pipeline::load_part_images(path, &doc)?)
            .map(|(part, image)| {
                Arc::new(Layer {
                    name: part.name.clone(),
                    path: RigDocument::image_path(path, part),
                    image,
                    offset_px: part.offset_px,
                    canvas_px: doc.canvas,
                })
            })
            .collect();
        let weighted = !doc.handles.is_empty() && doc.parts.iter().all(|p| p.weights.is_some());
        let images: Vec<_> = layers.iter().map(|l| l.image.clone()).collect();
        if !weighted {
            // The stale rig as it was when saved: the next computation keeps locked columns
            // from it. Not posable (`rig_current` is false).
            for part in &mut doc.parts {
                if let Some(stale) = part.stale_weights.take() {
                    part.weights = Some(stale);
                }
            }
        }
        let state = State {
            layers,
            handles: doc.handles.clone(),
            options: doc.options.clone(),
            animations: doc.animations.clone(),
            events: doc.events.clone(),
            rig_current: weighted,
            locked: doc.locked.iter().cloned().collect(),
            slots: SlotLayout::of(&doc),
            autorig: doc.autorig,
            target: doc.target,
            rig: Some(Arc::new(Scene::new(doc, &images)?)),
            pose: Pose::default(),
        };
        Ok(Document {
            state,
            path: Some(path.to_path_buf()),
            undo: Vec::new(),
            redo: Vec::new(),
            revision: 0,
            last_revision: 0,
            saved_revision: Some(0),
        })
    }

    pub fn state(&self) -> &State {
        &self.state
    }

    /// The rig ready to pose: built from the current inputs, with weights.
    pub fn posable(&self) -> Option<&Arc<Scene>> {
        self.state
            .rig
            .as_ref()
            .filter(|_| self.state.rig_current && !self.state.handles.is_empty())
    }

    /// The inputs to build the rig from, for [`compute_rig`] on another thread.
    pub fn rig_inputs(&self) -> RigInputs {
        rig_inputs_of(&self.state)
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Applies `command`; on error nothing changes.
    pub fn apply(&mut self, command: Command) -> Result<(), DocumentError> {
        let next = apply_to(&self.state, command)?;
        let previous = std::mem::replace(&mut self.state, next);
        self.undo.push((previous, self.revision));
        if self.undo.len() > UNDO_LIMIT {
            self.undo.remove(0);
        }
        self.redo.clear();
        self.last_revision += 1;
        self.revision = self.last_revision;
        Ok(())
    }

    /// Steps back one command; false when there is nothing to undo.
    pub fn undo(&mut self) -> bool {
        swap_in(
            (&mut self.state, &mut self.revision),
            &mut self.undo,
            &mut self.redo,
        )
    }

    /// Re-applies the last undone command; false when there is nothing to redo.
    pub fn redo(&mut self) -> bool {
        swap_in(
            (&mut self.state, &mut self.revision),
            &mut self.redo,
            &mut self.undo,
        )
    }

    /// Whether the current state differs from the one last saved (or opened): undoing back to
    /// the saved state makes the document clean again.
    pub fn dirty(&self) -> bool {
        self.saved_revision != Some(self.revision)
    }

    /// The rig document as it would be saved at `path`. A stale rig is saved with its meshes
    /// but without weights, so that reopening asks for them again instead of posing with
    /// weights of other handles; while some handle is locked, those weights are saved aside
    /// (`stale_weights`), so that the computation after reopening still keeps the locked ones.
    pub fn to_rig_document(&self, path: &Path) -> Result<RigDocument, DocumentError> {
        rig_document(&self.state, path)
    }

    /// Saves to `path` atomically and remembers it as the document's path.
    pub fn save(&mut self, path: &Path) -> Result<(), DocumentError> {
        let job = self.save_job(path);
        job.run()?;
        self.saved(&job);
        Ok(())
    }

    /// Whether saving must first trace and mesh the layers (no rig of them has been built),
    /// which takes long on large images: callers with a UI save through [`Document::save_job`]
    /// on another thread then.
    pub fn save_needs_build(&self) -> bool {
        let state = &self.state;
        !state.layers.is_empty()
            && !matches!(&state.rig, Some(scene) if same_layers(&scene.doc, &state.layers))
    }

    /// [`Document::save`] as a snapshot to write on another thread; once it has run, hand it
    /// to [`Document::saved`].
    pub fn save_job(&self, path: &Path) -> SaveJob {
        SaveJob {
            state: self.state.clone(),
            target: path.to_path_buf(),
            revision: self.revision,
            autosave: false,
        }
    }

    /// Records that `job` (from [`Document::save_job`]) was written: its file becomes the
    /// document's path, and the document is clean unless it changed since the snapshot. An
    /// autosave's job changes nothing.
    pub fn saved(&mut self, job: &SaveJob) {
        if job.autosave {
            return;
        }
        self.path = Some(job.target.clone());
        // Edits made while it was written keep the document modified, as they should.
        self.saved_revision = Some(job.revision);
    }

    /// What [`crate::jobs::render_animation`] needs, copied out of the current state (for
    /// another thread).
    pub fn render_job(&self) -> Result<(RigDocument, Vec<image::RgbaImage>), DocumentError> {
        if self.posable().is_none() {
            return Err(DocumentError::NoWeights);
        }
        let dir = self
            .path
            .as_deref()
            .and_then(Path::parent)
            .map(Path::to_path_buf)
            .unwrap_or_else(std::env::temp_dir);
        let doc = self.to_rig_document(&dir.join("render.sinew.json"))?;
        let images = self.state.layers.iter().map(|l| l.image.clone()).collect();
        Ok((doc, images))
    }

    /// Writes the current state to the autosave side file of the document's path (or of
    /// `fallback` for a document never saved); returns where it went.
    pub fn autosave(&self, fallback: &Path) -> Result<PathBuf, DocumentError> {
        self.autosave_job(fallback).run()
    }

    /// [`Document::autosave`] as a snapshot to write on another thread (an autosave leaves the
    /// document's path and `dirty` alone).
    pub fn autosave_job(&self, fallback: &Path) -> SaveJob {
        SaveJob {
            state: self.state.clone(),
            target: autosave_path(self.path.as_deref().unwrap_or(fallback)),
            revision: self.revision,
            autosave: true,
        }
    }
}

/// Builds the rig (trace, mesh, weights) for `inputs`. Meant for a background thread:
/// `progress(parts_done, parts_total)` reports each part, and setting `cancel` stops the build
/// before the next part with [`DocumentError::Cancelled`]. `dir` is the folder image paths are
/// stored relative to. Locked handles keep their weights from `inputs.previous`
/// ([`pipeline::keep_locked_weights`]); painted weights of the others are recomputed.
pub fn compute_rig(
    inputs: &RigInputs,
    dir: &Path,
    cancel: &AtomicBool,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Scene, DocumentError> {
    let mut report = |done: usize, total: usize, _: &str| progress(done, total);
    let built = pipeline::build_rig_cancellable(
        &inputs.layers,
        dir,
        &inputs.options,
        &inputs.handles,
        &mut report,
        cancel,
    );
    let (mut doc, _) = match built {
        Err(PipelineError::Cancelled) => return Err(DocumentError::Cancelled),
        other => other?,
    };
    if let Some(previous) = &inputs.previous {
        pipeline::keep_locked_weights(&mut doc, &previous.doc, &inputs.locked)?;
    }
    inputs.slots.apply_to(&mut doc)?;
    let images: Vec<&image::RgbaImage> = inputs.layers.iter().map(|l| &l.image).collect();
    let mut scene = Scene::new(doc, &images)?;
    scene
        .set_skins(&inputs.slots.shown)
        .map_err(|e| DocumentError::Slots(e.to_string()))?;
    Ok(scene)
}

#[cfg(test)]
#[path = "document_key_tests.rs"]
mod key_tests;
