//! Saving a [`super::Document`]: the rig document a state is saved as, save jobs that write a
//! snapshot off the UI thread, the side files beside a document (autosave, view) and undo's
//! swap of states.

use super::*;

/// The rig document of `state` as it would be saved at `path` (see
/// [`Document::to_rig_document`]). Traces and meshes the layers when `state` has no rig of
/// them yet, which takes long on large images: [`SaveJob`] runs it off the UI thread.
pub(super) fn rig_document(state: &State, path: &Path) -> Result<RigDocument, DocumentError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut doc = match &state.rig {
        Some(scene) if same_layers(&scene.doc, &state.layers) => scene.doc.clone(),
        _ => {
            if state.layers.is_empty() {
                return Err(DocumentError::NothingToSave);
            }
            pipeline::build_rig(&state.layers, dir, &state.options, &Handles::default())?.0
        }
    };
    for part in &mut doc.parts {
        // A stale rig's weights are not saved as weights (reopening must not pose with
        // weights of other handles), but kept aside while locked handles need them.
        let stale = if state.rig_current {
            None
        } else {
            part.weights.take().or(part.stale_weights.take())
        };
        part.stale_weights = stale.filter(|_| !state.locked.is_empty());
    }
    for (part, layer) in doc.parts.iter_mut().zip(&state.layers) {
        part.image = pipeline::relative_path(dir, &layer.path);
    }
    doc.handles = state.handles.clone();
    doc.options = state.options.clone();
    doc.animations = state.animations.clone();
    doc.events = state.events.clone();
    doc.locked = state.locked.iter().cloned().collect();
    doc.autorig = state.autorig;
    doc.target = state.target;
    state.slots.apply_to(&mut doc)?;
    Ok(doc)
}

/// A snapshot of a document to save or autosave, possibly on another thread:
/// [`Document::save_job`] and [`Document::autosave_job`] copy the state (layers and rig are
/// shared), [`SaveJob::run`] writes it.
#[derive(Clone)]
pub struct SaveJob {
    pub(super) state: State,
    pub(super) target: PathBuf,
    /// The document's revision when the snapshot was taken.
    pub(super) revision: u64,
    /// An autosave: [`Document::saved`] ignores it.
    pub(super) autosave: bool,
}

impl SaveJob {
    /// Where the file goes.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Writes the snapshot to its file (atomically and self-contained: layers' images outside
    /// its folder are copied into `NAME.parts/` with it, and an image whose file is gone is
    /// written from the layer held in memory); returns where it went.
    pub fn run(&self) -> Result<PathBuf, DocumentError> {
        let images = crate::io::PartImages {
            pending: Vec::new(),
            held: self.state.layers.iter().map(|l| Some(&l.image)).collect(),
        };
        rig_document(&self.state, &self.target)?.save_contained(
            &self.target,
            crate::io::JsonLayout::Compact,
            images,
        )?;
        Ok(self.target.clone())
    }
}

/// Makes the last state of `from` current (with its revision), pushing the current one onto
/// `to`.
pub(super) fn swap_in(
    (state, revision): (&mut State, &mut u64),
    from: &mut Vec<(State, u64)>,
    to: &mut Vec<(State, u64)>,
) -> bool {
    match from.pop() {
        Some((other, other_revision)) => {
            let previous = std::mem::replace(state, other);
            to.push((previous, std::mem::replace(revision, other_revision)));
            true
        }
        None => false,
    }
}

/// The side file autosaves go to: `NAME.autosave.json` beside `NAME.json`.
pub fn autosave_path(path: &Path) -> PathBuf {
    side_file(path, "autosave")
}

/// `NAME.KIND.json` beside the document `NAME.json` (autosaves, the editor's view).
pub fn side_file(path: &Path, kind: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "untitled".into());
    path.with_file_name(format!("{stem}.{kind}.json"))
}

pub(super) fn same_layers(doc: &RigDocument, layers: &[Arc<Layer>]) -> bool {
    doc.parts.len() == layers.len() && doc.parts.iter().zip(layers).all(|(p, l)| p.name == l.name)
}
