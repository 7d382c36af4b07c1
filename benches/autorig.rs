//! Autorig on the bundled character's flattened sprite at 512² (as drawn) and 2048² (scaled
//! up 4×, bilinear): the medial-axis skeleton alone, and everything at once (the humanoid
//! template, a 16-vertex cage and 8 points). Single-threaded. Targets: 512² < 100 ms,
//! 2048² < 1 s.
//!
//! `cargo bench --bench autorig`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use image::imageops::FilterType;
use sinew::autorig::{autorig, AutorigOptions, LayerRef, TemplateChoice};
use std::hint::black_box;
use std::path::Path;

fn character(size: u32) -> image::RgbaImage {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/character/flat.png");
    let image = sinew::io::load_png(&path).expect("the bundled character");
    if image.width() == size {
        image
    } else {
        image::imageops::resize(&image, size, size, FilterType::Triangle)
    }
}

fn bench_autorig(c: &mut Criterion) {
    let mut group = c.benchmark_group("autorig");
    group.sample_size(10);
    let everything = AutorigOptions {
        template: TemplateChoice::Humanoid,
        cage_vertices: Some(16),
        point_count: 8,
        ..AutorigOptions::default()
    };
    for size in [512u32, 2048] {
        let image = character(size);
        let layers = [LayerRef::whole("flat", &image)];
        group.bench_with_input(BenchmarkId::new("skeleton", size), &layers, |b, layers| {
            b.iter(|| autorig(black_box(layers), &[], &AutorigOptions::default()).unwrap())
        });
        group.bench_with_input(
            BenchmarkId::new("template+cage+points", size),
            &layers,
            |b, layers| b.iter(|| autorig(black_box(layers), &[], &everything).unwrap()),
        );
    }
    group.finish();
}

criterion_group!(benches, bench_autorig);
criterion_main!(benches);
