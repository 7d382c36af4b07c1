//! Scribble colorization of generated line art (`sinew::colorize::synthetic`): 512², 1024² and
//! 2048² canvases with 6 and 10 scribble colors (5 or 9 outlined shapes and the background,
//! 3 px antialiased black lines on white, one polyline scribble per region), default
//! [`ColorizeOptions`], no layers.
//!
//! Timed: the whole `colorize::colorize` call on decoded images and rasterized scribbles, with
//! the default options: gap closing, ink regions, the reach split of regions holding several
//! colors, the fill, lines on top (the lifted weights and their mesh only run with
//! `split: weights`; the mesh size is printed when there is one). The `size/colors` cases'
//! regions are closed, one color each; the split runs in `undrawn/size` (the background's two
//! halves share one region, 11 colors in all) and `open/size` (the 10 scribbles on a blank
//! page: one region holding all 10 colors, the split's worst case: the largest scribble's
//! Dijkstra over every pixel, the others stopped where they cannot win).
//!
//! Targets (two-core reference machine, issue 24): 2048² under 1 s; peak memory at 2048²
//! < 1 GiB (`cargo bench --bench colorize_memory`).
//!
//! `incremental/1024`: the line art prepared once ([`PreparedLineArt`]: gap closing, ink
//! regions), then the colorization after one more scribble, as the editor's colorize mode
//! re-solves while the artist scribbles (issue 24's target: under 100 ms at 1024²);
//! `incremental-undrawn/1024` the same on the `undrawn` scene, where each re-solve splits the
//! contested background.
//!
//! `cargo bench --bench colorize`; one case: `cargo bench --bench colorize -- '2048/10'`.

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use sinew::colorize::synthetic::{scene, Scene, SceneSpec};
use sinew::colorize::{self, ColorizeOptions, PreparedLineArt, ScribbleOptions, Scribbles};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("colorize");
    group.sampling_mode(SamplingMode::Flat).sample_size(10);
    for size in [512u32, 1024, 2048] {
        for colors in [6usize, 10] {
            let (s, scribbles) = scene_and_scribbles(SceneSpec {
                size,
                shapes: colors - 1,
                ..Default::default()
            });
            let options = ColorizeOptions::default();
            let result =
                colorize::colorize(&s.lineart, &scribbles, &options, false).expect("colorizes");
            if result.stats.vertices > 0 {
                println!(
                    "{size}²/{colors} colors: {} vertices, {} triangles ({:.1}% of the pixels)",
                    result.stats.vertices,
                    result.stats.triangles,
                    100.0 * result.stats.vertices as f64 / result.stats.pixels as f64
                );
            }
            group.bench_function(format!("{size}/{colors}"), |b| {
                b.iter(|| {
                    colorize::colorize(black_box(&s.lineart), &scribbles, &options, false)
                        .expect("colorizes")
                })
            });
        }
    }
    for size in [1024u32, 2048] {
        let (s, scribbles) = scene_and_scribbles(SceneSpec {
            size,
            shapes: 9,
            split_background: true,
            ..Default::default()
        });
        let options = ColorizeOptions::default();
        group.bench_function(format!("undrawn/{size}"), |b| {
            b.iter(|| {
                colorize::colorize(black_box(&s.lineart), &scribbles, &options, false)
                    .expect("colorizes")
            })
        });
        let blank = image::RgbaImage::from_pixel(size, size, image::Rgba([255, 255, 255, 255]));
        // The same shapes' scribbles on a blank page.
        let (_, scribbles) = scene_and_scribbles(SceneSpec {
            size,
            shapes: 9,
            ..Default::default()
        });
        group.bench_function(format!("open/{size}"), |b| {
            b.iter(|| {
                colorize::colorize(black_box(&blank), &scribbles, &options, false)
                    .expect("colorizes")
            })
        });
    }
    let (s, scribbles) = scene_and_scribbles(SceneSpec {
        size: 1024,
        shapes: 9,
        ..Default::default()
    });
    let prepared =
        PreparedLineArt::new(s.lineart.clone(), ColorizeOptions::default()).expect("prepares");
    // After a scribble is added, the re-solve colorizes the prepared line art from every
    // scribble (nothing scribble-dependent is kept between solves).
    let never = std::sync::atomic::AtomicBool::new(false);
    group.bench_function("incremental/1024", |b| {
        b.iter(|| {
            prepared
                .colorize(black_box(&scribbles), false, &never)
                .expect("colorizes")
        })
    });
    // The same on the undrawn scene: the re-solve splits the contested background by reach.
    let (s, scribbles) = scene_and_scribbles(SceneSpec {
        size: 1024,
        shapes: 9,
        split_background: true,
        ..Default::default()
    });
    let prepared =
        PreparedLineArt::new(s.lineart.clone(), ColorizeOptions::default()).expect("prepares");
    group.bench_function("incremental-undrawn/1024", |b| {
        b.iter(|| {
            prepared
                .colorize(black_box(&scribbles), false, &never)
                .expect("colorizes")
        })
    });
    group.finish();
}

/// A generated scene and its scribbles rasterized.
fn scene_and_scribbles(spec: SceneSpec) -> (Scene, Scribbles) {
    let s = scene(&spec);
    let scribbles = Scribbles::from_strokes(
        &s.strokes,
        spec.size,
        spec.size,
        &ScribbleOptions::default(),
    )
    .expect("the strokes rasterize");
    (s, scribbles)
}

criterion_group!(benches, bench);
criterion_main!(benches);
