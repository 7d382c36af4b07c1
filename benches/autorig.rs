//! Autorig on the bundled character's flattened sprite at 512² (as drawn) and 2048² (scaled
//! up 4×, bilinear): the medial-axis skeleton alone, and everything at once (the humanoid
//! template, a 16-vertex cage and 8 points). Single-threaded. Targets: 512² < 100 ms,
//! 2048² < 1 s. Layered input (group `autorig_layered`): the bundled character's 12 layers at
//! 512², and a 40-layer 4096² character made from them (scaled 8×, each layer cut into
//! segments along its long axis, trimmed and placed by offset), default options (automatic
//! template). Targets: 512² < 100 ms, 4096²/40 layers < 1 s.
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

/// The bundled character's layers (back to front, as `layers.json` lists them), each a
/// whole 512² canvas.
fn character_layers() -> Vec<(String, image::RgbaImage)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/character");
    let listing: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("layers.json")).unwrap()).unwrap();
    listing["layers"]
        .as_array()
        .expect("layers.json's layers")
        .iter()
        .map(|name| {
            let name = name.as_str().unwrap().to_string();
            let image = sinew::io::load_png(&dir.join(format!("{name}.png"))).unwrap();
            (name, image)
        })
        .collect()
}

/// The bounding box `[x0, y0, x1, y1)` of `image`'s non-transparent pixels (`None`: none).
fn opaque_box(image: &image::RgbaImage) -> Option<[u32; 4]> {
    let mut b: Option<[u32; 4]> = None;
    for (x, y, p) in image.enumerate_pixels() {
        if p[3] > 0 {
            let r = b.get_or_insert([x, y, x + 1, y + 1]);
            r[0] = r[0].min(x);
            r[1] = r[1].min(y);
            r[2] = r[2].max(x + 1);
            r[3] = r[3].max(y + 1);
        }
    }
    b
}

/// A layer as layered files are read: its image trimmed to its opaque pixels and the
/// trimmed image's canvas position.
struct Trimmed {
    name: String,
    image: image::RgbaImage,
    offset_px: [i32; 2],
}

/// `image` (at canvas position `offset`) trimmed to its opaque pixels.
fn trim(name: String, image: &image::RgbaImage, offset: [i32; 2]) -> Option<Trimmed> {
    let [x0, y0, x1, y1] = opaque_box(image)?;
    Some(Trimmed {
        name,
        image: image::imageops::crop_imm(image, x0, y0, x1 - x0, y1 - y0).to_image(),
        offset_px: [offset[0] + x0 as i32, offset[1] + y0 as i32],
    })
}

/// A 40-layer 4096² character: the bundled 12 layers scaled 8× (Triangle), each cut across
/// its long axis into pieces overlapping by 24 px (the four longest into 4, the others into
/// 3: 4·4 + 8·3 = 40) as an artist cuts a limb into segments, every piece trimmed and placed
/// by its offset. The first piece keeps the layer's name, the others are `NAME_2`, `NAME_3`…
/// Deterministic.
fn big_layered_character() -> Vec<Trimmed> {
    const SCALE: u32 = 8;
    const OVERLAP: u32 = 24;
    let scaled: Vec<Trimmed> = character_layers()
        .into_iter()
        .map(|(name, image)| {
            // Scale the opaque box with a 2 px margin: the same pixels as scaling the
            // whole canvas, without 64 MB per layer.
            let [x0, y0, x1, y1] = opaque_box(&image).expect("an opaque layer");
            let (x0, y0) = (x0.saturating_sub(2), y0.saturating_sub(2));
            let (x1, y1) = ((x1 + 2).min(image.width()), (y1 + 2).min(image.height()));
            let part = image::imageops::crop_imm(&image, x0, y0, x1 - x0, y1 - y0).to_image();
            let big = image::imageops::resize(
                &part,
                part.width() * SCALE,
                part.height() * SCALE,
                FilterType::Triangle,
            );
            let offset = [(x0 * SCALE) as i32, (y0 * SCALE) as i32];
            trim(name, &big, offset).expect("an opaque scaled layer")
        })
        .collect();
    let long = |t: &Trimmed| t.image.width().max(t.image.height());
    let mut by_length: Vec<usize> = (0..scaled.len()).collect();
    by_length.sort_by_key(|&k| std::cmp::Reverse(long(&scaled[k])));
    let mut out = Vec::new();
    for (k, layer) in scaled.iter().enumerate() {
        let pieces = if by_length[..4].contains(&k) { 4 } else { 3 };
        let (w, h) = layer.image.dimensions();
        let along_x = w >= h;
        let length = if along_x { w } else { h };
        for p in 0..pieces {
            let a = (length * p / pieces).saturating_sub(OVERLAP / 2);
            let b = (length * (p + 1) / pieces + OVERLAP / 2).min(length);
            let (x, y, cw, ch) = if along_x {
                (a, 0, b - a, h)
            } else {
                (0, a, w, b - a)
            };
            let piece = image::imageops::crop_imm(&layer.image, x, y, cw, ch).to_image();
            let name = if p == 0 {
                layer.name.clone()
            } else {
                format!("{}_{}", layer.name, p + 1)
            };
            let offset = [layer.offset_px[0] + x as i32, layer.offset_px[1] + y as i32];
            out.push(trim(name, &piece, offset).expect("an opaque piece"));
        }
    }
    assert_eq!(out.len(), 40);
    out
}

/// Layered input through the library call with the default options (automatic template):
/// the bundled character's 12 whole-canvas layers at 512², and the 40-layer 4096² character
/// of [`big_layered_character`]. Targets: 512² < 100 ms, 4096²/40 layers < 1 s.
fn bench_layered(c: &mut Criterion) {
    let mut group = c.benchmark_group("autorig_layered");
    group.sample_size(10);
    let small = character_layers();
    let layers: Vec<LayerRef> = small
        .iter()
        .map(|(name, image)| LayerRef::whole(name, image))
        .collect();
    group.bench_with_input(BenchmarkId::new("12 layers", 512), &layers, |b, layers| {
        b.iter(|| autorig(black_box(layers), &[], &AutorigOptions::default()).unwrap())
    });
    let big = big_layered_character();
    let layers: Vec<LayerRef> = big
        .iter()
        .map(|t| LayerRef {
            name: &t.name,
            image: &t.image,
            offset_px: t.offset_px,
            canvas_px: [4096, 4096],
        })
        .collect();
    group.bench_with_input(BenchmarkId::new("40 layers", 4096), &layers, |b, layers| {
        b.iter(|| autorig(black_box(layers), &[], &AutorigOptions::default()).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench_autorig, bench_layered);
criterion_main!(benches);
