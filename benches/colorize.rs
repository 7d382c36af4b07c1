//! Scribble colorization of generated line art (`sinew::colorize::synthetic`): 512², 1024² and
//! 2048² canvases with 6 and 10 scribble colors (5 or 9 outlined shapes and the background,
//! 3 px antialiased black lines on white, one polyline scribble per region), default
//! [`ColorizeOptions`] (harmonic weights, flat fill, no layers).
//!
//! Timed: the whole `colorize::colorize` call (gap closing, adaptive mesh, lifted stiffness,
//! Cholesky and one solve per color, interpolation to every pixel, lines on top) on decoded
//! images and rasterized scribbles. Mesh sizes are printed before measuring.
//!
//! Targets (two-core reference machine): 512² < 0.3 s, 2048² < 3 s; peak memory at 2048²
//! < 1 GiB (`cargo bench --bench colorize_memory`).
//!
//! `cargo bench --bench colorize`; one case: `cargo bench --bench colorize -- '2048/10'`.

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use sinew::colorize::synthetic::{scene, SceneSpec};
use sinew::colorize::{self, ColorizeOptions, ScribbleOptions, Scribbles};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("colorize");
    group.sampling_mode(SamplingMode::Flat).sample_size(10);
    for size in [512u32, 1024, 2048] {
        for colors in [6usize, 10] {
            let s = scene(&SceneSpec {
                size,
                shapes: colors - 1,
                ..Default::default()
            });
            let scribbles =
                Scribbles::from_strokes(&s.strokes, size, size, &ScribbleOptions::default())
                    .expect("the strokes rasterize");
            let options = ColorizeOptions::default();
            let result =
                colorize::colorize(&s.lineart, &scribbles, &options, false).expect("colorizes");
            println!(
                "{size}²/{colors} colors: {} vertices, {} triangles ({:.1}% of the pixels)",
                result.stats.vertices,
                result.stats.triangles,
                100.0 * result.stats.vertices as f64 / result.stats.pixels as f64
            );
            group.bench_function(format!("{size}/{colors}"), |b| {
                b.iter(|| {
                    colorize::colorize(black_box(&s.lineart), &scribbles, &options, false)
                        .expect("colorizes")
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
