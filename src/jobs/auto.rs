//! `sinew auto ART -o DIR`: one layered file or one flat sprite in, a character that moves out,
//! with no choice asked of the person.
//!
//! In: the art (a `.psd`/`.psb`/`.ora` or a Spine script's `.json`, or a PNG) and the output
//! folder. The stages, each timed:
//!
//! 1. **read**: the art's layers ([`crate::art::load_art`]);
//! 2. **autorig**: the proposed skeleton ([`crate::autorig::autorig`], template chosen from the
//!    layer names or the drawing's shape, as `sinew autorig` does);
//! 3. **rig**: trace, mesh and weigh every part with those handles
//!    ([`crate::pipeline::build_rig`], as `sinew rig --handles` does);
//! 4. **motions**: every clip of the bundled library ([`crate::motion::library::MOTIONS`])
//!    retargeted onto the rig ([`crate::motion::apply_motion`]); every one that travels in place
//!    ([`IN_PLACE`]) so their renders stay in the frame, as games play them. A rig none of whose arm or leg bones
//!    the captures drive (no template: a fish, a kite; a rig whose spine alone has template
//!    names) gets no motion: the summary says so;
//! 5. **render**: each animation drawn ([`crate::playback::render_animation`]) at
//!    [`AutoOptions::fps`], the canvas scaled down to [`AutoOptions::render_side_px`];
//! 6. **spine**: the Spine 4.2 export ([`crate::export::spine::export_spine`]);
//! 7. **write**: every file encoded and written.
//!
//! Out, in `DIR`: `rig.json` (the rig document, weights and animations) with its part images in
//! `rig.parts/` (so the folder is self-contained and can be moved), `ANIM.gif` and the sprite
//! sheet `ANIM.sheet.png` + `ANIM.sheet.json` per animation, `spine/NAME.{json,atlas,png}`, and
//! `summary.json` ([`AutoSummary`]).
//!
//! Nothing is half-written: the art and the output folder are checked before any work, the
//! files are written into a hidden sibling folder (`.DIR.PID.N.tmp`), and that folder then takes
//! `DIR`'s place in one step (Linux's `renameat2(RENAME_EXCHANGE)`; elsewhere two renames). A
//! failed run leaves `DIR` as it was. `DIR` must be missing, empty, or a folder an earlier
//! `sinew auto` wrote (it holds `summary.json`): the earlier output is replaced whole, and files
//! the person added there are kept (hard-linked into the new folder before the exchange;
//! subfolders moved over right after it).

use super::JobError;
use crate::art::{self, ArtOptions};
use crate::autorig::{self, AutorigOptions};
use crate::export::spine::{self, SpineOptions};
use crate::io::atomic::{self, OutputKind};
use crate::io::outputs::{resolved, OutputError};
use crate::io::sequence::{self, SequenceOptions};
use crate::io::{self, BuildOptions};
use crate::motion::retarget::Group;
use crate::motion::{self, library, MapError, RetargetOptions, RetargetReport};
use crate::pipeline::{self, Scene};
use crate::playback::{self, RenderSettings};
use serde::{Deserialize, Serialize};
use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The motions applied in place (no travel): their renders stay in the canvas.
pub const IN_PLACE: &[&str] = &["walk", "run", "idle", "jump", "jump_forward"];
/// The summary's file name in the output folder; its presence marks a folder `sinew auto` wrote.
pub const SUMMARY_FILE: &str = "summary.json";
/// The rig document's file name in the output folder.
pub const RIG_FILE: &str = "rig.json";

/// What `sinew auto` reads and where it writes.
#[derive(Clone, Debug, Default)]
pub struct AutoFiles {
    /// A layered file or a PNG sprite.
    pub art: PathBuf,
    /// The output folder (replaced whole when the run succeeds).
    pub output: PathBuf,
}

/// How `sinew auto` works; every field defaults to what the separate commands default to.
#[derive(Clone, Debug)]
pub struct AutoOptions {
    pub autorig: AutorigOptions,
    pub build: BuildOptions,
    /// Frames per second of the renders. Default [`playback::DEFAULT_RENDER_FPS`].
    pub fps: f64,
    /// The renders' longest side, px: the canvas is scaled down to it (never up). Default 512.
    pub render_side_px: u32,
    pub spine: SpineOptions,
}

impl Default for AutoOptions {
    fn default() -> Self {
        AutoOptions {
            autorig: AutorigOptions::default(),
            build: BuildOptions::default(),
            fps: playback::DEFAULT_RENDER_FPS,
            render_side_px: 512,
            spine: SpineOptions::default(),
        }
    }
}

/// Why `sinew auto` stopped; nothing was written.
#[derive(Debug, thiserror::Error)]
pub enum AutoError {
    /// A stage's own error (boxed: it is large).
    #[error(transparent)]
    Job(Box<JobError>),
    #[error(
        "{}: the folder is not empty and not one sinew auto wrote (no {SUMMARY_FILE}): choose a new or empty folder",
        .0.display()
    )]
    ForeignFolder(PathBuf),
    #[error("{}: the art lies inside the output folder, which sinew auto replaces", .0.display())]
    ArtInOutput(PathBuf),
    #[error("{}: cannot read the art: {source}", .path.display())]
    Art {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("the bundled motion '{name}' cannot be read: {reason}")]
    Library { name: String, reason: String },
}

macro_rules! via_job {
    ($($t:ty),*) => {$(
        impl From<$t> for AutoError {
            fn from(e: $t) -> Self {
                AutoError::Job(Box::new(e.into()))
            }
        }
    )*};
}
via_job!(
    JobError,
    OutputError,
    pipeline::PipelineError,
    autorig::AutorigError,
    spine::SpineError,
    playback::PlaybackError,
    playback::RenderAnimationError,
    sequence::SequenceError,
    io::DocumentError,
    io::ImageError
);

/// What `sinew auto` chose, made and wrote; `DIR/summary.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AutoSummary {
    /// The art, as given.
    pub art: String,
    pub canvas_px: [u32; 2],
    /// humanoid, quadruped or none.
    pub template: String,
    /// Why that template (the autorig's own words).
    pub template_reason: String,
    /// The autorig's other remarks, and the art's (layers skipped).
    pub notes: Vec<String>,
    pub bones: Vec<String>,
    pub parts: Vec<PartSummary>,
    /// The motions applied, in library order.
    pub motions: Vec<MotionSummary>,
    /// Why motions were not applied (or one was not), when so.
    pub motions_skipped: Vec<String>,
    pub renders: Vec<RenderSummary>,
    pub spine: SpineSummary,
    /// Every file written, relative to the output folder, sorted.
    pub files: Vec<String>,
    /// Each stage's wall time, in order.
    pub stages: Vec<StageTime>,
    /// The whole run up to the commit of the folder, s.
    pub total_s: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PartSummary {
    pub name: String,
    pub vertices: usize,
    pub triangles: usize,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MotionSummary {
    pub name: String,
    pub in_place: bool,
    pub report: RetargetReport,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RenderSummary {
    pub animation: String,
    pub frames: usize,
    pub size_px: [u32; 2],
    pub fps: f64,
    pub gif: String,
    pub sheet: String,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SpineSummary {
    pub name: String,
    pub bones: usize,
    pub slots: usize,
    /// Per animation, the bones whose motion was baked (none: native timelines).
    pub baked: Vec<(String, Vec<String>)>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StageTime {
    pub stage: String,
    pub seconds: f64,
    /// Of the total.
    pub share: f64,
}

impl AutoSummary {
    /// The summary for a person, a few lines (what the command prints).
    pub fn text(&self, output: &Path) -> String {
        let mut s = String::new();
        let line = |s: &mut String, t: String| {
            s.push_str(&t);
            s.push('\n');
        };
        line(
            &mut s,
            format!(
                "{}: {}×{} px, {} parts, {} bones",
                self.art,
                self.canvas_px[0],
                self.canvas_px[1],
                self.parts.len(),
                self.bones.len()
            ),
        );
        line(
            &mut s,
            format!("template: {} {}", self.template, self.template_reason)
                .trim_end()
                .to_string(),
        );
        for note in &self.notes {
            line(&mut s, format!("  note: {note}"));
        }
        let vertices: usize = self.parts.iter().map(|p| p.vertices).sum();
        line(
            &mut s,
            format!(
                "rig: {} vertices; bones {}",
                vertices,
                self.bones.join(", ")
            ),
        );
        for m in &self.motions {
            let views: Vec<String> = m
                .report
                .views
                .iter()
                .map(|(g, v)| format!("{} {}", plain(g), plain(v)))
                .collect();
            line(
                &mut s,
                format!(
                    "motion {}: {:.2} s, {} keys{}{}; {}",
                    m.name,
                    m.report.duration_s,
                    m.report.keys,
                    if m.report.looped { ", loops" } else { "" },
                    if m.in_place { ", in place" } else { "" },
                    views.join(", ")
                ),
            );
        }
        for reason in &self.motions_skipped {
            line(&mut s, format!("motions skipped: {reason}"));
        }
        for r in &self.renders {
            line(
                &mut s,
                format!(
                    "render {}: {} frames of {}×{} px at {} fps",
                    r.animation, r.frames, r.size_px[0], r.size_px[1], r.fps
                ),
            );
        }
        line(
            &mut s,
            format!(
                "spine {}: {} bones, {} slots",
                self.spine.name, self.spine.bones, self.spine.slots
            ),
        );
        let timing: Vec<String> = self
            .stages
            .iter()
            .map(|t| format!("{} {:.2} s ({:.0} %)", t.stage, t.seconds, t.share * 100.0))
            .collect();
        line(
            &mut s,
            format!("time {:.2} s: {}", self.total_s, timing.join(", ")),
        );
        line(
            &mut s,
            format!(
                "wrote {} files into {} (list in {})",
                self.files.len(),
                output.display(),
                SUMMARY_FILE
            ),
        );
        s
    }
}

/// A unit enum's serde name (`legs`, `side`).
fn plain<T: Serialize>(value: &T) -> String {
    serde_json::to_value(value)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// Stage timings.
struct Clock {
    started: Instant,
    stages: Vec<(String, f64)>,
    at: Instant,
}

impl Clock {
    fn new() -> Self {
        let now = Instant::now();
        Clock {
            started: now,
            stages: Vec::new(),
            at: now,
        }
    }
    /// Ends the stage running since the last call.
    fn lap(&mut self, stage: &str) {
        let now = Instant::now();
        self.stages
            .push((stage.to_string(), (now - self.at).as_secs_f64()));
        self.at = now;
    }
    fn times(&self) -> (Vec<StageTime>, f64) {
        let total = self.started.elapsed().as_secs_f64();
        let stages = self
            .stages
            .iter()
            .map(|(stage, seconds)| StageTime {
                stage: stage.clone(),
                seconds: *seconds,
                share: if total > 0.0 { seconds / total } else { 0.0 },
            })
            .collect();
        (stages, total)
    }
}

/// A file name made of the art's stem: letters, digits, `-` and `_` kept, others `_`.
fn safe_name(art: &Path) -> String {
    let stem = art
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if name.trim_matches('_').is_empty() {
        "character".to_string()
    } else {
        name
    }
}

/// Checks the art and the output folder before any work; returns the folder a commit replaces
/// (through symbolic links).
fn check_paths(files: &AutoFiles) -> Result<PathBuf, AutoError> {
    let meta = fs::metadata(&files.art).map_err(|source| AutoError::Art {
        path: files.art.clone(),
        source,
    })?;
    if !meta.is_file() {
        return Err(AutoError::Art {
            path: files.art.clone(),
            source: std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file"),
        });
    }
    let target = crate::io::outputs::check_output_kind(&files.output, OutputKind::Folder)?;
    let parent = atomic::parent_or_dot(&target);
    if !parent.is_dir() {
        return Err(OutputError::MissingFolder {
            path: files.output.clone(),
            folder: parent.to_path_buf(),
        }
        .into());
    }
    if target.is_dir() {
        let mut entries = fs::read_dir(&target).map_err(|source| JobError::Read {
            path: files.output.clone(),
            source,
        })?;
        if entries.next().is_some() && !target.join(SUMMARY_FILE).is_file() {
            return Err(AutoError::ForeignFolder(files.output.clone()));
        }
    }
    if resolved(&files.art).starts_with(resolved(&target)) {
        return Err(AutoError::ArtInOutput(files.art.clone()));
    }
    Ok(target)
}

/// Runs `sinew auto`: see the module doc. Returns the summary written as `DIR/summary.json`.
pub fn auto_files(files: &AutoFiles, options: &AutoOptions) -> Result<AutoSummary, AutoError> {
    let target = check_paths(files)?;
    let mut clock = Clock::new();

    // 1. The art. Every part's image goes to DIR/rig.parts (a flat sprite too), so the output
    // folder is self-contained.
    let parts_dir = files.output.join("rig.parts");
    let mut art = art::load_art(
        std::slice::from_ref(&files.art),
        &ArtOptions {
            parts_dir: parts_dir.clone(),
            ..Default::default()
        },
    )?;
    for layer in &mut art.layers {
        if !layer.path.starts_with(&parts_dir) {
            layer.path = art::part_image_path(&parts_dir, &layer.name);
        }
    }
    let canvas_px = art.layers[0].canvas_px;
    clock.lap("read");

    // 2. The skeleton.
    let proposal = super::propose_handles(&art.layers, &art.pivots, &options.autorig)?;
    let template = autorig::template_name(proposal.template).to_string();
    let mut template_reason = String::new();
    let mut notes = Vec::new();
    for note in &proposal.notes {
        match note.strip_prefix("template: ") {
            Some(rest) if template_reason.is_empty() => {
                template_reason = rest
                    .strip_prefix(template.as_str())
                    .unwrap_or(rest)
                    .trim()
                    .to_string()
            }
            _ => notes.push(note.clone()),
        }
    }
    notes.extend(art.notes.iter().cloned());
    clock.lap("autorig");

    // 3. Meshes and weights, the document's image paths relative to DIR.
    let (mut doc, reports) = pipeline::build_rig(
        &art.layers,
        &files.output,
        &options.build,
        &proposal.handles,
    )?;
    clock.lap("rig");

    // 4. The library's motions.
    let mut motions = Vec::new();
    let mut motions_skipped = Vec::new();
    for m in library::MOTIONS {
        let clip = m.clip().map_err(|e| AutoError::Library {
            name: m.name.to_string(),
            reason: e.to_string(),
        })?;
        let in_place = IN_PLACE.contains(&m.name);
        let retarget = RetargetOptions {
            in_place,
            loop_mode: m.loop_mode(),
            ..Default::default()
        };
        let no_limbs = || {
            format!(
                "the library's captures drive no arm or leg bone of this rig (template {template}); \
                 animate it with `sinew animate --map`"
            )
        };
        match motion::apply_motion(&mut doc, &clip, None, m.name, &retarget) {
            // A rig with only the spine's names (hip, chest, neck, head) would sway its torso
            // and keep its limbs still: not a walk. None is applied.
            Ok(report)
                if !report.views.contains_key(&Group::Legs)
                    && !report.views.contains_key(&Group::Arms) =>
            {
                doc.animations.remove(m.name);
                motions_skipped.push(no_limbs());
                break;
            }
            Ok(report) => motions.push(MotionSummary {
                name: m.name.to_string(),
                in_place,
                report,
            }),
            Err(motion::ApplyError::Map(MapError::Empty)) => {
                motions_skipped.push(no_limbs());
                break;
            }
            // One motion that does not fit this rig does not stop the others.
            Err(e) => motions_skipped.push(format!("{}: {e}", m.name)),
        }
    }
    clock.lap("motions");

    // 5. Renders, drawn once each and written twice (GIF, sheet) below.
    let images: Vec<image::RgbaImage> = art.layers.iter().map(|l| l.image.clone()).collect();
    let scene = Scene::new(doc.clone(), &images)?;
    let longest = canvas_px[0].max(canvas_px[1]).max(1) as f64;
    let settings = RenderSettings {
        fps: options.fps,
        scale: (options.render_side_px as f64 / longest).min(1.0),
        ..Default::default()
    };
    settings.view(canvas_px)?;
    let mut drawn = Vec::new();
    for m in &motions {
        let animation = super::animation(&doc, &m.name)?;
        let frames = playback::render_animation(&scene, &m.name, &animation, &settings, &|| {})?;
        let events = playback::render_events(&scene, &animation, &settings)?;
        drawn.push((m.name.clone(), frames, events));
    }
    clock.lap("render");

    // 6. The Spine export.
    let name = safe_name(&files.art);
    let export = spine::export_spine(&scene, &images, &name, &options.spine)?;
    clock.lap("spine");

    // 7. Everything written into the staging folder, which then takes DIR's place.
    let staging = atomic::temporary_sibling(&target);
    tidy_stale(&target);
    fs::create_dir(&staging).map_err(|source| JobError::CreateFolder {
        path: staging.clone(),
        source,
    })?;
    let written = (|| -> Result<(Vec<String>, Vec<RenderSummary>), AutoError> {
        let mut files_written = Vec::new();
        // Part images.
        for layer in &art.layers {
            let rel = layer
                .path
                .strip_prefix(&files.output)
                .unwrap_or(&layer.path)
                .to_path_buf();
            let path = staging.join(&rel);
            if let Some(dir) = path.parent() {
                fs::create_dir_all(dir).map_err(|source| JobError::CreateFolder {
                    path: dir.to_path_buf(),
                    source,
                })?;
            }
            io::save_png(&path, &layer.image)?;
            files_written.push(rel.to_string_lossy().into_owned());
        }
        doc.save(&staging.join(RIG_FILE))?;
        files_written.push(RIG_FILE.to_string());
        let mut renders = Vec::new();
        for (anim, frames, events) in &drawn {
            let gif = format!("{anim}.gif");
            let sheet = format!("{anim}.sheet.png");
            let mut size_px = [0, 0];
            for file in [&gif, &sheet] {
                let report = sequence::write_sequence(
                    frames,
                    events,
                    settings.fps,
                    &staging.join(file),
                    &SequenceOptions::default(),
                )?;
                size_px = [report.frame_size_px.0, report.frame_size_px.1];
                for f in report.files {
                    if let Ok(rel) = f.strip_prefix(&staging) {
                        files_written.push(rel.to_string_lossy().into_owned());
                    }
                }
            }
            renders.push(RenderSummary {
                animation: anim.clone(),
                frames: frames.len(),
                size_px,
                fps: settings.fps,
                gif,
                sheet,
            });
        }
        for f in export.write(&staging.join("spine"))? {
            if let Ok(rel) = f.strip_prefix(&staging) {
                files_written.push(rel.to_string_lossy().into_owned());
            }
        }
        Ok((files_written, renders))
    })();
    let (mut files_written, renders) = match written {
        Ok(w) => w,
        Err(e) => {
            let _ = fs::remove_dir_all(&staging);
            return Err(e);
        }
    };
    clock.lap("write");
    files_written.push(SUMMARY_FILE.to_string());
    files_written.sort();
    let (stages, total_s) = clock.times();
    let summary = AutoSummary {
        art: files.art.display().to_string(),
        canvas_px,
        template,
        template_reason,
        notes,
        bones: doc.handles.bones.iter().map(|b| b.name.clone()).collect(),
        parts: doc
            .parts
            .iter()
            .zip(&reports)
            .map(|(p, r)| PartSummary {
                name: p.name.clone(),
                vertices: r.mesh.vertices,
                triangles: r.mesh.triangles,
            })
            .collect(),
        motions,
        motions_skipped,
        renders,
        spine: SpineSummary {
            name: export.name.clone(),
            bones: export.skeleton.bones.len(),
            slots: export.parts.len(),
            baked: export.baked.clone(),
        },
        files: files_written,
        stages,
        total_s,
    };
    let committed = (|| -> Result<(), AutoError> {
        let text = serde_json::to_string_pretty(&summary).map_err(JobError::Serialize)? + "\n";
        super::write_text(&staging.join(SUMMARY_FILE), &text)?;
        commit(&staging, &target).map_err(|source| JobError::Write {
            path: files.output.clone(),
            source,
        })?;
        Ok(())
    })();
    if let Err(e) = committed {
        let _ = fs::remove_dir_all(&staging);
        return Err(e);
    }
    Ok(summary)
}

/// The top-level names an earlier run's summary lists (its files and folders).
fn listed_names(dir: &Path) -> Option<Vec<String>> {
    let text = fs::read_to_string(dir.join(SUMMARY_FILE)).ok()?;
    let value: serde_json::Value = serde_json::from_str(&text).ok()?;
    let mut names: Vec<String> = value
        .get("files")?
        .as_array()?
        .iter()
        .filter_map(|f| f.as_str())
        .filter_map(|f| Path::new(f).components().next())
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    names.push(SUMMARY_FILE.to_string());
    Some(names)
}

/// Puts the fully written `staging` in `target`'s place. An earlier output there is replaced
/// whole; entries of it that its summary does not list (the person's) come along: files as
/// hard links before the exchange, folders (and files that cannot be linked) moved after it.
fn commit(staging: &Path, target: &Path) -> std::io::Result<()> {
    if !target.exists() {
        return fs::rename(staging, target);
    }
    let ours = listed_names(target).unwrap_or_default();
    let mut after = Vec::new();
    for entry in fs::read_dir(target)? {
        let entry = entry?;
        let name = entry.file_name();
        let text = name.to_string_lossy();
        if ours.iter().any(|n| *n == text) || staging.join(&name).exists() {
            continue;
        }
        if entry.file_type()?.is_dir() || fs::hard_link(entry.path(), staging.join(&name)).is_err()
        {
            after.push(name);
        }
    }
    if let Ok(meta) = fs::metadata(target) {
        let _ = fs::set_permissions(staging, meta.permissions());
    }
    atomic::exchange_folders(staging, target)?;
    // `staging` now holds the earlier output.
    for name in after {
        fs::rename(staging.join(&name), target.join(&name))?;
    }
    let _ = fs::remove_dir_all(staging);
    Ok(())
}

/// Removes the staging folders of runs that were killed (their process is gone). One without a
/// summary was killed before its commit (the summary is written last): it goes whole. One with a
/// summary is either a complete staging folder killed before the exchange (its entries are listed
/// or hard links of files `target` holds) or the earlier output killed between the exchange and
/// the last move: entries it does not list and `target` lacks (the person's folders) are moved
/// back into `target`, the rest goes.
fn tidy_stale(target: &Path) {
    for stale in atomic::stale_temporaries(target) {
        if !fs::symlink_metadata(&stale).is_ok_and(|m| m.is_dir()) {
            continue;
        }
        let Some(ours) = listed_names(&stale) else {
            let _ = fs::remove_dir_all(&stale);
            continue;
        };
        if let Ok(entries) = fs::read_dir(&stale) {
            for entry in entries.filter_map(|e| e.ok()) {
                let name = entry.file_name();
                let text = name.to_string_lossy();
                let back = target.join(&name);
                if ours.iter().any(|n| *n == text) || back.exists() {
                    let path = entry.path();
                    if entry.file_type().is_ok_and(|t| t.is_dir()) {
                        let _ = fs::remove_dir_all(path);
                    } else {
                        let _ = fs::remove_file(path);
                    }
                } else if target.is_dir() {
                    let _ = fs::rename(entry.path(), back);
                }
            }
        }
        let _ = fs::remove_dir(&stale);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spine_names_are_safe() {
        assert_eq!(safe_name(Path::new("a/My Hero.psd")), "My_Hero");
        assert_eq!(safe_name(Path::new("a/...png")), "character");
    }

    #[test]
    fn a_commit_keeps_the_persons_files_and_drops_the_earlier_output() {
        let tmp = crate::test_scratch::scratch("auto-commit");
        let dir = tmp.path();
        let target = dir.join("out");
        fs::create_dir_all(target.join("spine")).unwrap();
        fs::create_dir_all(target.join("mine")).unwrap();
        fs::write(target.join("old.gif"), b"old").unwrap();
        fs::write(target.join("spine/x.json"), b"old").unwrap();
        fs::write(target.join("notes.txt"), b"mine").unwrap();
        fs::write(target.join("mine/a.txt"), b"mine").unwrap();
        fs::write(
            target.join(SUMMARY_FILE),
            r#"{"files": ["old.gif", "spine/x.json", "summary.json"]}"#,
        )
        .unwrap();
        let staging = atomic::temporary_sibling(&target);
        fs::create_dir_all(staging.join("spine")).unwrap();
        fs::write(staging.join("new.gif"), b"new").unwrap();
        fs::write(staging.join(SUMMARY_FILE), b"{}").unwrap();
        commit(&staging, &target).unwrap();
        assert!(!staging.exists());
        assert!(!target.join("old.gif").exists());
        assert!(!target.join("spine/x.json").exists());
        assert_eq!(fs::read(target.join("new.gif")).unwrap(), b"new");
        assert_eq!(fs::read(target.join("notes.txt")).unwrap(), b"mine");
        assert_eq!(fs::read(target.join("mine/a.txt")).unwrap(), b"mine");
    }
}
