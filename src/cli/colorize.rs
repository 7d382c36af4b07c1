//! `sinew colorize LINEART.png --scribbles S.png|S.json -o OUT.png`: argument parsing and glue.

use super::choices::{self, ColorWeightsArg, FillModeArg, RegionSplitArg};
use anyhow::Result;
use clap::Args;
use sinew::colorize::{self, ColorWeights, ColorizeOptions, FillMode, RegionSplit};
use std::path::PathBuf;
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
    #[arg(long, value_parser = choices::parser::<FillModeArg, FillMode>(), default_value = choices::default_name!(FillModeArg, ColorizeOptions::default().fill))]
    pub fill: FillMode,
    /// Also write one mask PNG per scribble color into this folder (NN-rrggbb.png).
    #[arg(long, value_name = "DIR")]
    pub layers: Option<PathBuf>,
    /// The weights' energy.
    #[arg(long, value_parser = choices::parser::<ColorWeightsArg, ColorWeights>(), default_value = choices::default_name!(ColorWeightsArg, ColorizeOptions::default().weights))]
    pub weights: ColorWeights,
    /// Lift scale: a full color change counts as S px.
    #[arg(long, value_name = "S", default_value_t = colorize::DEFAULT_LIFT_SCALE)]
    pub scale: f64,
    /// Gap closing: lines cast a ridge of ink fading over PX pixels; openings up to about PX
    /// px wide are closed (0: off).
    #[arg(long, value_name = "PX", default_value_t = ColorizeOptions::default().gap_closing_px)]
    pub gap_closing: f64,
    /// End-point joins: line ends up to PX apart that face each other are joined by a curve
    /// before the ridge (0: no curves).
    #[arg(long, value_name = "PX", default_value_t = ColorizeOptions::default().end_point_join.spline_max_px)]
    pub join_curve: f64,
    /// End-point joins: a free line end reaching a line within PX along its direction is
    /// joined to it by a segment (0: no segments).
    #[arg(long, value_name = "PX", default_value_t = ColorizeOptions::default().end_point_join.segment_max_px)]
    pub join_segment: f64,
    /// How a region holding several colors is split: reach (colors meet at necks, each
    /// scribble reaching in proportion to its size), depth (boundaries where it is
    /// narrowest), density (where ink crowds, G'MIC Smart Coloring's order) or weights (the
    /// content-aware weights).
    #[arg(long, value_parser = choices::parser::<RegionSplitArg, RegionSplit>(), default_value = choices::default_name!(RegionSplitArg, ColorizeOptions::default().split))]
    pub split: RegionSplit,
    /// With --split depth: distances to the lines beyond PX count as PX.
    #[arg(long, value_name = "PX", default_value_t = ColorizeOptions::default().split_depth_px)]
    pub split_depth: f64,
    /// With --split reach: α, a pixel d px from the lines costs d^−α to cross.
    #[arg(long, value_name = "ALPHA", default_value_t = ColorizeOptions::default().split_depth_exponent)]
    pub split_exponent: f64,
    /// With --split density: σ in px of the Gaussian that measures the ink around a pixel.
    #[arg(long, value_name = "PX", default_value_t = ColorizeOptions::default().split_blur_px)]
    pub split_blur: f64,
}

pub fn run(args: &ColorizeArgs) -> Result<()> {
    let start = Instant::now();
    let options = ColorizeOptions {
        scale: args.scale,
        weights: args.weights,
        fill: args.fill,
        gap_closing_px: args.gap_closing,
        split: args.split,
        split_depth_px: args.split_depth,
        split_depth_exponent: args.split_exponent,
        split_blur_px: args.split_blur,
        end_point_join: colorize::EndPointJoinOptions {
            spline_max_px: args.join_curve,
            segment_max_px: args.join_segment,
            ..Default::default()
        },
        ..Default::default()
    };
    if let Err(colorize::ColorizeError::InvalidOption { field, rule }) = options.check() {
        anyhow::bail!("{} {rule}", flag_of(field));
    }
    let files = sinew::jobs::ColorizeFiles {
        lineart: args.lineart.clone(),
        scribbles: args.scribbles.clone(),
        output: args.output.clone(),
        layers: args.layers.clone(),
    };
    let done = sinew::jobs::colorize_files(&files, &options)?;
    let s = &done.stats;
    super::out::report!(
        "colorized {}×{} px with {} colors: {} mesh vertices, {} triangles, {:.2} s",
        done.size_px.0,
        done.size_px.1,
        done.colors,
        s.vertices,
        s.triangles,
        start.elapsed().as_secs_f64()
    );
    if s.scribble_pixels_on_lines > 0 {
        super::out::report!(
            "  {} scribble pixels lie on lines and were ignored",
            s.scribble_pixels_on_lines
        );
    }
    Ok(())
}

/// The flag that sets the colorize option `field` (as files name it), for refusals in the
/// words of the command line; options without a flag keep their name.
fn flag_of(field: &str) -> &str {
    match field {
        "scale" => "--scale",
        "gap_closing_px" => "--gap-closing",
        "split_depth_px" => "--split-depth",
        "split_depth_exponent" => "--split-exponent",
        "split_blur_px" => "--split-blur",
        "end_point_join.spline_max_px" => "--join-curve",
        "end_point_join.segment_max_px" => "--join-segment",
        other => other,
    }
}
