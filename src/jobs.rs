//! The long-running work the shells start on a document: exporting, rendering an animation,
//! proposing handles.
//!
//! In: a [`Document`] (or what [`Document::render_job`] copies out of it, or its layers) and the
//! job's options. Out: the files written, or the proposal. Each runs to completion on the
//! calling thread; the editor calls them from a background thread. [`files`]: the file-to-file
//! jobs of the command line and of `sinew batch` ([`crate::batch`]). [`crate::document`] stays
//! about the editable document: it does not reach into export, playback or the automatic rig.

pub mod auto;
mod files;

pub use files::*;

use crate::anim::AnimError;
use crate::autorig::{self, AutorigError, AutorigOptions, LayerRef, Proposal};
use crate::document::{Document, DocumentError};
use crate::export::spine::{self, SpineError, SpineOptions};
use crate::io::outputs::{check_not_overwriting, OutputError};
use crate::io::sequence::{self, SequenceError, SequenceReport};
use crate::io::RigDocument;
use crate::names;
use crate::pipeline::{Layer, PipelineError, Scene};
use crate::playback::{self, PlaybackError, RenderAnimationError, RenderSettings};
use std::path::{Path, PathBuf};

/// Why a job failed. Each variant is the failing stage's own error, shown as it is.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    #[error(transparent)]
    Document(#[from] DocumentError),
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
    #[error(transparent)]
    Animation(#[from] AnimError),
    #[error(transparent)]
    Spine(#[from] SpineError),
    #[error(transparent)]
    Gltf(#[from] crate::export::gltf::GltfError),
    #[error(transparent)]
    DragonBones(#[from] crate::export::dragonbones::DragonBonesError),
    #[error(transparent)]
    Playback(#[from] PlaybackError),
    #[error(transparent)]
    Render(#[from] RenderAnimationError),
    #[error(transparent)]
    Sequence(#[from] SequenceError),
    #[error(transparent)]
    Autorig(#[from] AutorigError),
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error(transparent)]
    RigDocument(#[from] crate::io::DocumentError),
    #[error(transparent)]
    Image(#[from] crate::io::ImageError),
    #[error(transparent)]
    Slot(#[from] crate::io::SlotError),
    #[error(transparent)]
    Draw(#[from] crate::render::RenderError),
    #[error("{}: cannot read: {source}", .path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: cannot write: {source}", .path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: cannot create the folder: {source}", .path.display())]
    CreateFolder {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: not a valid {what}: {reason}", .path.display())]
    Json {
        path: PathBuf,
        what: String,
        reason: String,
    },
    /// A slot attachment naming no layer, or making a slot of something that cannot be one.
    #[error("attachment: {0}")]
    Attachment(AttachmentError),
    /// The rig (at `rig`, when known) has no animation `name`.
    #[error(
        "{}",
        no_animation_message(.rig.as_deref(), .name, .known, .suggestion, *.bones)
    )]
    NoAnimation {
        rig: Option<PathBuf>,
        name: String,
        /// The animations it has, in name order.
        known: Vec<String>,
        /// The one of `known` most like `name` ([`names::closest`]).
        suggestion: Option<String>,
        /// Whether the rig has bones (a motion of the bundled library drives bones).
        bones: bool,
    },
    /// The handles file at `path` is not a valid set of handles.
    #[error("{}: {source}", .path.display())]
    Handles {
        path: PathBuf,
        source: crate::rig::HandleError,
    },
    /// The handles file at `path` binds a handle to a part the art does not have.
    #[error(
        "{}: 'bind' gives handle '{handle}' the part '{part}', which is not a layer of the art{} \
         (its layers: {})",
        .path.display(),
        names::did_you_mean(.suggestion),
        names::listed(.layers)
    )]
    UnknownBindPart {
        path: PathBuf,
        handle: String,
        part: String,
        layers: Vec<String>,
        suggestion: Option<String>,
    },
    /// The rig at `path` cannot be drawn with the skins asked for.
    #[error("{}: {source}", .path.display())]
    Skins {
        path: PathBuf,
        source: crate::io::SlotError,
    },
    #[error("a canvas of {width}×{height} px is too large to draw")]
    CanvasTooLarge { width: u32, height: u32 },
    #[error("cannot write JSON: {0}")]
    Serialize(serde_json::Error),
    /// A colorize option out of its range (before any file is read).
    #[error(transparent)]
    ColorizeOptions(crate::colorize::ColorizeError),
    /// The scribbles or the colorization failed; `path` is the scribbles file.
    #[error("{}: {source}", .path.display())]
    Colorize {
        path: PathBuf,
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

/// What is wrong with the attachments of a rig job (`--attachment PART=SLOT`, a batch job's
/// `attachments`).
#[derive(Debug, thiserror::Error)]
pub enum AttachmentError {
    /// A name that is no layer of the art.
    #[error(
        "'{name}' is not a layer of the rig{} (its layers: {})",
        names::did_you_mean(.suggestion),
        names::listed(.layers)
    )]
    NoLayer {
        name: String,
        /// The art's layers, in order.
        layers: Vec<String>,
        /// The one of `layers` most like `name` ([`names::closest`]).
        suggestion: Option<String>,
    },
    /// Layers that cannot be made slots and attachments as asked (the reason).
    #[error("{0}")]
    Slots(String),
}

/// The refusal of an animation `name` the rig at `rig` lacks: the closest name it has, or, when
/// it has none or `name` is a motion of the bundled library, how to make one.
fn no_animation_message(
    rig: Option<&Path>,
    name: &str,
    known: &[String],
    suggestion: &Option<String>,
    bones: bool,
) -> String {
    let (file, shown) = match rig {
        Some(rig) => (format!("{}: ", rig.display()), command_path(rig)),
        None => (String::new(), "RIG.json".to_string()),
    };
    let library = crate::motion::library::find(name).map(|m| m.name);
    if known.is_empty() && !bones {
        return format!(
            "{file}the rig has no animations yet; key one in 'sinew edit {shown} --mode animate' \
             (New animation); a motion of the bundled library needs bones, which 'sinew autorig' \
             proposes"
        );
    }
    if known.is_empty() {
        let motion = library.unwrap_or("walk");
        return format!(
            "{file}the rig has no animations yet; make one with 'sinew animate {shown} --motion \
             {motion}' (the bundled {motion}, retargeted) or key one in 'sinew edit {shown} \
             --mode animate' (New animation)"
        );
    }
    let hint = match (suggestion, library) {
        (None, Some(motion)) if bones => format!(
            "; 'sinew animate {shown} --motion {motion}' adds the bundled library's {motion}"
        ),
        _ => String::new(),
    };
    format!(
        "{file}the rig has no animation '{name}'{} (it has: {}){hint}",
        names::did_you_mean(suggestion),
        names::listed(known)
    )
}

/// `path` as it would be typed in a command line: in double quotes when it holds anything but
/// letters, digits and `._/-`.
fn command_path(path: &Path) -> String {
    let text = path.display().to_string();
    let plain = !text.is_empty()
        && text
            .chars()
            .all(|c| c.is_alphanumeric() || "._/-".contains(c));
    if plain {
        text
    } else {
        format!("\"{text}\"")
    }
}

/// Exports the document's current state for Spine's runtimes into `dir` (see
/// [`crate::export::spine`]): `NAME.json`, `NAME.atlas` and the atlas pages, with the document's
/// current animations. Needs current weights ([`DocumentError::NoWeights`] otherwise).
pub fn export_spine(
    doc: &Document,
    dir: &Path,
    name: &str,
    options: &SpineOptions,
) -> Result<Vec<PathBuf>, JobError> {
    if doc.posable().is_none() {
        return Err(DocumentError::NoWeights.into());
    }
    let rig = doc.to_rig_document(&dir.join(format!("{name}.sinew.json")))?;
    let images: Vec<_> = doc.state().layers.iter().map(|l| l.image.clone()).collect();
    let scene = Scene::new(rig, &images)?;
    let export = spine::export_spine(&scene, &images, name, options)?;
    // As `sinew export spine` checks: no file of the export may write over the document or a
    // part's image (an export into the document's folder under its name would), nor another.
    let targets: Vec<PathBuf> = export
        .file_names()
        .into_iter()
        .map(|file| dir.join(file))
        .collect();
    let layers: Vec<&Path> = doc
        .state()
        .layers
        .iter()
        .map(|l| l.path.as_path())
        .collect();
    check_not_overwriting(
        doc.path.as_deref().into_iter().chain(layers),
        targets.iter().map(|t| Some(t.as_path())),
    )?;
    Ok(export.write(dir)?)
}

/// Renders animation `name` of `doc` as `settings` say to `output`, which is a folder of
/// numbered PNGs, a `.gif` or a `.png` sprite sheet, as `sinew render` does. `doc` and `images`
/// are what [`Document::render_job`] copies out of a document.
pub fn render_animation(
    doc: RigDocument,
    images: &[image::RgbaImage],
    name: &str,
    settings: &RenderSettings,
    output: &Path,
) -> Result<SequenceReport, JobError> {
    doc.check_animations()?;
    let animation = doc
        .animations
        .get(name)
        .cloned()
        .ok_or_else(|| AnimError::Malformed {
            animation: name.to_string(),
            reason: "the document has no animation of that name".into(),
        })?;
    sequence::format_for_path(output)?;
    // Settings are checked before the scene is built: a bad scale fails at once.
    settings.view(doc.canvas)?;
    let scene = Scene::new(doc, images)?;
    let (report, _events) = playback::write_animation(
        &scene,
        name,
        &animation,
        settings,
        output,
        &Default::default(),
        &|| {},
    )?;
    Ok(report)
}

/// Handles proposed by the automatic rig (`sinew autorig`) for `layers`, to install with
/// [`crate::document::Command::Propose`] (which records the template followed) and edit like
/// hand-placed ones.
pub fn propose_handles<L: std::borrow::Borrow<Layer>>(
    layers: &[L],
    pivots: &[crate::io::layered::Pivot],
    options: &AutorigOptions,
) -> Result<Proposal, JobError> {
    let refs: Vec<LayerRef> = layers
        .iter()
        .map(|l| {
            let l = l.borrow();
            LayerRef {
                name: &l.name,
                image: &l.image,
                offset_px: l.offset_px,
                canvas_px: l.canvas_px,
            }
        })
        .collect();
    Ok(autorig::autorig(&refs, pivots, options)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_animation_says_what_to_do_next() {
        let known = names::owned(["hop", "walk"]);
        let rig = Path::new("my rig.json");
        assert_eq!(
            no_animation_message(Some(rig), "walkk", &known, &Some("walk".into()), true),
            "my rig.json: the rig has no animation 'walkk'; did you mean 'walk'? (it has: hop, walk)"
        );
        let none = no_animation_message(Some(rig), "stroll", &[], &None, true);
        assert!(
            none.starts_with("my rig.json: the rig has no animations yet; make one with 'sinew animate \"my rig.json\" --motion walk'"),
            "{none}"
        );
        assert!(
            none.contains("'sinew edit \"my rig.json\" --mode animate'"),
            "{none}"
        );
        let boneless = no_animation_message(Some(rig), "walk", &[], &None, false);
        assert!(!boneless.contains("sinew animate"), "{boneless}");
        assert!(boneless.contains("sinew autorig"), "{boneless}");
        assert_eq!(
            no_animation_message(None, "run", &known, &None, true),
            "the rig has no animation 'run' (it has: hop, walk); 'sinew animate RIG.json --motion \
             run' adds the bundled library's run"
        );
    }
}
