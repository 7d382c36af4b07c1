//! Samples an animation into pose files and frames, to look at how it moves.
//!
//! `cargo run --release --example anim_frames -- RIG.json ANIMATIONS.json NAME FRAMES OUT_DIR
//! [--mix-into OTHER MIX_S]`
//!
//! RIG.json is a rig document (`sinew demo -o DIR` writes `DIR/character.json`); ANIMATIONS.json
//! an object name → animation (`assets/character/animations.json`). The animation is checked
//! against the rig, then sampled looping at FRAMES evenly spaced times over one cycle; for each
//! frame `k` this writes `OUT_DIR/NAME_k.pose.json` (a pose file for `sinew pose`) and
//! `OUT_DIR/NAME_k.png`, plus `OUT_DIR/NAME_sheet.png` (every frame at half size, in a row of
//! up to 4 per line) and `OUT_DIR/NAME_onion.png` (every frame's silhouette outline drawn over the
//! first frame, to judge the motion's range). With `--mix-into OTHER MIX_S` the frames show the
//! crossfade from NAME (started at 0) into OTHER over MIX_S seconds instead, OTHER starting when
//! the mix starts, over FRAMES evenly spaced times from 0 to MIX_S.

use anyhow::{bail, Context, Result};
use image::{imageops, Rgba, RgbaImage};
use sinew::anim::{sample_mix, Animation, Playhead};
use sinew::pipeline::Scene;
use sinew::{io, render};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Frames per line of the contact sheet.
const SHEET_COLUMNS: usize = 4;

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() != 5 && args.len() != 8 {
        bail!("usage: anim_frames RIG.json ANIMATIONS.json NAME FRAMES OUT_DIR [--mix-into OTHER MIX_S]");
    }
    let rig_path = PathBuf::from(&args[0]);
    let anims_path = PathBuf::from(&args[1]);
    let name = &args[2];
    let frames: usize = args[3].parse().context("FRAMES must be a whole number")?;
    let out_dir = PathBuf::from(&args[4]);
    let mix = match args.get(5).map(String::as_str) {
        Some("--mix-into") => Some((
            args[6].clone(),
            args[7].parse::<f64>().context("MIX_S must be a number")?,
        )),
        Some(other) => bail!("unknown option {other}"),
        None => None,
    };
    if frames == 0 {
        bail!("FRAMES must be at least 1");
    }

    let scene = Scene::load(&rig_path)?;
    let text = std::fs::read_to_string(&anims_path)
        .with_context(|| format!("{}: cannot read", anims_path.display()))?;
    let raw: BTreeMap<String, serde_json::Value> = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a JSON object", anims_path.display()))?;
    let animations = sinew::anim::parse_animations(&raw)?;
    let parts: Vec<&str> = scene.doc.parts.iter().map(|p| p.name.as_str()).collect();
    for (anim_name, anim) in &animations {
        anim.check_rig(anim_name, &scene.doc.handles, &parts, &scene.doc.events)?;
    }
    let get = |n: &str| -> Result<&Animation> {
        animations
            .get(n)
            .with_context(|| format!("{}: no animation '{n}'", anims_path.display()))
    };
    let animation = get(name)?;
    std::fs::create_dir_all(&out_dir)?;

    let mut images = Vec::with_capacity(frames);
    for k in 0..frames {
        let fraction = k as f64 / frames as f64;
        let pose = match &mix {
            None => animation.sample(fraction * animation.duration_s(), true),
            Some((other, mix_s)) => {
                let elapsed = k as f64 / (frames.max(2) - 1) as f64 * mix_s;
                let from = Playhead {
                    animation,
                    time_s: elapsed,
                    looping: true,
                };
                let to = Playhead {
                    animation: get(other)?,
                    time_s: elapsed,
                    looping: true,
                };
                sample_mix(from, to, elapsed, *mix_s, &scene.doc.handles)
            }
        };
        let stem = format!("{name}_{k:02}");
        std::fs::write(
            out_dir.join(format!("{stem}.pose.json")),
            serde_json::to_string_pretty(&pose)? + "\n",
        )?;
        let positions = scene.pose_positions(&pose)?;
        let image = render::rgba_from_pixmap(&scene.render(&positions)?);
        io::save_png(&out_dir.join(format!("{stem}.png")), &image)?;
        images.push(image);
    }

    let (w, h) = images[0].dimensions();
    let (cw, ch) = (w / 2, h / 2);
    let columns = frames.min(SHEET_COLUMNS) as u32;
    let rows = frames.div_ceil(SHEET_COLUMNS) as u32;
    let mut sheet = RgbaImage::from_pixel(cw * columns, ch * rows, Rgba([255, 255, 255, 255]));
    for (k, image) in images.iter().enumerate() {
        let small = imageops::resize(image, cw, ch, imageops::FilterType::Triangle);
        let (x, y) = ((k as u32 % columns) * cw, (k as u32 / columns) * ch);
        imageops::overlay(&mut sheet, &small, i64::from(x), i64::from(y));
    }
    io::save_png(&out_dir.join(format!("{name}_sheet.png")), &sheet)?;

    // Onion skin: the first frame, with every frame's alpha edge in a colour from red to blue.
    let mut onion = RgbaImage::from_pixel(w, h, Rgba([255, 255, 255, 255]));
    imageops::overlay(&mut onion, &images[0], 0, 0);
    for (k, image) in images.iter().enumerate() {
        let f = k as f64 / frames.max(2) as f64;
        let color = Rgba([(255.0 * (1.0 - f)) as u8, 40, (255.0 * f) as u8, 255]);
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                let inside = |x: u32, y: u32| image.get_pixel(x, y)[3] >= 128;
                if inside(x, y)
                    && !(inside(x - 1, y)
                        && inside(x + 1, y)
                        && inside(x, y - 1)
                        && inside(x, y + 1))
                {
                    onion.put_pixel(x, y, color);
                }
            }
        }
    }
    io::save_png(&out_dir.join(format!("{name}_onion.png")), &onion)?;
    println!("wrote {frames} frames of '{name}' to {}", out_dir.display());
    Ok(())
}
