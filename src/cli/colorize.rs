//! `sinew colorize LINEART.png --scribbles S.png|S.json -o OUT.png`: argument parsing and glue.

use super::choices::{self, ColorWeightsArg, FillModeArg, RegionSplitArg};
use anyhow::{Context, Result};
use clap::Args;
use sinew::colorize::{self, ColorWeights, ColorizeOptions, FillMode, RegionSplit, Scribbles};
use sinew::io;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Args, Debug)]
pub struct ColorizeArgs {
    /// The line art (PNG): lines on white or on transparency.
    pub lineart: PathBuf,
    /// The scribbles: an RGBA PNG layer of the same size (strokes on transparency; one handle
    /// per color), or a JSON file of polylines (`{"strokes": [{"color", "width", "points"}]}`).
    #[arg(long)]
    pub scribbles: PathBuf,
    /// The colored image to write (PNG).
    #[arg(short, long)]
    pub output: PathBuf,
    /// flat: each pixel its region's color; soft: region edges antialiased over about 3 px.
    #[arg(long, value_parser = choices::parser::<FillModeArg, FillMode>(), default_value = "flat")]
    pub fill: FillMode,
    /// Also write one mask PNG per scribble color into this folder (NN-rrggbb.png).
    #[arg(long, value_name = "DIR")]
    pub layers: Option<PathBuf>,
    /// The weights' energy.
    #[arg(long, value_parser = choices::parser::<ColorWeightsArg, ColorWeights>(), default_value = "harmonic")]
    pub weights: ColorWeights,
    /// Lift scale: a full color change counts as S px.
    #[arg(long, value_name = "S", default_value_t = colorize::DEFAULT_LIFT_SCALE)]
    pub scale: f64,
    /// Gap closing: lines cast a ridge of ink fading over PX pixels; openings up to about PX
    /// px wide are closed (0: off).
    #[arg(long, value_name = "PX", default_value_t = ColorizeOptions::default().gap_closing_px)]
    pub gap_closing: f64,
    /// How a region holding several colors is split: depth (boundaries where it is
    /// narrowest) or weights (the content-aware weights).
    #[arg(long, value_parser = choices::parser::<RegionSplitArg, RegionSplit>(), default_value = "depth")]
    pub split: RegionSplit,
    /// With --split depth: distances to the lines beyond PX count as PX.
    #[arg(long, value_name = "PX", default_value_t = ColorizeOptions::default().split_depth_px)]
    pub split_depth: f64,
}

/// Whether the scribble file is the JSON polyline format (by extension).
fn is_json(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.to_string_lossy().eq_ignore_ascii_case("json"))
}

pub fn run(args: &ColorizeArgs) -> Result<()> {
    let start = Instant::now();
    super::check_outputs(
        [args.lineart.as_path(), args.scribbles.as_path()],
        // --layers is a folder, made where missing.
        [Some(args.output.as_path())],
    )?;
    let options = ColorizeOptions {
        scale: args.scale,
        weights: args.weights,
        fill: args.fill,
        gap_closing_px: args.gap_closing,
        split: args.split,
        split_depth_px: args.split_depth,

        ..Default::default()
    };
    let lineart = io::load_png(&args.lineart)?;
    let scribbles_path = args.scribbles.display();
    let scribbles = if is_json(&args.scribbles) {
        let text = std::fs::read_to_string(&args.scribbles)
            .with_context(|| format!("{scribbles_path}: cannot read"))?;
        Scribbles::from_json(&text, lineart.width(), lineart.height(), &options.scribbles)
            .with_context(|| format!("{scribbles_path}"))?
    } else {
        let layer = io::load_png(&args.scribbles)?;
        Scribbles::from_layer(&layer, &options.scribbles)
            .with_context(|| format!("{scribbles_path}"))?
    };
    let result = colorize::colorize(&lineart, &scribbles, &options, args.layers.is_some())
        .with_context(|| format!("{scribbles_path}"))?;
    // Everything is computed; now write, each file atomically.
    if let Some(dir) = &args.layers {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create the folder", dir.display()))?;
        for (k, (layer, color)) in result.layers.iter().zip(&result.palette).enumerate() {
            let path = dir.join(format!("{k:02}-{}.png", colorize::scribbles::hex(*color)));
            io::save_png(&path, layer)?;
        }
    }
    io::save_png(&args.output, &result.image)?;
    let s = &result.stats;
    println!(
        "colorized {}×{} px with {} colors: {} mesh vertices, {} triangles, {:.2} s",
        lineart.width(),
        lineart.height(),
        result.palette.len(),
        s.vertices,
        s.triangles,
        start.elapsed().as_secs_f64()
    );
    if s.scribble_pixels_on_lines > 0 {
        println!(
            "  {} scribble pixels lie on lines and were ignored",
            s.scribble_pixels_on_lines
        );
    }
    Ok(())
}
