//! The exports that play without a Spine licence: `sinew export gltf RIG.json -o FILE.glb` (binary
//! glTF for Godot, Bevy, Unity, Blender and three.js) and `sinew export dragonbones RIG.json -o
//! DIR` (DragonBones 5.5 for Cocos, Egret, Pixi, Phaser and the other DragonBones runtimes).

use anyhow::Result;
use clap::Args;
use sinew::export::dragonbones::DragonBonesOptions;
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
    super::out::report!(
        "gltf: {} joints, {} meshes (at most {MAX_INFLUENCES} influences per vertex), {} KB",
        export.joints.len(),
        export.parts.len(),
        export.glb.len().div_ceil(1024)
    );
    for animation in &export.animations {
        super::out::report!(
            "  {}: baked {} keys at {} fps",
            animation.name,
            animation.times_s.len(),
            args.fps
        );
    }
    for line in &export.left_out {
        super::out::report!("  not in glTF: {line}");
    }
    super::out::report!("  wrote {}", args.output.display());
    Ok(())
}

#[derive(Args, Debug)]
pub struct DragonBonesArgs {
    /// The rig document (every part must have weights).
    pub rig: PathBuf,
    /// The folder to write into (created if missing).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The armature's frame rate: every motion is keyed on each frame.
    #[arg(long, default_value_t = DragonBonesOptions::default().frame_rate)]
    pub fps: u32,
    /// Decimate each part's mesh to at most N vertices (the runtime's 16-bit offsets overflow
    /// on fine meshes).
    #[arg(long, value_name = "N", default_value_t = sinew::export::dragonbones::DEFAULT_MAX_VERTICES)]
    pub max_vertices: usize,
    /// Keep the K strongest weights per vertex, renormalized.
    #[arg(long, value_name = "K", default_value_t = sinew::export::dragonbones::DEFAULT_MAX_INFLUENCES)]
    pub max_influences: usize,
    /// Base name of the files (default: the rig file's name).
    #[arg(long)]
    pub name: Option<String>,
}

pub fn run_dragonbones(args: &DragonBonesArgs) -> Result<()> {
    let options = DragonBonesOptions {
        frame_rate: args.fps,
        max_vertices: Some(args.max_vertices),
        max_influences: Some(args.max_influences),
        ..DragonBonesOptions::default()
    };
    let (export, written) = sinew::jobs::export_dragonbones_files(
        &args.rig,
        &args.output,
        args.name.as_deref(),
        &options,
    )?;
    super::out::report!(
        "dragonbones {}: {} bones, {} animations",
        export.name,
        export.joints.len() + 1,
        export.animations.len()
    );
    for animation in &export.animations {
        super::out::report!(
            "  {}: baked {} frames at {} fps",
            animation.name,
            animation.frame_count + 1,
            export.frame_rate
        );
    }
    for line in &export.left_out {
        super::out::report!("  not in DragonBones: {line}");
    }
    for path in &written {
        super::out::report!("  wrote {}", path.display());
    }
    Ok(())
}
