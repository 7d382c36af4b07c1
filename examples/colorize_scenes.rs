//! Writes the synthetic colorization scenes (line art, scribbles as a layer and as JSON, truth,
//! result, flood fill)
//! to a folder and prints their scores: `cargo run --release --example colorize_scenes [DIR]`.

use image::{Rgba, RgbaImage};
use sinew::colorize::flood::flood_fill;
use sinew::colorize::score::score;
use sinew::colorize::synthetic::{scene, SceneSpec};
use sinew::colorize::{self, ColorizeOptions, FillMode, LineArt, ScribbleOptions, Scribbles};
use std::path::PathBuf;

fn main() -> anyhow::Result<()> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or("out/colorize".into()));
    std::fs::create_dir_all(&dir)?;
    let scale: f64 = std::env::var("SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(colorize::DEFAULT_LIFT_SCALE);
    let specs = [
        ("closed", SceneSpec::default()),
        (
            "thin-gray",
            SceneSpec {
                line_width: 1.5,
                line_gray: 80,
                shapes: 6,
                ..Default::default()
            },
        ),
        (
            "gap2",
            SceneSpec {
                gap_px: Some(2.0),
                ..Default::default()
            },
        ),
        (
            "gap6",
            SceneSpec {
                gap_px: Some(6.0),
                ..Default::default()
            },
        ),
        (
            "undrawn",
            SceneSpec {
                split_background: true,
                ..Default::default()
            },
        ),
    ];
    for (name, spec) in specs {
        let s = scene(&spec);
        let sc = Scribbles::from_strokes(
            &s.strokes,
            spec.size,
            spec.size,
            &ScribbleOptions::default(),
        )?;
        for fill in [FillMode::Flat, FillMode::Soft] {
            let options = ColorizeOptions {
                scale,
                fill,
                ..Default::default()
            };
            let t = std::time::Instant::now();
            let r = colorize::colorize(&s.lineart, &sc, &options, false)?;
            let art = LineArt::new(&s.lineart);
            let (labels, _) = colorize::effective_labels(&art, &sc, options.line_threshold)?;
            let flood = flood_fill(
                art.width,
                art.height,
                &art.line_mask(0.5),
                &labels,
                &sc.colors,
            );
            let flood = colorize::fill::with_lines_on_top(&flood, &s.lineart, art.opaque);
            println!(
                "{name} {fill:?}: weights {:.4}, flood {:.4}, {} vertices, {:.3} s",
                score(&r.image, &s.truth, &s.is_line),
                score(&flood, &s.truth, &s.is_line),
                r.stats.vertices,
                t.elapsed().as_secs_f64()
            );
            let f = format!("{fill:?}").to_lowercase();
            r.image.save(dir.join(format!("{name}-{f}.png")))?;
            flood.save(dir.join(format!("{name}-flood.png")))?;
        }
        s.lineart.save(dir.join(format!("{name}-art.png")))?;
        s.truth.save(dir.join(format!("{name}-truth.png")))?;
        let layer = RgbaImage::from_fn(spec.size, spec.size, |x, y| {
            match sc.labels[(y * spec.size + x) as usize] {
                0 => Rgba([0, 0, 0, 0]),
                l => {
                    let c = sc.colors[l as usize - 1];
                    Rgba([c[0], c[1], c[2], 255])
                }
            }
        });
        layer.save(dir.join(format!("{name}-scribbles.png")))?;
        // The same strokes as the JSON scribble file (`sinew colorize --scribbles`,
        // `sinew edit --line-art … --scribbles …`).
        let file = sinew::colorize::scribbles::StrokeFile {
            strokes: s.strokes.clone(),
        };
        std::fs::write(
            dir.join(format!("{name}-scribbles.json")),
            serde_json::to_vec_pretty(&file)?,
        )?;
    }
    Ok(())
}
