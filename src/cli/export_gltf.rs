//! `sinew export gltf RIG.json -o FILE.glb`: the rig as binary glTF for Godot, Bevy, Unity,
//! Blender and three.js.

use anyhow::Result;
use clap::Args;
use sinew::export::gltf::{GltfOptions, MAX_INFLUENCES};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct GltfArgs {
    /// The rig document (every part must have weights).
    pub rig: PathBuf,
    /// The .glb file to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Keys per second of the baked animations.
    #[arg(long, default_value_t = GltfOptions::default().bake_fps)]
    pub fps: f64,
    /// Canvas px per glTF unit (a metre to most engines).
    #[arg(long, default_value_t = GltfOptions::default().px_per_unit)]
    pub px_per_unit: f64,
    /// glTF units between consecutive parts of the draw order along z.
    #[arg(long, default_value_t = GltfOptions::default().layer_spacing)]
    pub layer_spacing: f64,
}

pub fn run(args: &GltfArgs) -> Result<()> {
    let options = GltfOptions {
        bake_fps: args.fps,
        px_per_unit: args.px_per_unit,
        layer_spacing: args.layer_spacing,
        ..GltfOptions::default()
    };
    let export = sinew::jobs::export_gltf_file(&args.rig, &args.output, &options)?;
    println!(
        "gltf: {} joints, {} meshes (at most {MAX_INFLUENCES} influences per vertex), {} KB",
        export.joints,
        export.parts.len(),
        export.glb.len().div_ceil(1024)
    );
    for (animation, keys) in &export.animations {
        println!("  {animation}: baked {keys} keys at {} fps", args.fps);
    }
    for line in &export.left_out {
        println!("  not in glTF: {line}");
    }
    println!("  wrote {}", args.output.display());
    Ok(())
}
