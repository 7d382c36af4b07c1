//! `sinew animate RIG.json --motion NAME|CLIP.bvh [-o OUT.json]`: a capture clip retargeted onto
//! the rig and stored in its document as an animation.

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use sinew::io::outputs::check_outputs;
use sinew::io::RigDocument;
use sinew::motion::{self, library, Facing, LoopMode, MapFile, RetargetOptions, View};
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct AnimateArgs {
    /// The rig document to animate.
    pub rig: PathBuf,
    /// A motion of the bundled library (idle, walk, run, jump, jump_forward, wave) or a BVH
    /// capture file.
    #[arg(long, value_name = "NAME|CLIP.bvh")]
    pub motion: String,
    /// The animation's name (default: the motion's name, or the file's stem).
    #[arg(long, value_name = "N")]
    pub name: Option<String>,
    /// The plane the capture is seen on: side (a character drawn in profile), front (facing
    /// the viewer) or auto (per limb group, the plane of its largest motion).
    #[arg(long, value_enum, default_value_t = ViewArg::Auto)]
    pub view: ViewArg,
    /// Seen from the side, which way the character faces on screen.
    #[arg(long, value_enum, default_value_t = FacingArg::Right)]
    pub facing: FacingArg,
    /// No horizontal travel: the character walks or runs on the spot.
    #[arg(long)]
    pub in_place: bool,
    /// Make the clip loop (cut at the frame that best matches its start, the rest of the
    /// seam blended), or not; auto: the library knows its cycles, a capture file loops when
    /// a frame of its second half nearly matches its first.
    #[arg(long = "loop", value_enum, default_value_t = LoopArg::Auto)]
    pub loop_mode: LoopArg,
    /// A joint map for a rig whose bones do not have the humanoid template's names:
    /// {"bones": {"BONE": ["FROM_JOINT", "TO_JOINT"]}} (TO may be "JOINT/end").
    #[arg(long, value_name = "MAP.json")]
    pub map: Option<PathBuf>,
    /// Where to write the rig with its new animation (default: the rig itself).
    #[arg(short, long, value_name = "OUT.json")]
    pub output: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ViewArg {
    Auto,
    Side,
    Front,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FacingArg {
    Right,
    Left,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum LoopArg {
    Auto,
    On,
    Off,
}

/// The options the arguments give.
fn options(args: &AnimateArgs) -> RetargetOptions {
    RetargetOptions {
        view: match args.view {
            ViewArg::Auto => View::Auto,
            ViewArg::Side => View::Side,
            ViewArg::Front => View::Front,
        },
        facing: match args.facing {
            FacingArg::Right => Facing::Right,
            FacingArg::Left => Facing::Left,
        },
        in_place: args.in_place,
        loop_mode: match args.loop_mode {
            LoopArg::Auto => LoopMode::Auto,
            LoopArg::On => LoopMode::Blend,
            LoopArg::Off => LoopMode::Off,
        },
        ..RetargetOptions::default()
    }
}

/// Part image paths of `doc` (relative to `from`'s folder) made to resolve from `to`'s.
fn rebase_images(doc: &mut RigDocument, from: &Path, to: &Path) -> Result<()> {
    let dir = |p: &Path| {
        let parent = p.parent().filter(|d| !d.as_os_str().is_empty());
        std::path::absolute(parent.unwrap_or(Path::new(".")))
    };
    let (from_dir, to_dir) = (dir(from)?, dir(to)?);
    if from_dir == to_dir {
        return Ok(());
    }
    for part in &mut doc.parts {
        let image = from_dir.join(&part.image);
        part.image = match image.strip_prefix(&to_dir) {
            Ok(rel) => rel.to_string_lossy().into_owned(),
            Err(_) => image.to_string_lossy().into_owned(),
        };
    }
    Ok(())
}

pub fn run(args: &AnimateArgs) -> Result<()> {
    let output = args.output.clone().unwrap_or_else(|| args.rig.clone());
    let is_file =
        args.motion.to_ascii_lowercase().ends_with(".bvh") || Path::new(&args.motion).is_file();
    let inputs: Vec<&Path> = [
        Some(Path::new(&args.motion)).filter(|_| is_file),
        args.map.as_deref(),
    ]
    .into_iter()
    .flatten()
    .collect();
    check_outputs(inputs, [Some(output.as_path())])?;
    let library_motion = if is_file {
        None
    } else {
        library::find(&args.motion)
    };
    let (clip, default_name) = if is_file {
        let path = Path::new(&args.motion);
        let clip = motion::read(path, &motion::BvhLimits::default())
            .with_context(|| format!("cannot read the capture {}", path.display()))?;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        (clip, stem)
    } else {
        let Some(m) = library::find(&args.motion) else {
            let names = library::MOTIONS.iter().map(|m| m.name);
            bail!(
                "--motion: no motion '{}' in the library{} (it has: {}); give a .bvh file for your \
                 own capture",
                args.motion,
                sinew::names::did_you_mean(&sinew::names::closest(&args.motion, names)),
                library::names()
            );
        };
        (m.clip()?, m.name.to_string())
    };
    let map: Option<MapFile> = match &args.map {
        Some(path) => Some(super::read_json(path, "joint map")?),
        None => None,
    };
    let mut doc = RigDocument::load(&args.rig)?;
    let name = args.name.clone().unwrap_or(default_name);
    let mut options = options(args);
    // A library motion knows whether it is a cycle.
    if let (LoopArg::Auto, Some(m)) = (args.loop_mode, library_motion) {
        options.loop_mode = m.loop_mode();
    }
    let report = motion::apply_motion(&mut doc, &clip, map.as_ref(), &name, &options)?;
    rebase_images(&mut doc, &args.rig, &output)?;
    doc.save(&output)?;
    let views: Vec<String> = report
        .views
        .iter()
        .map(|(g, v)| format!("{} {}", serde_plain(g), serde_plain(v)))
        .collect();
    println!(
        "{}: animation '{name}', {:.2} s, {} keys from {} frames ({} bones driven; {}; {} foot contacts planted{})",
        output.display(),
        report.duration_s,
        report.keys,
        report.frames,
        report.driven.len(),
        views.join(", "),
        report.contacts,
        if report.looped { "; loops" } else { "" },
    );
    Ok(())
}

/// A unit enum's serde name (`legs`, `side`).
fn serde_plain<T: serde::Serialize>(value: &T) -> String {
    serde_json::to_value(value)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}
