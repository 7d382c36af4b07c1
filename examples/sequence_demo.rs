//! Writes the synthetic test animation (`io::sequence::synthetic`) in every sequence format and
//! prints how long each took: the input of `tools/browser-check`.
//!
//! `cargo run --release --example sequence_demo -- OUT_DIR [SIDE_PX] [FRAMES] [FPS]`
//! (defaults 256 px, 24 frames, 24 fps). Writes OUT_DIR/demo.gif (transparent),
//! OUT_DIR/demo_on_white.gif (composited over #ffffffff), OUT_DIR/demo.png + demo.json (sprite
//! sheet) and OUT_DIR/demo_frames/ (numbered PNGs).

use sinew::io::sequence::synthetic::synthetic_animation;
use sinew::io::sequence::{
    composite_over_background, parse_rgba_hex, write_sequence, SequenceOptions,
};
use std::path::PathBuf;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(out) = args.first().map(PathBuf::from) else {
        anyhow::bail!("usage: sequence_demo OUT_DIR [SIDE_PX] [FRAMES] [FPS]");
    };
    let side_px: u32 = args.get(1).map_or(Ok(256), |s| s.parse())?;
    let count: usize = args.get(2).map_or(Ok(24), |s| s.parse())?;
    let fps: f64 = args.get(3).map_or(Ok(24.0), |s| s.parse())?;
    std::fs::create_dir_all(&out)?;

    let frames = synthetic_animation(side_px, count);
    let white = composite_over_background(&frames, parse_rgba_hex("#ffffffff")?);
    let options = SequenceOptions::default();
    for (frames, name) in [
        (&frames, "demo.gif"),
        (&white, "demo_on_white.gif"),
        (&frames, "demo.png"),
        (&frames, "demo_frames"),
    ] {
        let start = Instant::now();
        let report = write_sequence(frames, &[], fps, &out.join(name), &options)?;
        let bytes: u64 = report
            .files
            .iter()
            .map(|f| std::fs::metadata(f).map_or(0, |m| m.len()))
            .sum();
        println!(
            "{name}: {} frames {}×{} px, {:.3} s long, {} file(s) {} bytes, palette {:?}, sheet {:?}, written in {:.1} ms",
            report.frame_count,
            report.frame_size_px.0,
            report.frame_size_px.1,
            report.duration_s,
            report.files.len(),
            bytes,
            report.palette_colours,
            report.sheet_size_px,
            start.elapsed().as_secs_f64() * 1e3
        );
    }
    Ok(())
}
