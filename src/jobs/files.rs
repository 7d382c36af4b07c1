//! The file-to-file jobs `sinew rig`, `autorig`, `render`, `export spine` and `colorize` run,
//! and `sinew batch` runs for each job of a manifest: one library call per command, so the
//! command line and the batch cannot drift apart.
//!
//! Each checks its outputs before any work ([`crate::io::outputs`]), computes everything, then
//! writes each file atomically ([`crate::io::atomic`]). Paths are used as given (relative ones
//! against the process's working folder). Progress callbacks are for the shells' bars.

use super::JobError;
use crate::autorig::{self, AutorigOptions, Proposal};
use crate::colorize::{self, ColorizeOptions, ColorizeStats, Scribbles};
use crate::export::spine::{self, SpineExport, SpineOptions};
use crate::io::outputs::{check_not_overwriting, check_output_kind, check_outputs, parent_dir};
use crate::io::sequence::{self, SequenceFormat, SequenceReport};
use crate::io::{self, BuildOptions, RigDocument};
use crate::pipeline::{self, PartReport, Scene};
use crate::playback::{self, RenderSettings};
use crate::rig::Handles;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Reads a JSON file that must hold one object into `T`; `what` names the file's kind in
/// errors ("handles file").
pub fn read_json<T: serde::de::DeserializeOwned>(path: &Path, what: &str) -> Result<T, JobError> {
    let text = std::fs::read_to_string(path).map_err(|source| JobError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let invalid = |reason: String| JobError::Json {
        path: path.to_path_buf(),
        what: what.to_string(),
        reason,
    };
    // serde would also take an array for a struct.
    let value: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| invalid(e.to_string()))?;
    if !value.is_object() {
        return Err(invalid("expected a JSON object".into()));
    }
    serde_json::from_str(&text).map_err(|e| invalid(e.to_string()))
}

/// The image files of `doc`'s parts (`doc` read from `rig`).
pub fn part_images(rig: &Path, doc: &RigDocument) -> Vec<PathBuf> {
    doc.parts
        .iter()
        .map(|part| RigDocument::image_path(rig, part))
        .collect()
}

/// The files of a rig job (`sinew rig`).
#[derive(Clone, Debug, Default)]
pub struct RigFiles {
    /// PNG layers or layered files, back to front. Layered files' parts are written to
    /// `OUTPUT.parts/`.
    pub images: Vec<PathBuf>,
    /// The handles file; without it the rig has no weights.
    pub handles: Option<PathBuf>,
    /// Layer (part) → the layer whose slot it is another attachment of.
    pub attachments: BTreeMap<String, String>,
    /// The rig document to write.
    pub output: PathBuf,
    /// The rest pose with the wireframe on top, PNG.
    pub preview: Option<PathBuf>,
    /// How the rig document's JSON is laid out (default compact).
    pub layout: io::JsonLayout,
}

/// What a rig job made.
pub struct RigDone {
    pub doc: RigDocument,
    pub stats: Vec<PartReport>,
    /// Notes on layers skipped or drawn differently ([`crate::art::Art::notes`]).
    pub notes: Vec<String>,
}

/// Loads the art of `images` for a command that writes `output` (layered files' parts go to
/// `OUTPUT.parts/`).
pub fn load_art(images: &[PathBuf], output: &Path) -> Result<crate::art::Art, JobError> {
    let options = crate::art::ArtOptions {
        parts_dir: output.with_extension("parts"),
        ..Default::default()
    };
    // A file that is not a PNG is refused with the formats art may come in, not only PNG.
    crate::art::load_art(images, &options).map_err(|e| match e {
        pipeline::PipelineError::Image(io::ImageError::NotPng { path, found, .. }) => {
            io::ImageError::NotPng {
                path,
                found,
                expected: io::image::Expected::Art,
            }
            .into()
        }
        e => e.into(),
    })
}

/// Traces, meshes and weighs `files.images` into a rig document (`sinew rig`); `progress` as
/// [`pipeline::build_rig_with_progress`] calls it.
pub fn rig_files(
    files: &RigFiles,
    options: &BuildOptions,
    progress: &mut dyn FnMut(usize, usize, &str),
) -> Result<RigDone, JobError> {
    let inputs = || {
        files
            .images
            .iter()
            .map(PathBuf::as_path)
            .chain(files.handles.as_deref())
    };
    check_outputs(
        inputs(),
        [Some(files.output.as_path()), files.preview.as_deref()],
    )?;
    let art = load_art(&files.images, &files.output)?;
    // The parts of layered files are written beside the document: none may overwrite an input.
    check_not_overwriting(
        inputs(),
        art.part_paths()
            .chain([files.output.as_path()])
            .chain(files.preview.as_deref())
            .map(Some),
    )?;
    let layer_names = || art.layers.iter().map(|l| l.name.as_str());
    let handles: Handles = match &files.handles {
        Some(path) => {
            let handles: Handles = read_json(path, "handles file")?;
            check_handles(&handles, path, &layer_names().collect::<Vec<_>>())?;
            handles
        }
        None => Handles::default(),
    };
    // Attachments name layers: checked before any work.
    if let Some(name) = files
        .attachments
        .iter()
        .flat_map(|(part, slot)| [part, slot])
        .find(|n| !layer_names().any(|l| l == n.as_str()))
    {
        return Err(JobError::Attachment(super::AttachmentError::NoLayer {
            name: name.clone(),
            layers: crate::names::owned(layer_names()),
            suggestion: crate::names::closest(name, layer_names()),
        }));
    }
    let doc_dir = parent_dir(&files.output);
    let (mut doc, stats) =
        pipeline::build_rig_with_progress(&art.layers, doc_dir, options, &handles, progress)?;
    doc.set_slots(&files.attachments, io::Skins::new())
        .map_err(|reason| JobError::Attachment(super::AttachmentError::Slots(reason)))?;
    let preview = match &files.preview {
        Some(_) => {
            let images: Vec<_> = art.layers.iter().map(|l| l.image.clone()).collect();
            Some(preview_image(&Scene::new(doc.clone(), &images)?)?)
        }
        None => None,
    };
    // The document with its layered files' parts, and copies of the images outside its folder
    // (`OUTPUT.parts/`), as one set: a rig names only files inside its folder.
    let images = io::PartImages {
        pending: art.part_files()?,
        held: Vec::new(),
    };
    let doc = doc.save_contained(&files.output, files.layout, images)?.doc;
    if let (Some(path), Some(image)) = (&files.preview, preview) {
        io::save_png(path, &image)?;
    }
    Ok(RigDone {
        doc,
        stats,
        notes: art.notes,
    })
}

/// The handles read from `path` checked as the rig will check them, and each part their
/// `bind` names against the art's `layers`, so that a refusal names the file.
fn check_handles(handles: &Handles, path: &Path, layers: &[&str]) -> Result<(), JobError> {
    handles.validate().map_err(|source| JobError::Handles {
        path: path.to_path_buf(),
        source,
    })?;
    for (handle, parts) in &handles.bind {
        if let Some(part) = parts.iter().find(|p| !layers.contains(&p.as_str())) {
            return Err(JobError::UnknownBindPart {
                path: path.to_path_buf(),
                handle: handle.clone(),
                part: part.clone(),
                layers: crate::names::owned(layers),
                suggestion: crate::names::closest(part, layers),
            });
        }
    }
    Ok(())
}

/// The rest pose on white with every part's wireframe on top.
pub fn preview_image(scene: &Scene) -> Result<image::RgbaImage, JobError> {
    let doc = &scene.doc;
    let [w, h] = doc.canvas;
    let mut canvas = tiny_skia::Pixmap::new(w, h).ok_or(JobError::CanvasTooLarge {
        width: w,
        height: h,
    })?;
    canvas.fill(tiny_skia::Color::WHITE);
    let rest = scene.rest_positions();
    scene.draw(&mut canvas, &rest, tiny_skia::Transform::identity())?;
    let wire = tiny_skia::Color::from_rgba8(20, 90, 200, 170);
    for (part, positions) in doc.parts.iter().zip(&rest) {
        crate::render::draw_wireframe(
            &mut canvas,
            positions,
            &part.mesh.triangles,
            tiny_skia::Transform::identity(),
            wire,
            0.75,
        );
    }
    Ok(crate::render::rgba_from_pixmap(&canvas))
}

/// The files of an autorig job (`sinew autorig`).
#[derive(Clone, Debug, Default)]
pub struct AutorigFiles {
    /// PNG layers or layered files, back to front.
    pub images: Vec<PathBuf>,
    /// The handles file to write.
    pub output: PathBuf,
    /// The proposed rig drawn over the images, PNG.
    pub preview: Option<PathBuf>,
}

/// Proposes handles for `files.images` and writes them (`sinew autorig`). Returns the proposal
/// and the art's notes.
pub fn autorig_files(
    files: &AutorigFiles,
    options: &AutorigOptions,
) -> Result<(Proposal, Vec<String>), JobError> {
    check_outputs(
        files.images.iter().map(PathBuf::as_path),
        [Some(files.output.as_path()), files.preview.as_deref()],
    )?;
    let art = load_art(&files.images, &files.output)?;
    let proposal = super::propose_handles(&art.layers, &art.pivots, options)?;
    let text = serde_json::to_string_pretty(&proposal.handles).map_err(JobError::Serialize)? + "\n";
    let preview = match &files.preview {
        Some(_) => {
            let refs: Vec<autorig::LayerRef> = art
                .layers
                .iter()
                .map(|l| autorig::LayerRef {
                    name: &l.name,
                    image: &l.image,
                    offset_px: l.offset_px,
                    canvas_px: l.canvas_px,
                })
                .collect();
            Some(autorig::draw_preview(&refs, &proposal.handles)?)
        }
        None => None,
    };
    write_text(&files.output, &text)?;
    if let (Some(path), Some(image)) = (&files.preview, preview) {
        io::save_png(path, &image)?;
    }
    Ok((proposal, art.notes))
}

/// Writes `text` to `path` atomically.
pub fn write_text(path: &Path, text: &str) -> Result<(), JobError> {
    io::write_atomic(path, text.as_bytes()).map_err(|source| JobError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// What a render job draws besides its settings (`sinew render`).
#[derive(Clone, Debug, Default)]
pub struct RenderFiles {
    /// The rig document.
    pub rig: PathBuf,
    /// The animation to play.
    pub animation: String,
    /// Skins to draw with, later ones overriding earlier ones.
    pub skins: Vec<String>,
    /// A folder (numbered PNGs), a `.gif`, or a `.png` sprite sheet with its `.json` beside it.
    pub output: PathBuf,
    /// Play as the document's target runtime when it names one
    /// ([`RenderSettings::playing_as`]): what `sinew render` does unless told `--exact` or
    /// another `--match-runtime`.
    pub follow_target: bool,
}

/// Renders an animation of a rig file to `files.output` (`sinew render`), in bounded memory;
/// `on_frame(frames_in_all)` is called once per frame drawn.
pub fn render_files(
    files: &RenderFiles,
    settings: &RenderSettings,
    on_frame: &(dyn Fn(usize) + Sync),
) -> Result<RenderDone, JobError> {
    let scene = scene_with_skins(&files.rig, &files.skins)?;
    // A frame folder is made where it is missing; a sprite sheet writes its JSON beside it.
    let written = match sequence::format_for_path(&files.output)? {
        SequenceFormat::Folder => vec![],
        SequenceFormat::Gif => vec![files.output.clone()],
        SequenceFormat::Sheet => vec![files.output.clone(), files.output.with_extension("json")],
    };
    if written.is_empty() {
        check_output_kind(&files.output, io::atomic::OutputKind::Folder)?;
    }
    let images = part_images(&files.rig, &scene.doc);
    check_outputs(
        std::iter::once(files.rig.as_path()).chain(images.iter().map(PathBuf::as_path)),
        written.iter().map(|f| Some(f.as_path())),
    )?;
    let animation = animation_in(&scene.doc, &files.rig, &files.animation)?;
    let targeted;
    let settings = match scene.doc.target.filter(|_| files.follow_target) {
        Some(target) => {
            targeted = settings.playing_as(target);
            &targeted
        }
        None => settings,
    };
    // Check the settings and the target before rendering: a bad one fails at once.
    settings.view(scene.doc.canvas)?;
    let frame_times_s = playback::frame_times(animation.duration_s(), settings.fps)?;
    let frames = frame_times_s.len();
    let (report, events) = playback::write_animation(
        &scene,
        &files.animation,
        &animation,
        settings,
        &files.output,
        &Default::default(),
        &|| on_frame(frames),
    )?;
    Ok(RenderDone {
        report,
        events,
        frame_times_s,
    })
}

/// What a render job wrote.
pub struct RenderDone {
    pub report: SequenceReport,
    /// The events each frame fires, per frame.
    pub events: Vec<Vec<crate::anim::FiredEvent>>,
    /// Each frame's time in the animation, s.
    pub frame_times_s: Vec<f64>,
}

/// The rig at `rig` with its parts' images, drawing `skins` ([`Scene::set_skins`]); a skin it
/// lacks is refused naming the file and the closest skin it has.
pub fn scene_with_skins(rig: &Path, skins: &[String]) -> Result<Scene, JobError> {
    let mut scene = Scene::load(rig)?;
    scene.set_skins(skins).map_err(|source| JobError::Skins {
        path: rig.to_path_buf(),
        source,
    })?;
    Ok(scene)
}

/// The document's animation `name`, checked against its rig; a refusal names no file (see
/// [`animation_in`]).
pub fn animation(doc: &RigDocument, name: &str) -> Result<crate::anim::Animation, JobError> {
    find_animation(doc, None, name)
}

/// The animation `name` of `doc`, read from `rig`, checked against its rig; a missing one is
/// refused naming `rig`, the closest name it has, or how to make one.
pub fn animation_in(
    doc: &RigDocument,
    rig: &Path,
    name: &str,
) -> Result<crate::anim::Animation, JobError> {
    find_animation(doc, Some(rig), name)
}

fn find_animation(
    doc: &RigDocument,
    rig: Option<&Path>,
    name: &str,
) -> Result<crate::anim::Animation, JobError> {
    doc.check_animations()?;
    doc.animations
        .get(name)
        .cloned()
        .ok_or_else(|| JobError::NoAnimation {
            rig: rig.map(Path::to_path_buf),
            name: name.to_string(),
            known: crate::names::owned(doc.animations.keys()),
            suggestion: crate::names::closest(name, doc.animations.keys()),
            bones: !doc.handles.bones.is_empty(),
        })
}

/// Exports a rig file for Spine into folder `output` (`sinew export spine`): `NAME.json`,
/// `NAME.atlas` and the pages; `name` defaults to the rig file's stem. Returns the export and
/// the files written.
pub fn export_spine_files(
    rig: &Path,
    output: &Path,
    name: Option<&str>,
    options: &SpineOptions,
) -> Result<(SpineExport, Vec<PathBuf>), JobError> {
    let doc = RigDocument::load(rig)?;
    let images = pipeline::load_part_images(rig, &doc)?;
    let scene = Scene::new(doc, &images)?;
    let name = match name {
        Some(n) => n.to_string(),
        None => rig
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "skeleton".into()),
    };
    let export = spine::export_spine(&scene, &images, &name, options)?;
    // `-o .` beside the rig would write NAME.json over the rig and NAME.png over a sprite.
    let targets: Vec<PathBuf> = export
        .file_names()
        .into_iter()
        .map(|file| output.join(file))
        .collect();
    let sprites = part_images(rig, &scene.doc);
    // The export folder is made where missing: only what is there and the overwriting are
    // checked.
    check_output_kind(output, io::atomic::OutputKind::Folder)?;
    for target in &targets {
        check_output_kind(target, io::atomic::OutputKind::File)?;
    }
    check_not_overwriting(
        std::iter::once(rig).chain(sprites.iter().map(PathBuf::as_path)),
        targets.iter().map(|t| Some(t.as_path())),
    )?;
    let written = export.write(output)?;
    Ok((export, written))
}

/// Exports the rig at `rig` as DragonBones files into the folder `output` (`sinew export
/// dragonbones`), named `name` (default: the rig file's stem): refused before anything is
/// written when a file would overwrite the rig or its images.
pub fn export_dragonbones_files(
    rig: &Path,
    output: &Path,
    name: Option<&str>,
    options: &crate::export::dragonbones::DragonBonesOptions,
) -> Result<(crate::export::dragonbones::DragonBonesExport, Vec<PathBuf>), JobError> {
    let doc = RigDocument::load(rig)?;
    let images = pipeline::load_part_images(rig, &doc)?;
    let scene = Scene::new(doc, &images)?;
    let name = match name {
        Some(n) => n.to_string(),
        None => rig
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "skeleton".into()),
    };
    let export = crate::export::dragonbones::export_dragonbones(&scene, &images, &name, options)?;
    let targets: Vec<PathBuf> = export
        .files()
        .into_iter()
        .map(|(file, _)| output.join(file))
        .collect();
    check_output_kind(output, io::atomic::OutputKind::Folder)?;
    for target in &targets {
        check_output_kind(target, io::atomic::OutputKind::File)?;
    }
    let sprites = part_images(rig, &scene.doc);
    check_not_overwriting(
        std::iter::once(rig).chain(sprites.iter().map(PathBuf::as_path)),
        targets.iter().map(|t| Some(t.as_path())),
    )?;
    let written = export.write(output)?;
    Ok((export, written))
}

/// Exports the rig at `rig` as binary glTF to `output` (a `.glb` file; `sinew export gltf`):
/// refused before anything is written when `output` would overwrite the rig or its images.
pub fn export_gltf_file(
    rig: &Path,
    output: &Path,
    options: &crate::export::gltf::GltfOptions,
) -> Result<crate::export::gltf::GltfExport, JobError> {
    let doc = RigDocument::load(rig)?;
    let images = pipeline::load_part_images(rig, &doc)?;
    let scene = Scene::new(doc, &images)?;
    let export = crate::export::gltf::export_gltf(&scene, &images, options)?;
    check_output_kind(output, io::atomic::OutputKind::File)?;
    let sprites = part_images(rig, &scene.doc);
    check_not_overwriting(
        std::iter::once(rig).chain(sprites.iter().map(PathBuf::as_path)),
        std::iter::once(Some(output)),
    )?;
    export.write(output)?;
    Ok(export)
}

/// The files of a colorize job (`sinew colorize`).
#[derive(Clone, Debug, Default)]
pub struct ColorizeFiles {
    /// The line art, PNG.
    pub lineart: PathBuf,
    /// An RGBA PNG layer of scribbles, or the JSON polyline file (by its `.json` extension).
    pub scribbles: PathBuf,
    /// The colored image to write, PNG.
    pub output: PathBuf,
    /// A folder (made where missing) for one mask PNG per color, `NN-rrggbb.png`.
    pub layers: Option<PathBuf>,
}

/// What a colorize job made.
pub struct ColorizeDone {
    pub size_px: (u32, u32),
    pub colors: usize,
    pub stats: ColorizeStats,
}

/// Colors line art from scribbles and writes the image (and the masks) (`sinew colorize`).
pub fn colorize_files(
    files: &ColorizeFiles,
    options: &ColorizeOptions,
) -> Result<ColorizeDone, JobError> {
    check_outputs(
        [files.lineart.as_path(), files.scribbles.as_path()],
        // The layers are a folder, made where missing.
        [Some(files.output.as_path())],
    )?;
    options.check().map_err(JobError::ColorizeOptions)?;
    let lineart = io::load_png(&files.lineart)?;
    let with_path = |source: Box<dyn std::error::Error + Send + Sync>| JobError::Colorize {
        path: files.scribbles.clone(),
        source,
    };
    let is_json = files
        .scribbles
        .extension()
        .is_some_and(|e| e.to_string_lossy().eq_ignore_ascii_case("json"));
    let scribbles = if is_json {
        let text = std::fs::read_to_string(&files.scribbles).map_err(|source| JobError::Read {
            path: files.scribbles.clone(),
            source,
        })?;
        Scribbles::from_json(&text, lineart.width(), lineart.height(), &options.scribbles)
            .map_err(|e| with_path(e.into()))?
    } else {
        let layer = io::load_png(&files.scribbles)?;
        Scribbles::from_layer(&layer, &options.scribbles).map_err(|e| with_path(e.into()))?
    };
    let result = colorize::colorize(&lineart, &scribbles, options, files.layers.is_some())
        .map_err(|e| with_path(e.into()))?;
    // Everything is computed; now write, each file atomically.
    if let Some(dir) = &files.layers {
        std::fs::create_dir_all(dir).map_err(|source| JobError::CreateFolder {
            path: dir.clone(),
            source,
        })?;
        for (k, (layer, color)) in result.layers.iter().zip(&result.palette).enumerate() {
            let path = dir.join(format!("{k:02}-{}.png", colorize::scribbles::hex(*color)));
            io::save_png(&path, layer)?;
        }
    }
    io::save_png(&files.output, &result.image)?;
    Ok(ColorizeDone {
        size_px: lineart.dimensions(),
        colors: result.palette.len(),
        stats: result.stats,
    })
}
