//! Trace + mesh of generated sprites at 512², 1024² and 4096² (one core: tracing and meshing are
//! single-threaded). Targets: 1024² < 50 ms, 4096² < 1 s.
//!
//! `cargo bench --bench trace_mesh`

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use sinew::mesh::{triangulate, MeshOptions};
use sinew::trace::{trace, TraceOptions};
use std::hint::black_box;

fn trace_and_mesh(c: &mut Criterion) {
    let mut group = c.benchmark_group("trace_mesh");
    group.sample_size(10);
    for size in [512u32, 1024, 4096] {
        let image = common::critter(size);
        let area = (size * size) as f64;
        group.bench_with_input(BenchmarkId::new("trace", size), &image, |b, image| {
            b.iter(|| trace(black_box(image), &TraceOptions::default()).unwrap())
        });
        group.bench_with_input(BenchmarkId::new("trace+mesh", size), &image, |b, image| {
            b.iter(|| {
                let outlines = trace(black_box(image), &TraceOptions::default()).unwrap();
                triangulate(&outlines, area, &MeshOptions::default()).unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, trace_and_mesh);
criterion_main!(benches);
