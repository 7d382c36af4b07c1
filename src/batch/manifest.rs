//! The batch manifest (`sinew batch MANIFEST.json`): typed jobs, parsed at the edge.
//!
//! In: the manifest's JSON text. Out: a [`Manifest`] whose jobs each name their inputs,
//! options and outputs; paths are relative to the manifest's folder (see docs/formats.md,
//! "Batch manifest"). Checks that need several jobs (inputs that exist or are made, outputs
//! written once, no cycle) are [`super::plan`]'s.

use crate::colorize::{ColorWeights, ColorizeOptions, FillMode, RegionSplit};
use crate::export::spine::{BakeMode, SpineOptions, SpinePreset, SpineVersion};
use crate::io::BuildOptions;
use crate::playback::RenderSettings;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

use super::BatchError;

/// A batch: jobs in any order (they run after the jobs that write their inputs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    pub jobs: Vec<Job>,
}

/// The job kinds, as the manifest's `kind` names them.
pub const KINDS: [&str; 5] = ["rig", "autorig", "render", "export", "colorize"];

/// One job: a kind, a unique name, inputs, options, outputs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Job {
    /// `sinew rig`: layers (+ handles) → a rig document.
    Rig(Box<RigJob>),
    /// `sinew autorig`: layers → a handles file.
    Autorig(AutorigJob),
    /// `sinew render`: an animation of a rig → frames folder, GIF or sprite sheet.
    Render(RenderJob),
    /// `sinew export spine`: a rig → Spine JSON, atlas and pages in a folder.
    Export(ExportJob),
    /// `sinew colorize`: line art + scribbles → a colored image (and masks).
    Colorize(ColorizeJob),
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RigJob {
    pub name: String,
    pub inputs: RigInputs,
    /// The library's build options (trace, mesh, weights, ik), each defaulting as
    /// `sinew rig` does without flags.
    #[serde(default)]
    pub options: RigJobOptions,
    pub outputs: RigOutputs,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RigInputs {
    /// PNG layers or layered files, back to front.
    pub images: Vec<PathBuf>,
    /// The handles file; without it the rig has no weights.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub handles: Option<PathBuf>,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct RigJobOptions {
    /// Part → the part whose slot it is another attachment of (`--attachment PART=SLOT`).
    /// Default none.
    pub attachments: BTreeMap<String, String>,
    /// Default: `sinew rig`'s defaults.
    pub build: BuildOptions,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RigOutputs {
    /// The rig document.
    pub rig: PathBuf,
    /// The wireframe preview, PNG.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preview: Option<PathBuf>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AutorigJob {
    pub name: String,
    pub inputs: LayerInputs,
    #[serde(default)]
    pub options: AutorigJobOptions,
    pub outputs: AutorigOutputs,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LayerInputs {
    /// PNG layers or layered files, back to front.
    pub images: Vec<PathBuf>,
}

/// `sinew autorig`'s flags.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct AutorigJobOptions {
    /// At most this many bones. Default: the automatic rig's budget.
    pub bones: Option<usize>,
    /// Also a cage of at most this many vertices. Default none.
    pub cage: Option<usize>,
    /// Point handles. Default 0.
    pub points: usize,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AutorigOutputs {
    /// The handles file.
    pub handles: PathBuf,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preview: Option<PathBuf>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RenderJob {
    pub name: String,
    pub inputs: RigInput,
    pub options: RenderJobOptions,
    pub outputs: RenderOutputs,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RigInput {
    /// The rig document (its part images are read beside it, as it names them).
    pub rig: PathBuf,
}

/// `sinew render`'s flags.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RenderJobOptions {
    /// The animation to play.
    pub animation: String,
    /// Frames per second. Default 24.
    #[serde(default = "default_fps")]
    pub fps: f64,
    /// Output px per canvas px. Default 1.
    #[serde(default = "default_scale")]
    pub scale: f64,
    /// Output size [w, h] px. Default: the scaled canvas.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size_px: Option<[u32; 2]>,
    /// Background `#rrggbb` or `#rrggbbaa`. Default transparent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub background: Option<String>,
    /// Skins to draw with, a later one overriding an earlier one. Default none.
    #[serde(default)]
    pub skins: Vec<String>,
}

fn default_fps() -> f64 {
    crate::playback::DEFAULT_RENDER_FPS
}

fn default_scale() -> f64 {
    RenderSettings::default().scale
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RenderOutputs {
    /// A folder (no extension: numbered PNGs), `.gif`, or `.png` (a sprite sheet; its `.json`
    /// is written beside it).
    pub output: PathBuf,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExportJob {
    pub name: String,
    pub inputs: RigInput,
    #[serde(default)]
    pub options: ExportJobOptions,
    pub outputs: ExportOutputs,
}

/// The names of [`BakeMode`]'s values.
#[derive(JsonSchema)]
#[serde(rename_all = "lowercase")]
#[allow(dead_code)]
enum BakeModeName {
    Auto,
    All,
}

/// `sinew export spine`'s flags.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct ExportJobOptions {
    /// Base name of the files. Default: the rig file's name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skeleton: Option<String>,
    /// Spine editor line: "4.1", "4.2" or "4.3". Default "4.2".
    pub spine_version: String,
    /// Keys per second of baked motion. Default 30.
    pub bake_fps: f64,
    /// What is baked. Default auto.
    #[schemars(with = "BakeModeName")]
    pub bake: BakeMode,
    /// "full" (default) or "game" (at most 250 vertices per mesh and 4 influences per vertex),
    /// as `--preset`; the two limits below override the preset's.
    pub preset: SpinePreset,
    /// Keep the K strongest weights per vertex. Default all (or the preset's).
    pub max_influences: Option<usize>,
    /// Decimate each mesh to at most N vertices. Default the fine mesh (or the preset's).
    pub max_vertices: Option<usize>,
}

impl Default for ExportJobOptions {
    fn default() -> Self {
        let spine = SpineOptions::default();
        ExportJobOptions {
            skeleton: None,
            spine_version: SpineVersion::default().name().into(),
            bake_fps: spine.bake_fps,
            bake: spine.bake,
            preset: SpinePreset::Full,
            max_influences: None,
            max_vertices: None,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExportOutputs {
    /// The folder the export is written into (made where missing).
    pub folder: PathBuf,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ColorizeJob {
    pub name: String,
    pub inputs: ColorizeInputs,
    #[serde(default)]
    pub options: ColorizeJobOptions,
    pub outputs: ColorizeOutputs,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ColorizeInputs {
    /// The line art, PNG.
    pub lineart: PathBuf,
    /// A scribble layer (PNG) or the JSON polylines of `sinew colorize --scribbles`.
    pub scribbles: PathBuf,
}

/// `sinew colorize`'s flags. The defaults are [`ColorizeOptions::default`]'s.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct ColorizeJobOptions {
    /// Default flat.
    pub fill: FillMode,
    /// Default harmonic.
    pub weights: ColorWeights,
    /// Lift scale: a full color change counts as this many px. Default 1000.
    pub scale: f64,
    /// How a region holding several colors is split (`--split`): reach, depth, density or
    /// weights. Default reach.
    pub split: RegionSplit,
    /// With split reach: α, a pixel d px from the lines costs d^−α to cross
    /// (`--split-exponent`). Default 6.
    pub split_depth_exponent: f64,
    /// With split depth: distances to the lines beyond this many px count as this many
    /// (`--split-depth`). Default 16.
    pub split_depth_px: f64,
    /// With split density: σ in px of the Gaussian that measures the ink around a pixel
    /// (`--split-blur`). Default 12.
    pub split_blur_px: f64,
}

impl Default for ColorizeJobOptions {
    fn default() -> Self {
        let options = ColorizeOptions::default();
        ColorizeJobOptions {
            fill: options.fill,
            weights: options.weights,
            scale: options.scale,
            split: options.split,
            split_depth_exponent: options.split_depth_exponent,
            split_depth_px: options.split_depth_px,
            split_blur_px: options.split_blur_px,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ColorizeOutputs {
    /// The colored image, PNG.
    pub image: PathBuf,
    /// A folder for one mask PNG per color.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layers: Option<PathBuf>,
}

/// An input or output path of a job, and whether it is a folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct JobPath {
    pub path: PathBuf,
    pub folder: bool,
}

impl Job {
    pub fn name(&self) -> &str {
        match self {
            Job::Rig(j) => &j.name,
            Job::Autorig(j) => &j.name,
            Job::Render(j) => &j.name,
            Job::Export(j) => &j.name,
            Job::Colorize(j) => &j.name,
        }
    }

    pub fn kind(&self) -> &'static str {
        match self {
            Job::Rig(_) => "rig",
            Job::Autorig(_) => "autorig",
            Job::Render(_) => "render",
            Job::Export(_) => "export",
            Job::Colorize(_) => "colorize",
        }
    }

    /// The files the job reads, as the manifest names them (relative to its folder). A rig
    /// document's part images are read too; [`super::record`] hashes them.
    pub fn inputs(&self) -> Vec<PathBuf> {
        match self {
            Job::Rig(j) => j
                .inputs
                .images
                .iter()
                .chain(&j.inputs.handles)
                .cloned()
                .collect(),
            Job::Autorig(j) => j.inputs.images.clone(),
            Job::Render(j) => vec![j.inputs.rig.clone()],
            Job::Export(j) => vec![j.inputs.rig.clone()],
            Job::Colorize(j) => vec![j.inputs.lineart.clone(), j.inputs.scribbles.clone()],
        }
    }

    /// Every path the manifest names for the job, with its field as the manifest writes it
    /// (`inputs.images[1]`, `outputs.rig`): what [`super::plan`] confines to the manifest's
    /// folder.
    pub fn named_paths(&self) -> Vec<(String, &PathBuf)> {
        let mut out: Vec<(String, &PathBuf)> = Vec::new();
        fn list<'a>(out: &mut Vec<(String, &'a PathBuf)>, field: &str, paths: &'a [PathBuf]) {
            for (i, p) in paths.iter().enumerate() {
                out.push((format!("{field}[{i}]"), p));
            }
        }
        let mut named = Vec::new();
        match self {
            Job::Rig(j) => {
                list(&mut out, "inputs.images", &j.inputs.images);
                named.extend(j.inputs.handles.iter().map(|p| ("inputs.handles", p)));
                named.push(("outputs.rig", &j.outputs.rig));
                named.extend(j.outputs.preview.iter().map(|p| ("outputs.preview", p)));
            }
            Job::Autorig(j) => {
                list(&mut out, "inputs.images", &j.inputs.images);
                named.push(("outputs.handles", &j.outputs.handles));
                named.extend(j.outputs.preview.iter().map(|p| ("outputs.preview", p)));
            }
            Job::Render(j) => {
                named.push(("inputs.rig", &j.inputs.rig));
                named.push(("outputs.output", &j.outputs.output));
            }
            Job::Export(j) => {
                named.push(("inputs.rig", &j.inputs.rig));
                named.push(("outputs.folder", &j.outputs.folder));
            }
            Job::Colorize(j) => {
                named.push(("inputs.lineart", &j.inputs.lineart));
                named.push(("inputs.scribbles", &j.inputs.scribbles));
                named.push(("outputs.image", &j.outputs.image));
                named.extend(j.outputs.layers.iter().map(|p| ("outputs.layers", p)));
            }
        }
        out.extend(named.into_iter().map(|(f, p)| (f.to_string(), p)));
        out
    }

    /// What the job writes, as the manifest names it. A rig of layered files also writes
    /// `RIG.parts/` (listed here as a folder); a sprite sheet writes its `.json` beside it.
    pub fn outputs(&self) -> Vec<JobPath> {
        let file = |p: &PathBuf| JobPath {
            path: p.clone(),
            folder: false,
        };
        let folder = |p: &PathBuf| JobPath {
            path: p.clone(),
            folder: true,
        };
        match self {
            Job::Rig(j) => {
                let mut out = vec![file(&j.outputs.rig)];
                out.extend(j.outputs.preview.iter().map(file));
                if j.inputs.images.iter().any(|p| crate::art::is_layered(p)) {
                    out.push(folder(&j.outputs.rig.with_extension("parts")));
                }
                out
            }
            Job::Autorig(j) => std::iter::once(&j.outputs.handles)
                .chain(&j.outputs.preview)
                .map(file)
                .collect(),
            Job::Render(j) => {
                let out = &j.outputs.output;
                match out
                    .extension()
                    .map(|e| e.to_string_lossy().to_ascii_lowercase())
                {
                    None => vec![folder(out)],
                    Some(e) if e == "png" => vec![file(out), file(&out.with_extension("json"))],
                    Some(_) => vec![file(out)],
                }
            }
            Job::Export(j) => vec![folder(&j.outputs.folder)],
            Job::Colorize(j) => std::iter::once(file(&j.outputs.image))
                .chain(j.outputs.layers.iter().map(folder))
                .collect(),
        }
    }
}

impl RenderJobOptions {
    /// The library's render settings (the rest at their defaults).
    pub fn settings(&self) -> Result<RenderSettings, BatchError> {
        Ok(RenderSettings {
            fps: self.fps,
            scale: self.scale,
            size_px: self.size_px,
            background: self
                .background
                .as_deref()
                .map(crate::io::sequence::parse_rgba_hex)
                .transpose()
                .map_err(|e| BatchError::Options(e.to_string()))?,
            ..Default::default()
        })
    }
}

impl ExportJobOptions {
    pub fn spine(&self) -> Result<SpineOptions, BatchError> {
        Ok(SpineOptions {
            version: SpineVersion::parse(&self.spine_version)
                .map_err(|e| BatchError::Options(e.to_string()))?,
            bake_fps: self.bake_fps,
            bake: self.bake,
            ..self
                .preset
                .options_with(self.max_influences, self.max_vertices)
        })
    }
}

impl ColorizeJobOptions {
    pub fn colorize(&self) -> ColorizeOptions {
        ColorizeOptions {
            fill: self.fill,
            weights: self.weights,
            scale: self.scale,
            split: self.split,
            split_depth_exponent: self.split_depth_exponent,
            split_depth_px: self.split_depth_px,
            split_blur_px: self.split_blur_px,
            ..Default::default()
        }
    }
}

/// Parses a manifest: one object with `jobs`, each job's `kind` one of [`KINDS`], each job
/// read into its kind's type (unknown fields refused). Errors name the job by index and name.
pub fn parse(text: &str) -> Result<Manifest, BatchError> {
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| BatchError::Json(e.to_string()))?;
    let object = value
        .as_object()
        .ok_or_else(|| BatchError::Json("expected a JSON object".into()))?;
    if let Some(key) = object.keys().find(|k| *k != "jobs") {
        return Err(BatchError::Json(format!(
            "unknown field '{key}' (expected 'jobs')"
        )));
    }
    let jobs = object
        .get("jobs")
        .and_then(|j| j.as_array())
        .ok_or_else(|| BatchError::Json("expected 'jobs', an array of jobs".into()))?;
    let mut parsed = Vec::with_capacity(jobs.len());
    for (index, job) in jobs.iter().enumerate() {
        let name = job
            .get("name")
            .and_then(|n| n.as_str())
            .map(|n| format!(" ('{n}')"))
            .unwrap_or_default();
        let at = format!("job {index}{name}");
        let kind = job
            .get("kind")
            .and_then(|k| k.as_str())
            .ok_or_else(|| BatchError::Job(at.clone(), "no 'kind'".into()))?;
        if !KINDS.contains(&kind) {
            return Err(BatchError::Job(
                at,
                format!("unknown kind '{kind}' (known: {})", KINDS.join(", ")),
            ));
        }
        let job: Job =
            serde_json::from_value(job.clone()).map_err(|e| BatchError::Job(at, e.to_string()))?;
        parsed.push(job);
    }
    Ok(Manifest { jobs: parsed })
}

#[cfg(test)]
mod preset_tests {
    use super::*;

    #[test]
    fn an_export_job_reads_the_preset_and_explicit_limits_override_it() {
        let job: ExportJobOptions = serde_json::from_str(r#"{"preset": "game"}"#).unwrap();
        let game = job.spine().unwrap();
        assert_eq!(
            game.max_vertices,
            Some(crate::export::spine::GAME_PRESET_MAX_VERTICES)
        );
        assert_eq!(
            game.max_influences,
            Some(crate::export::spine::GAME_PRESET_MAX_INFLUENCES)
        );
        let job: ExportJobOptions =
            serde_json::from_str(r#"{"preset": "game", "max_vertices": 40}"#).unwrap();
        assert_eq!(job.spine().unwrap().max_vertices, Some(40));
        let full = ExportJobOptions::default().spine().unwrap();
        assert_eq!(full, SpineOptions::default());
        assert!(serde_json::from_str::<ExportJobOptions>(r#"{"preset": "tiny"}"#).is_err());
    }
}

#[cfg(test)]
mod colorize_tests {
    use super::*;

    #[test]
    fn a_colorize_job_defaults_as_the_library_and_passes_every_option_on() {
        assert_eq!(
            ColorizeJobOptions::default().colorize(),
            ColorizeOptions::default()
        );
        let job: ColorizeJobOptions = serde_json::from_str(
            r#"{"fill": "soft", "weights": "bbw", "scale": 500, "split": "density",
                "split_depth_exponent": 3, "split_depth_px": 8, "split_blur_px": 5}"#,
        )
        .unwrap();
        let options = job.colorize();
        assert_eq!(
            (options.fill, options.weights, options.scale, options.split),
            (
                FillMode::Soft,
                ColorWeights::Bbw,
                500.0,
                RegionSplit::Density
            )
        );
        assert_eq!(
            (
                options.split_depth_exponent,
                options.split_depth_px,
                options.split_blur_px
            ),
            (3.0, 8.0, 5.0)
        );
    }
}
