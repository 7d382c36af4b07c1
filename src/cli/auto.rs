//! `sinew auto ART -o DIR`: the automatic rig, weights, the library's motions, renders and the
//! Spine export in one command (see [`sinew::jobs::auto`]).

use anyhow::Result;
use clap::Args;
use sinew::jobs::auto::{auto_files, AutoFiles, AutoOptions};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct AutoArgs {
    /// A layered file (.psd, .psb, .ora, or the .json of a Spine export script beside its
    /// PNGs) or a flat PNG sprite.
    pub art: PathBuf,
    /// The folder to write (made; an earlier `sinew auto` output there is replaced whole).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Frames per second of the GIFs and sprite sheets.
    #[arg(long, default_value_t = AutoOptions::default().fps)]
    pub fps: f64,
    /// Longest side of the rendered frames, px (the canvas is scaled down to it, never up).
    #[arg(long, value_name = "PX", default_value_t = AutoOptions::default().render_side_px,
          value_parser = clap::value_parser!(u32).range(1..))]
    pub render_size: u32,
}

pub fn run(args: &AutoArgs) -> Result<()> {
    let options = AutoOptions {
        fps: args.fps,
        render_side_px: args.render_size,
        ..AutoOptions::default()
    };
    let files = AutoFiles {
        art: args.art.clone(),
        output: args.output.clone(),
    };
    let summary = auto_files(&files, &options)?;
    if !super::out::quiet() {
        print!("{}", summary.text(&args.output));
    }
    Ok(())
}
