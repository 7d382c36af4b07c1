//! Writing 30 frames of 512² px: GIF (palette + LZW), sprite sheet (trim + pack + PNG), and the
//! palette alone. Encoding only (no disk), on the synthetic animation.

use criterion::{criterion_group, criterion_main, Criterion};
use sinew::io::sequence::palette::{pack_rgb, quantize, Histogram};
use sinew::io::sequence::synthetic::synthetic_animation;
use sinew::io::sequence::{build_sheet, encode_gif, GifOptions, SheetOptions};
use std::hint::black_box;

const SIDE_PX: u32 = 512;
const FRAMES: usize = 30;
const FPS: f64 = 30.0;

fn sequence(c: &mut Criterion) {
    let frames = synthetic_animation(SIDE_PX, FRAMES);
    let on_grey = sinew::io::sequence::composite_over_background(&frames, [128, 128, 128, 255]);
    let mut group = c.benchmark_group("sequence_30x512");
    group.sample_size(10);
    group.bench_function("gif_transparent", |b| {
        b.iter(|| encode_gif(black_box(&frames), FPS, &GifOptions::default()).unwrap())
    });
    group.bench_function("gif_opaque", |b| {
        b.iter(|| encode_gif(black_box(&on_grey), FPS, &GifOptions::default()).unwrap())
    });
    group.bench_function("palette_opaque", |b| {
        b.iter(|| {
            let h = Histogram::from_frames(
                on_grey
                    .iter()
                    .map(|f| f.pixels().map(|p| pack_rgb(p[0], p[1], p[2])).collect())
                    .collect(),
            );
            quantize(&h, 255)
        })
    });
    group.bench_function("sheet", |b| {
        b.iter(|| {
            let sheet = build_sheet(
                black_box(&frames),
                &[],
                FPS,
                "demo",
                "demo.png",
                &SheetOptions::default(),
            )
            .unwrap();
            sinew::io::image::encode_png(&sheet.image).unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, sequence);
criterion_main!(benches);
