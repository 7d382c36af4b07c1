//! The `sinew` command: argument parsing and the thin glue from arguments to the library.
//!
//! Every failure reaches [`main`](crate) as one `anyhow` error; the binary prints it on one line
//! and exits with code 2. Outputs are computed first and written last, each atomically.

mod animate;
mod auto;
mod batch;
mod choices;
mod colorize;
mod demo_assets;
mod examples;
mod export_gltf;
pub(crate) mod out;
mod shell;
mod target;

use anyhow::{anyhow, bail, Context, Result};
use choices::{BakeModeArg, BlendArg, SchemaKindArg, SpinePresetArg, TemplateArg, WeightMethodArg};
use clap::{Args, Parser, Subcommand, ValueEnum};
use serde::Serialize;
use sinew::anim::{self, CurveEvaluation, SampleOptions};
use sinew::autorig::TemplateChoice;
use sinew::export::spine::played::ExportPlayed;
use sinew::export::spine::{self, BakeMode, SpineOptions, SpinePreset, SpineVersion};
use sinew::io::outputs::check_outputs;
use sinew::io::{self, BuildOptions, RigDocument};
use sinew::mesh::MeshOptions;
use sinew::pipeline::{self, PartReport, Scene};
use sinew::playback;
use sinew::render;
use sinew::rig::{Handles, Pose};
use sinew::schema::SchemaKind;
use sinew::skin::Blend;
use sinew::trace::TraceOptions;
use sinew::weights::{TwoLevelOptions, WeightMethod, WeightOptions};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Parser, Debug)]
#[command(
    name = "sinew",
    version,
    about = "2D cutout animation: rig your art, animate it, export it to your game",
    after_help = examples::SINEW
)]
pub struct Cli {
    /// The most memory a command may allocate, e.g. 512MiB or 8GiB (default 2GiB, or the
    /// SINEW_MEMORY_BUDGET environment variable); work beyond it is refused before it starts.
    #[arg(long, global = true, value_name = "SIZE", value_parser = parse_memory_budget)]
    pub memory_budget: Option<sinew::budget::MemoryBudget>,
    /// Print only warnings, errors and the data asked for: no reports, notes or progress bars.
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    pub quiet: bool,
    /// Also print details: each part's mesh quality and how long the command took.
    #[arg(short, long, global = true)]
    pub verbose: bool,
    #[command(subcommand)]
    pub command: Command,
}

/// The names of sinew's commands (for "did you mean").
pub fn command_names() -> Vec<String> {
    use clap::CommandFactory;
    Cli::command()
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .collect()
}

/// Bounds the thread pool `RAYON_NUM_THREADS` asks for by the machine
/// ([`sinew::budget::bounded_threads`]): a count such as 1000000 cannot start at all.
fn bound_rayon_threads() {
    let Some(asked) = std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|text| text.trim().parse::<usize>().ok())
    else {
        return;
    };
    let (threads, lowered) = sinew::budget::bounded_threads(asked);
    if lowered {
        out::note!(
            "RAYON_NUM_THREADS={asked}: this machine runs at most {threads} threads \
             ({} per core); using {threads}",
            sinew::budget::THREADS_PER_CORE
        );
        // Fails only when a pool was built already, which leaves that one.
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global();
    }
}

/// Parses `--memory-budget`.
fn parse_memory_budget(text: &str) -> Result<sinew::budget::MemoryBudget, String> {
    sinew::budget::MemoryBudget::parse(text).map_err(|e| e.to_string())
}

/// Sets the process's memory budget: `--memory-budget`, else `SINEW_MEMORY_BUDGET`, else the
/// default ([`sinew::budget`]).
fn set_memory_budget(flag: Option<sinew::budget::MemoryBudget>) -> Result<()> {
    use sinew::budget::{MemoryBudget, MEMORY_BUDGET_ENV};
    let budget = match (flag, std::env::var_os(MEMORY_BUDGET_ENV)) {
        (Some(budget), _) => budget,
        (None, None) => MemoryBudget::default(),
        (None, Some(text)) => {
            let text = text
                .to_str()
                .with_context(|| format!("{MEMORY_BUDGET_ENV} is not UTF-8"))?;
            MemoryBudget::parse(text).with_context(|| MEMORY_BUDGET_ENV.to_string())?
        }
    };
    sinew::budget::set_memory_budget(budget);
    Ok(())
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Trace, mesh and weigh images into a rig document (each image or layer a part).
    ///
    /// Layer images (PNG, all the same size) or layered files are traced, meshed and, with a
    /// handles file, given bounded biharmonic weights; parts are in draw order, back to front.
    #[command(after_help = examples::RIG)]
    Rig(RigArgs),
    /// Draw a rig in a pose (the rest pose when none is given).
    #[command(after_help = examples::POSE)]
    Pose(PoseArgs),
    /// Render an animation to numbered PNGs (a folder), a GIF or a sprite sheet.
    #[command(after_help = examples::RENDER)]
    Render(RenderArgs),
    /// Run the whole pipeline on the bundled character.
    #[command(after_help = examples::DEMO)]
    Demo(DemoArgs),
    /// Export a rig for a game runtime: Spine, glTF or DragonBones.
    #[command(after_help = examples::EXPORT)]
    Export(ExportArgs),
    /// Propose handles (a skeleton, a cage, points) from the drawing.
    #[command(after_help = examples::AUTORIG)]
    Autorig(AutorigArgs),
    /// Add an animation to a rig from motion capture, retargeted onto its bones.
    ///
    /// The motion is a clip of the bundled library (idle, walk, run, jump, jump_forward,
    /// wave) or a BVH file of your own.
    #[command(after_help = examples::ANIMATE)]
    Animate(animate::AnimateArgs),
    /// Art in, a character that moves out: rig, motions, renders and a Spine export.
    ///
    /// The automatic rig, weights, the library's motions, GIF and sprite-sheet renders and
    /// the Spine export, with a summary of what was chosen.
    #[command(after_help = examples::AUTO)]
    Auto(auto::AutoArgs),
    /// Show or set the runtime a rig plays as (pose, render and the editor follow it).
    #[command(after_help = examples::TARGET)]
    Target(target::TargetArgs),
    /// Color line art from a few colored scribbles.
    ///
    /// Each scribble's color fills the regions the lines close around it; a region holding
    /// several colors is split between them (--split).
    #[command(after_help = examples::COLORIZE)]
    Colorize(colorize::ColorizeArgs),
    /// Run the jobs of a manifest in parallel, here or on a Ray cluster.
    ///
    /// Jobs rig, autorig, render, export or colorize; a job whose inputs, options and sinew
    /// version are unchanged since its last success is skipped.
    #[command(after_help = examples::BATCH)]
    Batch(batch::BatchArgs),
    /// Print the JSON Schema of a file sinew reads (see docs/formats.md).
    #[command(after_help = examples::SCHEMA)]
    Schema(SchemaArgs),
    /// Open the editor window: rig, weigh, pose, animate and colorize by hand.
    #[cfg(feature = "editor")]
    #[command(after_help = examples::EDIT)]
    Edit(EditArgs),
    /// Print the completion script of a shell (bash, zsh, fish, elvish, powershell).
    #[command(after_help = examples::COMPLETIONS)]
    Completions(shell::CompletionsArgs),
    /// Print the man page sinew(1), or write a page per command into a folder (-o DIR).
    #[command(after_help = examples::MAN)]
    Man(shell::ManArgs),
}

/// `sinew edit [RIG]`.
#[cfg(feature = "editor")]
#[derive(Args, Debug)]
pub struct EditArgs {
    /// The rig to open; none starts an empty document (drop PNG layers on the window).
    pub rig: Option<PathBuf>,
    /// The mode to start in (default: the one the rig's saved view was left in, else rig).
    #[arg(long, value_enum)]
    pub mode: Option<EditMode>,
    /// A pose to start with (pose mode).
    #[arg(long)]
    pub pose: Option<PathBuf>,
    /// Take a PNG screenshot of the window after its first frames, then quit.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// A handle to select first (rig mode shows its weights).
    #[arg(long)]
    pub select: Option<String>,
    /// Open animate mode's graph view (every curve of the selected handle) at start.
    #[arg(long)]
    pub graph_view: bool,
    /// Line art (PNG) to open in colorize mode.
    #[arg(long)]
    pub line_art: Option<PathBuf>,
    /// Scribbles to draw on the line art (the JSON of `sinew colorize --scribbles`).
    #[arg(long, requires = "line_art")]
    pub scribbles: Option<PathBuf>,
    /// Append every frame's times to this file (tab-separated, ms: the editor's own code, the
    /// whole frame with the GL draw, the interval since the frame before), for benchmarks.
    #[arg(long)]
    pub frame_log: Option<PathBuf>,
}

#[cfg(feature = "editor")]
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum EditMode {
    Rig,
    Pose,
    Animate,
    Colorize,
}

/// `sinew schema KIND`.
#[derive(Args, Debug)]
pub struct SchemaArgs {
    /// The file whose schema to print.
    #[arg(value_parser = choices::parser::<SchemaKindArg, SchemaKind>())]
    pub kind: SchemaKind,
}

#[derive(Args, Debug)]
pub struct ExportArgs {
    #[command(subcommand)]
    pub format: ExportFormat,
}

#[derive(Subcommand, Debug)]
pub enum ExportFormat {
    /// Spine skeleton JSON, .atlas and page PNGs, for the Spine runtimes.
    ///
    /// Writes DIR/NAME.json, DIR/NAME.atlas and DIR/NAME.png.
    #[command(after_help = examples::EXPORT_SPINE)]
    Spine(SpineArgs),
    /// Binary glTF 2.0 (.glb), for Godot, Bevy, Unity, Blender and three.js.
    ///
    /// Skinned meshes, their textures and the animations baked on frames, in one file.
    #[command(after_help = examples::EXPORT_GLTF)]
    Gltf(export_gltf::GltfArgs),
    /// DragonBones 5.5 JSON and texture atlas, for Cocos, Egret, Pixi and Phaser.
    ///
    /// Writes DIR/NAME_ske.json, DIR/NAME_tex.json and DIR/NAME_tex.png; every motion is
    /// baked on the armature's frames.
    #[command(after_help = examples::EXPORT_DRAGONBONES)]
    Dragonbones(export_gltf::DragonBonesArgs),
}

#[derive(Args, Debug)]
pub struct SpineArgs {
    /// The rig document (every part must have weights).
    pub rig: PathBuf,
    /// The folder to write into (created if missing).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Spine editor line to write for: 4.2 (or 4.1, or 4.3).
    #[arg(long, default_value = SpineVersion::default().name())]
    pub spine_version: String,
    /// Keys per second for motion Spine cannot express natively (baked).
    #[arg(long, default_value_t = SpineOptions::default().bake_fps)]
    pub fps: f64,
    /// full: every vertex and influence; game: meshes decimated to 250 vertices per part and
    /// at most 4 influences per vertex (the two options below override the preset's).
    #[arg(long, value_parser = choices::parser::<SpinePresetArg, SpinePreset>(), default_value = choices::default_name!(SpinePresetArg, SpinePreset::default()))]
    pub preset: SpinePreset,
    #[arg(long, value_name = "K", help = format!("Keep the K strongest weights per vertex, \
        renormalized (default: the preset's; full keeps all, game {})", spine::GAME_PRESET_MAX_INFLUENCES))]
    pub max_influences: Option<usize>,
    #[arg(long, value_name = "N", help = format!("Decimate each part's mesh to at most N \
        vertices, weights carried from the fine mesh (default: the preset's; full keeps all, \
        game {})", spine::GAME_PRESET_MAX_VERTICES))]
    pub max_vertices: Option<usize>,
    /// auto: bake only what native timelines cannot express; all: bake every bone.
    #[arg(long, value_parser = choices::parser::<BakeModeArg, BakeMode>(), default_value = choices::default_name!(BakeModeArg, SpineOptions::default().bake))]
    pub bake: BakeMode,
    /// Base name of the files (default: the rig file's name).
    #[arg(long)]
    pub name: Option<String>,
}

/// A runtime whose playback `--match-runtime` reproduces.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq)]
pub enum RuntimeMatch {
    /// Spine's official runtimes: f32 keys, each Bézier key as a 10-segment polyline.
    Spine,
    /// The DragonBones runtimes playing `sinew export dragonbones`'s frames (default options).
    Dragonbones,
    /// A glTF runtime playing `sinew export gltf`'s baked keys (default options).
    Gltf,
}

fn sample_options(runtime: Option<RuntimeMatch>) -> SampleOptions {
    SampleOptions {
        curves: match runtime {
            Some(RuntimeMatch::Spine) => CurveEvaluation::SpineRuntime,
            _ => CurveEvaluation::Exact,
        },
    }
}

/// The baked runtime `--match-runtime` names, if it names one.
fn baked_runtime(runtime: Option<RuntimeMatch>) -> Option<playback::BakedRuntime> {
    match runtime {
        Some(RuntimeMatch::Dragonbones) => Some(playback::BakedRuntime::Dragonbones),
        Some(RuntimeMatch::Gltf) => Some(playback::BakedRuntime::Gltf),
        Some(RuntimeMatch::Spine) | None => None,
    }
}

/// The export `--match-runtime spine` reproduces.
fn export_played(spine_version: &str, bake_fps: f64) -> Result<ExportPlayed> {
    Ok(ExportPlayed {
        version: SpineVersion::parse(spine_version)?,
        bake_fps,
    })
}

#[derive(Args, Debug)]
pub struct AutorigArgs {
    /// Layer images (PNG, all the same size) or layered files (.psd, .psb, .ora, or the .json
    /// of a Spine export script beside its PNGs), back to front.
    #[arg(required = true)]
    pub images: Vec<PathBuf>,
    /// The handles file to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// At most this many bones (default: the template's budget, humanoid 20, quadruped 25,
    /// 25 without a template).
    #[arg(long, value_name = "N")]
    pub bones: Option<usize>,
    /// Also propose a cage of at most N vertices (default: no cage).
    #[arg(long, value_name = "N")]
    pub cage: Option<usize>,
    /// Also propose N point handles.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub points: usize,
    /// The skeleton to fit, naming and parenting its limbs (auto: from the layer names, else
    /// the drawing's shape; the choice and its reason are printed).
    #[arg(long, value_parser = choices::parser::<TemplateArg, TemplateChoice>(),
          default_value = choices::default_name!(TemplateArg, TemplateChoice::default()))]
    pub template: TemplateChoice,
    /// Also draw the proposed rig over the images as a PNG.
    #[arg(long)]
    pub preview: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The rig document.
    pub rig: PathBuf,
    /// The animation to play.
    #[arg(long)]
    pub anim: String,
    /// Frames per second.
    #[arg(long, default_value_t = playback::DEFAULT_RENDER_FPS)]
    pub fps: f64,
    /// Output px per canvas px.
    #[arg(long, default_value_t = playback::RenderSettings::default().scale)]
    pub scale: f64,
    /// Output size WxH in px (default: the scaled canvas); the canvas is centered in it.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<[u32; 2]>,
    /// Background color #rrggbb or #rrggbbaa (default: transparent).
    #[arg(long)]
    pub background: Option<String>,
    /// How handle transformations blend.
    #[arg(long, value_parser = choices::parser::<BlendArg, Blend>(), default_value = choices::default_name!(BlendArg, playback::RenderSettings::default().blend))]
    pub blend: Blend,
    /// Play as this runtime plays the export of its format instead of exactly (default: the
    /// rig's target runtime, which `sinew target` sets).
    #[arg(long, value_enum)]
    pub match_runtime: Option<RuntimeMatch>,
    /// Play exactly, even when the rig names a target runtime.
    #[arg(long, conflicts_with = "match_runtime")]
    pub exact: bool,
    /// With --match-runtime spine: the Spine line the export was written for (`sinew export spine
    /// --spine-version`): 4.2 (or 4.1, whose export bakes physics, or 4.3).
    #[arg(long, default_value = SpineVersion::default().name(), requires = "match_runtime")]
    pub spine_version: String,
    /// With --match-runtime spine: the export's keys per second of baked motion (`sinew export spine
    /// --fps`).
    #[arg(long, default_value_t = SpineOptions::default().bake_fps, requires = "match_runtime")]
    pub bake_fps: f64,
    /// Draw with this skin (a rig's `skins`: see docs/formats.md, "Rig document"); repeat to
    /// combine skins, a later one overriding an earlier one on the same slot.
    #[arg(long = "skin", value_name = "NAME")]
    pub skins: Vec<String>,
    /// Where to write: a folder (no extension), OUT.gif, or OUT.png (a sprite sheet, with
    /// OUT.json beside it, which lists each frame's events).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also print the events each frame fires, one JSON object a line:
    /// {"frame", "frame_time", "event": {"name", "time", "int", "float", "string", ...}}.
    #[arg(long)]
    pub events: bool,
}

/// Parses `WxH` (px).
fn parse_size(text: &str) -> Result<[u32; 2], String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{text}' is not WxH"))?;
    let side = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| format!("'{text}' is not WxH with positive whole numbers"))
    };
    Ok([side(w)?, side(h)?])
}

#[derive(Args, Debug)]
pub struct RigArgs {
    /// Layer images (PNG, all the same size) or layered files (.psd, .psb, .ora, or the .json
    /// of a Spine export script beside its PNGs), back to front.
    #[arg(required = true)]
    pub images: Vec<PathBuf>,
    /// The rig document to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write the mesh wireframe over the sprites as a PNG.
    #[arg(long)]
    pub preview: Option<PathBuf>,
    /// Write the rig document indented, one value per line (default: compact).
    #[arg(long)]
    pub pretty: bool,
    /// The handles file (bones, points, cages, regions); with it, weights are computed.
    #[arg(long)]
    pub handles: Option<PathBuf>,
    /// Make layer PART another attachment of layer SLOT's slot (repeatable; see docs/formats.md,
    /// "Rig document": `slot`).
    #[arg(long = "attachment", value_name = "PART=SLOT", value_parser = parse_attachment)]
    pub attachments: Vec<(String, String)>,
    #[command(flatten)]
    pub build: BuildArgs,
}

/// The help of a tracing or meshing flag of `sinew rig`: `text` and its defaults for `--detail
/// fine` and `--detail coarse`, read from the library's options.
fn tuning_help(text: &str, default: impl Fn(&TraceOptions, &MeshOptions) -> String) -> String {
    let fine = default(&TraceOptions::default(), &MeshOptions::default());
    let coarse = default(&TraceOptions::coarse(), &MeshOptions::coarse());
    format!("{text} [default: {fine}; with --detail coarse: {coarse}]")
}

/// Parses `PART=SLOT`.
fn parse_attachment(text: &str) -> Result<(String, String), String> {
    match text.split_once('=') {
        Some((part, slot)) if !part.is_empty() && !slot.is_empty() => {
            Ok((part.to_string(), slot.to_string()))
        }
        _ => Err(format!("'{text}' is not PART=SLOT")),
    }
}

/// Tracing and meshing parameters; each defaults to the library's default.
#[derive(Args, Debug)]
pub struct BuildArgs {
    /// fine: quality mesh for skinning; coarse: few vertices, for game runtimes.
    #[arg(long, value_enum, default_value_t = Detail::Fine)]
    pub detail: Detail,
    #[arg(long, help = tuning_help("A pixel is opaque from this alpha on (0–255)", |t, _| t.alpha_threshold.to_string()))]
    pub alpha_threshold: Option<u8>,
    #[arg(long, help = tuning_help("Outward padding of the outline, px", |t, _| t.padding_px.to_string()))]
    pub padding: Option<f64>,
    #[arg(long, help = tuning_help("Outline simplification tolerance, px", |t, _| t.simplify_tolerance_px.to_string()))]
    pub simplify: Option<f64>,
    #[arg(long, help = tuning_help("Smallest triangle angle refinement aims for, degrees", |_, m| m.min_angle_deg.to_string()))]
    pub min_angle: Option<f64>,
    #[arg(long, help = tuning_help("Largest triangle area as a fraction of the canvas area", |_, m| m.max_area_fraction.to_string()))]
    pub max_area_fraction: Option<f64>,
    /// The weights' energy.
    #[arg(long = "weights", value_parser = choices::parser::<WeightMethodArg, WeightMethod>(), default_value = choices::default_name!(WeightMethodArg, WeightOptions::default().method))]
    pub weight_method: WeightMethod,
    /// Content-aware weights: measure color changes as this many px (default: off).
    #[arg(long, value_name = "S")]
    pub content_aware: Option<f64>,
    /// Keep the K largest weights per vertex (default: all).
    #[arg(long, value_name = "K")]
    pub max_influences: Option<usize>,
    /// Monotone bounded biharmonic weights: no spurious local extrema (slower).
    #[arg(long)]
    pub monotone: bool,
    /// With `--weights rigid`: width of the blend band around joints, px.
    #[arg(long = "blend", value_name = "PX", default_value_t = WeightOptions::default().rigid_blend_px)]
    pub rigid_blend_px: f64,
    /// Two-level weights: solve on a coarse mesh of about N vertices of the same domain, carry
    /// the weights to the fine mesh and polish them there (faster on large meshes; see
    /// docs/two-level-weights.md for how far they are from the exact solve). Default: off,
    /// the exact solve on the fine mesh.
    #[arg(long, value_name = "N")]
    pub coarse_weights: Option<usize>,
}

#[derive(ValueEnum, Clone, Copy, Debug, Default, PartialEq)]
pub enum Detail {
    #[default]
    Fine,
    Coarse,
}

impl BuildArgs {
    /// The options of the flags, checked: a value out of range is refused naming its flag.
    fn checked_options(&self) -> Result<BuildOptions> {
        let options = self.options();
        let flag_of = |field: &'static str| match field {
            "alpha_threshold" => "--alpha-threshold",
            "padding_px" => "--padding",
            "simplify_tolerance_px" => "--simplify",
            "min_angle_deg" => "--min-angle",
            "max_area_fraction" => "--max-area-fraction",
            other => other,
        };
        if let Err(sinew::trace::TraceError::InvalidOption { field, rule }) =
            sinew::trace::check_options(&options.trace)
        {
            anyhow::bail!("{} {rule}", flag_of(field));
        }
        if let Err(sinew::mesh::MeshError::InvalidOption { field, rule }) = options.mesh.check() {
            anyhow::bail!("{} {rule}", flag_of(field));
        }
        Ok(options)
    }

    fn options(&self) -> BuildOptions {
        let (mut trace, mut mesh) = match self.detail {
            Detail::Fine => (TraceOptions::default(), MeshOptions::default()),
            Detail::Coarse => (TraceOptions::coarse(), MeshOptions::coarse()),
        };
        if let Some(v) = self.alpha_threshold {
            trace.alpha_threshold = v;
        }
        if let Some(v) = self.padding {
            trace.padding_px = v;
        }
        if let Some(v) = self.simplify {
            trace.simplify_tolerance_px = v;
        }
        if let Some(v) = self.min_angle {
            mesh.min_angle_deg = v;
        }
        if let Some(v) = self.max_area_fraction {
            mesh.max_area_fraction = v;
        }
        let weights = WeightOptions {
            method: self.weight_method,
            content_aware: self.content_aware,
            max_influences: self.max_influences,
            monotone: self.monotone,
            rigid_blend_px: self.rigid_blend_px,
            two_level: self.coarse_weights.map(|n| TwoLevelOptions {
                coarse_vertices: n,
                ..TwoLevelOptions::default()
            }),
            ..WeightOptions::default()
        };
        BuildOptions {
            trace,
            mesh,
            weights,
            ik: sinew::ik::IkOptions::default(),
        }
    }
}

#[derive(Args, Debug)]
pub struct PoseArgs {
    /// The rig document.
    pub rig: PathBuf,
    /// The image to write (PNG).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also write the posed vertices of every part as JSON.
    #[arg(long)]
    pub vertices: Option<PathBuf>,
    /// The pose file (bone rotations, point moves, cage polygons).
    #[arg(long, conflicts_with = "anim")]
    pub pose: Option<PathBuf>,
    /// Pose from this animation of the rig document, at `--time`.
    #[arg(long)]
    pub anim: Option<String>,
    /// Seconds into `--anim` (looping past its end). Default 0.
    #[arg(long, requires = "anim", allow_negative_numbers = true)]
    pub time: Option<f64>,
    /// How handle transformations blend: linear (LBS), dqs (dual quaternions) or stretch
    /// (LBS with stretchable bones).
    #[arg(long, value_parser = choices::parser::<BlendArg, Blend>(), default_value = choices::default_name!(BlendArg, Blend::default()))]
    pub blend: Blend,
    /// With --anim: play as this runtime plays the export of its format instead of exactly
    /// (default: the rig's target runtime, `sinew target`).
    #[arg(long, value_enum, requires = "anim")]
    pub match_runtime: Option<RuntimeMatch>,
    /// With --anim: play exactly, even when the rig names a target runtime.
    #[arg(long, requires = "anim", conflicts_with = "match_runtime")]
    pub exact: bool,
    /// With --match-runtime spine: the Spine line the export was written for (`sinew export spine
    /// --spine-version`): 4.2 (or 4.1, whose export bakes physics, or 4.3).
    #[arg(long, default_value = SpineVersion::default().name(), requires = "match_runtime")]
    pub spine_version: String,
    /// With --match-runtime spine: the export's keys per second of baked motion (`sinew export spine
    /// --fps`).
    #[arg(long, default_value_t = SpineOptions::default().bake_fps, requires = "match_runtime")]
    pub bake_fps: f64,
    /// Draw with this skin (a rig's `skins`: see docs/formats.md, "Rig document"); repeat to
    /// combine skins, a later one overriding an earlier one on the same slot.
    #[arg(long = "skin", value_name = "NAME")]
    pub skins: Vec<String>,
}

#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder.
    #[arg(short, long, default_value = "out")]
    pub output: PathBuf,
    /// A character laid out as the bundled one (layers.json, handles.json, animations.json,
    /// events.json if it fires any, a PNG per layer and attachment) instead of the bundled
    /// character, which is built into sinew.
    #[arg(long, value_name = "DIR")]
    pub assets: Option<PathBuf>,
}

/// Runs one parsed command.
pub fn run(cli: Cli) -> Result<()> {
    out::set(cli.quiet, cli.verbose);
    set_memory_budget(cli.memory_budget)?;
    bound_rayon_threads();
    let started = Instant::now();
    run_command(cli.command)?;
    out::detail!("done in {:.2} s", started.elapsed().as_secs_f64());
    Ok(())
}

fn run_command(command: Command) -> Result<()> {
    match command {
        Command::Rig(args) => rig(&args),
        Command::Pose(args) => pose(&args),
        Command::Render(args) => render_animation(&args),
        Command::Demo(args) => demo(&args),
        Command::Export(ExportArgs {
            format: ExportFormat::Spine(args),
        }) => export_spine(&args),
        Command::Export(ExportArgs {
            format: ExportFormat::Gltf(args),
        }) => export_gltf::run(&args),
        Command::Export(ExportArgs {
            format: ExportFormat::Dragonbones(args),
        }) => export_gltf::run_dragonbones(&args),
        Command::Autorig(args) => autorig(&args),
        Command::Animate(args) => animate::run(&args),
        Command::Auto(args) => auto::run(&args),
        Command::Target(args) => target::run(&args),
        Command::Colorize(args) => colorize::run(&args),
        Command::Batch(args) => batch::run(&args),
        Command::Schema(args) => print_schema(&args),
        Command::Completions(args) => shell::completions(&args),
        Command::Man(args) => shell::man(&args),
        #[cfg(feature = "editor")]
        Command::Edit(args) => edit(&args),
    }
}

#[cfg(feature = "editor")]
fn edit(args: &EditArgs) -> Result<()> {
    use sinew::editor::Mode;
    let pose = match &args.pose {
        Some(path) => Some(read_json::<sinew::rig::Pose>(path, "pose file")?),
        None => None,
    };
    let mode = args.mode.map(|m| match m {
        EditMode::Rig => Mode::Rig,
        EditMode::Pose => Mode::Pose,
        EditMode::Animate => Mode::Animate,
        EditMode::Colorize => Mode::Colorize,
    });
    sinew::editor::run(sinew::editor::Start {
        rig: args.rig.clone(),
        mode,
        pose,
        select: args.select.clone(),
        screenshot: args.screenshot.clone(),
        graph_view: args.graph_view,
        line_art: args.line_art.clone(),
        scribbles: args.scribbles.clone(),
        frame_log: args.frame_log.clone(),
    })
}

/// Prints the JSON Schema of a file kind on stdout (a reader that stops early, `| head`, is no
/// error).
fn print_schema(args: &SchemaArgs) -> Result<()> {
    use std::io::Write;
    let text = serde_json::to_string_pretty(&sinew::schema::schema(args.kind))? + "\n";
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(e).context("cannot write the schema to stdout")
        }
        _ => Ok(()),
    }
}

fn autorig(args: &AutorigArgs) -> Result<()> {
    use sinew::autorig::AutorigOptions;
    let mut options = AutorigOptions {
        template: args.template,
        cage_vertices: args.cage,
        point_count: args.points,
        ..AutorigOptions::default()
    };
    options.skeleton.max_bones = args.bones;
    let files = sinew::jobs::AutorigFiles {
        images: args.images.clone(),
        output: args.output.clone(),
        preview: args.preview.clone(),
    };
    let (proposal, notes) = sinew::jobs::autorig_files(&files, &options)?;
    print_notes(&notes);
    let h = &proposal.handles;
    out::report!(
        "{}: {} bones, {} points, {} cages",
        args.output.display(),
        h.bones.len(),
        h.points.len(),
        h.cages.len()
    );
    // The template line first and unindented: what the proposal follows, and why.
    let (chosen, rest): (Vec<&String>, Vec<&String>) = proposal
        .notes
        .iter()
        .partition(|n| n.starts_with("template: "));
    match chosen.first() {
        Some(line) => out::report!("{line}"),
        None => out::report!(
            "template: {}",
            sinew::autorig::template_name(proposal.template)
        ),
    }
    for note in rest {
        out::report!("  {note}");
    }
    Ok(())
}

/// The notes on layers skipped or drawn differently.
fn print_notes(notes: &[String]) {
    for note in notes {
        out::report!("note: {note}");
    }
}

/// Reads a JSON file that must hold one object into `T`, naming the file in every error.
fn read_json<T: serde::de::DeserializeOwned>(path: &Path, what: &str) -> Result<T> {
    Ok(sinew::jobs::read_json(path, what)?)
}

fn rig(args: &RigArgs) -> Result<()> {
    let files = sinew::jobs::RigFiles {
        images: args.images.clone(),
        handles: args.handles.clone(),
        attachments: args.attachments.iter().cloned().collect(),
        output: args.output.clone(),
        preview: args.preview.clone(),
        layout: if args.pretty {
            io::JsonLayout::Pretty
        } else {
            io::JsonLayout::Compact
        },
    };
    // Parts done (a layered file holds several), each traced, meshed and weighed.
    let bar = out::bar("rigging", "parts");
    let options = args.build.checked_options()?;
    let done = sinew::jobs::rig_files(&files, &options, &mut |done, total, name| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
        bar.set_message(name.to_string());
    });
    bar.finish_and_clear();
    let done = done.map_err(|e| match e {
        sinew::jobs::JobError::Attachment(reason) => anyhow!("--attachment: {reason}"),
        e => e.into(),
    })?;
    print_notes(&done.notes);
    for (part, s) in done.doc.parts.iter().zip(&done.stats) {
        report_part(&part.name, s);
    }
    Ok(())
}

fn report_part(name: &str, r: &PartReport) {
    let s = &r.mesh;
    out::report!("{name}: {} vertices, {} triangles", s.vertices, s.triangles);
    out::detail!(
        "  {name}: smallest triangle angle {:.1}° (skinning deforms thin triangles badly; \
         --min-angle sets what refinement aims for, outlines narrower than a triangle keep \
         thinner ones)",
        s.min_angle_deg
    );
    if !r.bound_to_nearest.is_empty() {
        eprintln!(
            "sinew: warning: part '{name}': {} mesh vertices lie on pieces no handle reaches: they follow the nearest handle rigidly ({})",
            r.bound_vertices,
            r.bound_to_nearest.join(", ")
        );
    }
    if !r.unconverged.is_empty() {
        eprintln!(
            "sinew: warning: part '{name}': the weights of {} stopped at the solver's iteration limit (accurate to about 1e-3)",
            r.unconverged.join(", ")
        );
    }
}

/// The rest pose on white with every part's wireframe on top.
fn preview_image(scene: &Scene) -> Result<image::RgbaImage> {
    Ok(sinew::jobs::preview_image(scene)?)
}

fn pose(args: &PoseArgs) -> Result<()> {
    if args.output.is_none() && args.vertices.is_none() {
        bail!("nothing to write: give -o OUT.png and/or --vertices V.json");
    }
    let scene = sinew::jobs::scene_with_skins(&args.rig, &args.skins)?;
    let images = sinew::jobs::part_images(&args.rig, &scene.doc);
    check_outputs(
        [Some(args.rig.as_path()), args.pose.as_deref()]
            .into_iter()
            .flatten()
            .chain(images.iter().map(PathBuf::as_path)),
        [args.output.as_deref(), args.vertices.as_deref()],
    )?;
    if args.output.is_some() {
        playback::check_pose_memory(scene.doc.canvas)?;
    }
    let (pose, transforms) = match (&args.pose, &args.anim) {
        (Some(path), _) => {
            let pose: Pose = read_json(path, "pose file")?;
            scene.doc.check_pose_attachments(&pose)?;
            let transforms = scene.handle_transforms(&pose)?;
            (pose, transforms)
        }
        (None, Some(name)) => {
            let time_s = args.time.unwrap_or(0.0);
            if !time_s.is_finite() {
                bail!("--time must be a finite number of seconds");
            }
            let animation = sinew::jobs::animation_in(&scene.doc, &args.rig, name)?;
            let mut settings = playback::RenderSettings {
                sampling: sample_options(args.match_runtime),
                export: export_played(&args.spine_version, args.bake_fps)?,
                baked_runtime: baked_runtime(args.match_runtime),
                ..Default::default()
            };
            if let Some(target) = scene.doc.target {
                if args.match_runtime.is_none() && !args.exact {
                    settings = settings.playing_as(target);
                }
            }
            let frame = playback::play(&scene, name, &animation, &[time_s], true, &settings)?
                .pop()
                .context("no frame")?;
            (frame.pose, frame.transforms)
        }
        (None, None) => (Pose::default(), scene.handle_transforms(&Pose::default())?),
    };
    let positions = scene.positions_from_transforms(&transforms, &pose, args.blend)?;
    let image = match &args.output {
        Some(_) => Some(playback::render_posed(&scene, &positions, &pose)?),
        None => None,
    };
    let vertices = match &args.vertices {
        Some(_) => Some(vertices_json(&scene.doc, &positions)?),
        None => None,
    };
    if let (Some(path), Some(image)) = (&args.output, image) {
        io::save_png(path, &image)?;
    }
    if let (Some(path), Some(text)) = (&args.vertices, vertices) {
        io::write_atomic(path, text.as_bytes())
            .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    Ok(())
}

fn render_animation(args: &RenderArgs) -> Result<()> {
    let settings = playback::RenderSettings {
        fps: args.fps,
        scale: args.scale,
        size_px: args.size,
        background: args
            .background
            .as_deref()
            .map(io::sequence::parse_rgba_hex)
            .transpose()?,
        blend: args.blend,
        sampling: sample_options(args.match_runtime),
        export: export_played(&args.spine_version, args.bake_fps)?,
        baked_runtime: baked_runtime(args.match_runtime),
    };
    let files = sinew::jobs::RenderFiles {
        rig: args.rig.clone(),
        animation: args.anim.clone(),
        skins: args.skins.clone(),
        output: args.output.clone(),
        follow_target: args.match_runtime.is_none() && !args.exact,
    };
    // The frame count is known inside the job, and told with every frame drawn.
    let bar = out::bar("rendering", "frames");
    // Drawn and written a chunk of frames at a time: any length renders in bounded memory.
    let written = sinew::jobs::render_files(&files, &settings, &|total| {
        bar.set_length(total as u64);
        bar.inc(1);
    });
    bar.finish_and_clear();
    let sinew::jobs::RenderDone {
        report,
        events,
        frame_times_s,
    } = written?;
    if args.events {
        for (frame, (fired, time)) in events.iter().zip(frame_times_s).enumerate() {
            for event in fired {
                let line = serde_json::json!({"frame": frame, "frame_time": time, "event": event});
                println!("{line}");
            }
        }
    }
    // With --events, stdout holds only the event lines.
    let summary = format!(
        "{}: {} frames of {}×{} px, {:.2} s",
        args.output.display(),
        report.frame_count,
        report.frame_size_px.0,
        report.frame_size_px.1,
        report.duration_s
    );
    if args.events {
        if !out::quiet() {
            eprintln!("{summary}");
        }
    } else {
        out::report!("{summary}");
    }
    Ok(())
}

/// The `--vertices` file of docs/formats.md.
fn vertices_json(doc: &RigDocument, positions: &[Vec<sinew::geom::Point>]) -> Result<String> {
    #[derive(Serialize)]
    struct Part<'a> {
        name: &'a str,
        vertices: &'a [sinew::geom::Point],
        triangles: &'a [[u32; 3]],
    }
    #[derive(Serialize)]
    struct Posed<'a> {
        parts: Vec<Part<'a>>,
    }
    let parts = doc
        .parts
        .iter()
        .zip(positions)
        .map(|(p, pos)| Part {
            name: &p.name,
            vertices: pos,
            triangles: &p.mesh.triangles,
        })
        .collect();
    Ok(serde_json::to_string(&Posed { parts })? + "\n")
}

/// The bundled character's layer list: layers in draw order, other attachments of their slots
/// (image name → slot), skins.
#[derive(serde::Deserialize)]
struct LayerList {
    layers: Vec<String>,
    #[serde(default)]
    attachments: std::collections::BTreeMap<String, String>,
    #[serde(default)]
    skins: io::Skins,
}

fn demo(args: &DemoArgs) -> Result<()> {
    let created = !args.output.exists();
    let result = demo_steps(args);
    // A run that failed before writing anything leaves no empty folder behind (remove_dir only
    // removes an empty one).
    if result.is_err() && created {
        // The layers it copied first go with it (the folder is its own: it made it).
        let _ = std::fs::remove_dir_all(args.output.join("character.parts"));
        let _ = std::fs::remove_dir(&args.output);
    }
    result
}

fn demo_steps(args: &DemoArgs) -> Result<()> {
    let started = Instant::now();
    let assets = demo_assets::DemoAssets::new(args.assets.as_deref());
    let list_name = assets.name("layers.json");
    let list: LayerList = serde_json::from_slice(&assets.read("layers.json")?)
        .with_context(|| format!("{list_name}: not a layer list"))?;
    let files: Vec<String> = list
        .layers
        .iter()
        .chain(list.attachments.keys())
        .map(|name| format!("{name}.png"))
        .collect();
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("{}: cannot create folder", args.output.display()))?;
    // The layers copied beside the rig (`character.parts/`), which names them there: a rig
    // names only files inside its folder (batches refuse images outside their manifest's).
    let parts_dir = args.output.join("character.parts");
    std::fs::create_dir_all(&parts_dir)
        .with_context(|| format!("{}: cannot create folder", parts_dir.display()))?;
    let mut copies = Vec::with_capacity(files.len());
    for file in &files {
        let copy = parts_dir.join(file);
        let bytes = assets.read(file)?;
        io::write_atomic(&copy, &bytes)
            .with_context(|| format!("{}: cannot write", copy.display()))?;
        copies.push(copy);
    }
    let paths = copies;

    let t = Instant::now();
    let layers = pipeline::load_layers(&paths)?;
    let load_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let handles: Handles = assets.read_json("handles.json", "handles file")?;
    let (doc, stats) =
        pipeline::build_rig(&layers, &args.output, &BuildOptions::default(), &handles)?;
    let rig_s = t.elapsed().as_secs_f64();

    let mut doc = doc;
    doc.set_slots(&list.attachments, list.skins.clone())
        .map_err(|reason| anyhow::anyhow!("{list_name}: {reason}"))?;
    let animations_name = assets.name("animations.json");
    let animations_json: serde_json::Value =
        assets.read_json("animations.json", "animations file")?;
    let bad = || format!("{animations_name}: bad animation");
    doc.animations = anim::animations_from_json(&animations_json).with_context(bad)?;
    // The events the animations fire (footsteps), when the assets define any.
    if assets.read_optional("events.json")?.is_some() {
        let events_json: serde_json::Value = assets.read_json("events.json", "events file")?;
        doc.events = anim::events_from_json(&events_json)
            .with_context(|| format!("{}: bad events", assets.name("events.json")))?;
    }
    doc.check_animations().with_context(bad)?;
    let animations = doc.animations.clone();
    let rig_path = args.output.join("character.json");
    doc.save(&rig_path)?;
    let mut written = vec![rig_path];

    let t = Instant::now();
    let images: Vec<_> = layers.iter().map(|l| l.image.clone()).collect();
    let mut scene = Scene::new(doc.clone(), &images)?;
    let rest = render::rgba_from_pixmap(&scene.render(&scene.rest_positions())?);
    let rest_s = t.elapsed().as_secs_f64();
    let rest_path = args.output.join("rest.png");
    io::save_png(&rest_path, &rest)?;
    // Each skin at rest too (`rest_SKIN.png`); the animations play in the default skin.
    for skin in doc.skins.keys() {
        scene.set_skins(std::slice::from_ref(skin))?;
        let image = render::rgba_from_pixmap(&scene.render(&scene.rest_positions())?);
        let path = args.output.join(format!("rest_{skin}.png"));
        io::save_png(&path, &image)?;
        written.push(path);
    }
    scene.set_skins(&[])?;
    let preview_path = args.output.join("mesh.png");
    io::save_png(&preview_path, &preview_image(&scene)?)?;
    written.extend([rest_path, preview_path]);

    let t = Instant::now();
    let export = spine::export_spine(&scene, &images, "character", &SpineOptions::default())?;
    written.extend(export.write(&args.output.join("spine"))?);
    let spine_s = t.elapsed().as_secs_f64();

    let mut render_s = 0.0;
    let mut write_s = 0.0;
    let mut frame_count = 0;
    for (name, animation) in &animations {
        let t = Instant::now();
        let settings = playback::RenderSettings {
            fps: DEMO_FPS,
            ..Default::default()
        };
        let frames = playback::render_animation(&scene, name, animation, &settings, &|| {})?;
        let events = playback::render_events(&scene, animation, &settings)?;
        render_s += t.elapsed().as_secs_f64();
        frame_count += frames.len();
        let t = Instant::now();
        for target in [
            args.output.join(format!("{name}.gif")),
            args.output.join(format!("{name}.png")),
            args.output.join(name),
        ] {
            let report = io::sequence::write_sequence(
                &frames,
                &events,
                DEMO_FPS,
                &target,
                &Default::default(),
            )?;
            if report.format == io::sequence::SequenceFormat::Folder {
                written.push(target);
            } else {
                written.extend(report.files);
            }
        }
        write_s += t.elapsed().as_secs_f64();
    }

    let (v, t_count): (usize, usize) = stats.iter().fold((0, 0), |a, s| {
        (a.0 + s.mesh.vertices, a.1 + s.mesh.triangles)
    });
    out::report!(
        "sinew demo: {} parts, {v} vertices, {t_count} triangles; animations {}",
        doc.parts.len(),
        animations.keys().cloned().collect::<Vec<_>>().join(", ")
    );
    out::report!("  load images   {:>8.1} ms", load_s * 1e3);
    out::report!(
        "  rig           {:>8.1} ms (trace, mesh, weights)",
        rig_s * 1e3
    );
    out::report!("  rest pose     {:>8.1} ms", rest_s * 1e3);
    out::report!("  spine export  {:>8.1} ms", spine_s * 1e3);
    out::report!(
        "  animate       {:>8.1} ms ({frame_count} frames at {DEMO_FPS} fps, sampled and rendered)",
        render_s * 1e3
    );
    out::report!(
        "  write         {:>8.1} ms (GIFs, sheets, frames)",
        write_s * 1e3
    );
    for path in &written {
        out::report!("  wrote {}", path.display());
    }
    out::report!(
        "  total         {:>8.1} ms",
        started.elapsed().as_secs_f64() * 1e3
    );
    Ok(())
}

fn export_spine(args: &SpineArgs) -> Result<()> {
    let options = SpineOptions {
        version: SpineVersion::parse(&args.spine_version)?,
        bake_fps: args.fps,
        bake: args.bake,
        ..args
            .preset
            .options_with(args.max_influences, args.max_vertices)
    };
    let (export, written) =
        sinew::jobs::export_spine_files(&args.rig, &args.output, args.name.as_deref(), &options)?;
    report_spine_export(&export, &written);
    Ok(())
}

fn report_spine_export(export: &spine::SpineExport, written: &[PathBuf]) {
    let vertices: usize = export.parts.iter().map(|p| p.mesh.uvs.len()).sum();
    out::report!(
        "spine {}: {} bones, {} slots, {vertices} mesh vertices",
        export.name,
        export.skeleton.bones.len(),
        export.parts.len()
    );
    for (animation, baked) in &export.baked {
        if baked.is_empty() {
            out::report!("  {animation}: native timelines");
        } else {
            out::report!("  {animation}: baked {}", baked.join(", "));
        }
    }
    for path in written {
        out::report!("  wrote {}", path.display());
    }
}

/// Frame rate of the demo's renders.
const DEMO_FPS: f64 = 24.0;
