//! One frame of the bundled character at 1024×1024: `Scene::draw` of all 12 parts.
//!
//! Setup (not timed): the character is rigged once (`pipeline::build_rig` with the default
//! options and `assets/character/handles.json`, as `sinew demo` does), its scene built, and the
//! rest pose and a posed frame (limbs, head and tail bent, see [`posed`]) skinned. The canvas is
//! 1024×1024 and the view scales the 512×512 rig canvas by 2 (`canvas_from_world`).
//!
//! - `render/1024/rest` and `render/1024/posed`: clear the canvas, then draw every part, inside a
//!   one-thread rayon pool's `install` (the single-core cost).
//!
//! - `pose_positions/character/{f32_plan,f64_reference}` (one thread): the posed pose's
//!   vertices from its handle transforms. `f32_plan` is the one path every consumer takes
//!   (`Scene::positions_from_transforms`, packed f32 plans made once per scene);
//!   `f64_reference` is the compressed-row f64 `linear_blend` over the same parts, what the
//!   path did before and what the tests compare against.
//!
//! Target (issue "Keyframed timelines, rendered animations, golden-image tests"): one frame in
//! < 8 ms on one core.
//!
//! `cargo bench --bench render`

use criterion::{criterion_group, criterion_main, Criterion};
use sinew::geom::Point;
use sinew::io::BuildOptions;
use sinew::pipeline::{self, Scene};
use sinew::rig::pose::{Affine, BonePose};
use sinew::rig::{Handles, Pose};
use sinew::skin::{linear_blend, Blend, SkinWeights};
use std::path::{Path, PathBuf};

/// Side of the rendered frame, px.
const FRAME_PX: u32 = 1024;

/// The bundled character rigged and loaded, with its rest and posed vertex positions.
struct Character {
    scene: Scene,
    rest: Vec<Vec<Point>>,
    posed: Vec<Vec<Point>>,
}

fn character() -> Character {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/character");
    let list: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("layers.json")).expect("bundled layers.json"),
    )
    .expect("layers.json is JSON");
    let paths: Vec<PathBuf> = list["layers"]
        .as_array()
        .expect("a layer list")
        .iter()
        .map(|n| dir.join(format!("{}.png", n.as_str().expect("a layer name"))))
        .collect();
    let layers = pipeline::load_layers(&paths).expect("bundled layers load");
    let handles: Handles = serde_json::from_str(
        &std::fs::read_to_string(dir.join("handles.json")).expect("bundled handles.json"),
    )
    .expect("handles.json parses");
    let (doc, _) = pipeline::build_rig(&layers, &dir, &BuildOptions::default(), &handles)
        .expect("the character rigs");
    let images: Vec<_> = layers.iter().map(|l| l.image.clone()).collect();
    let scene = Scene::new(doc, &images).expect("the scene loads");
    let rest = scene.rest_positions();
    let posed = scene.pose_positions(&posed()).expect("the pose applies");
    Character { scene, rest, posed }
}

/// A walk-cycle-like pose: every limb, the head and the tail bent.
fn posed() -> Pose {
    let rotations = [
        ("chest", 8.0),
        ("head", -14.0),
        ("leg_upper_l", 25.0),
        ("leg_lower_l", -30.0),
        ("leg_upper_r", -20.0),
        ("leg_lower_r", 15.0),
        ("arm_upper_l", 35.0),
        ("arm_lower_l", 40.0),
        ("arm_upper_r", -30.0),
        ("arm_lower_r", -25.0),
        ("tail_1", 10.0),
        ("tail_2", 12.0),
        ("tail_3", -15.0),
        ("tail_4", 10.0),
        ("tail_5", -12.0),
        ("tail_6", 20.0),
    ];
    let mut pose = Pose::default();
    for (bone, rotate) in rotations {
        pose.bones.insert(
            bone.to_string(),
            BonePose {
                rotate,
                ..Default::default()
            },
        );
    }
    pose
}

fn render(c: &mut Criterion) {
    let character = character();
    let [w, _] = character.scene.doc.canvas;
    let zoom = FRAME_PX as f32 / w as f32;
    let view = tiny_skia::Transform::from_scale(zoom, zoom);
    let mut canvas = tiny_skia::Pixmap::new(FRAME_PX, FRAME_PX).expect("a 1024² canvas");
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("one-thread pool");
    let mut group = c.benchmark_group("render");
    group.sample_size(50);
    for (name, positions) in [("rest", &character.rest), ("posed", &character.posed)] {
        group.bench_function(format!("{FRAME_PX}/{name}"), |b| {
            single.install(|| {
                b.iter(|| {
                    canvas.fill(tiny_skia::Color::TRANSPARENT);
                    character
                        .scene
                        .draw(&mut canvas, positions, view)
                        .expect("positions match the scene");
                })
            })
        });
    }
    group.finish();
}

/// Posed vertices from transforms: the scene's one path against the f64 reference.
fn pose_positions(c: &mut Criterion) {
    let character = character();
    let scene = &character.scene;
    let pose = posed();
    let transforms = scene.handle_transforms(&pose).expect("the pose applies");
    let columns = sinew::rig::handle_columns(&scene.doc.handles);
    // The reference's per-part inputs, made outside the timing like the scene's plans.
    let parts: Vec<(Vec<Point>, SkinWeights, Vec<Affine>)> = scene
        .doc
        .parts
        .iter()
        .filter_map(|part| {
            let weights = part.weights.as_ref()?;
            let part_transforms = weights
                .handles
                .iter()
                .map(|name| {
                    let column = columns.iter().position(|c| c == name).expect("a column");
                    transforms[column]
                })
                .collect();
            let rest = part.mesh.to_mesh().vertices;
            Some((rest, SkinWeights::from_rows(&weights.rows), part_transforms))
        })
        .collect();
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("one-thread pool");
    let mut group = c.benchmark_group("pose_positions");
    group.sample_size(50);
    group.bench_function("character/f32_plan", |b| {
        single.install(|| {
            b.iter(|| {
                scene
                    .positions_from_transforms(&transforms, &pose, Blend::Linear)
                    .expect("the pose applies")
            })
        })
    });
    let mut out: Vec<Vec<Point>> = parts.iter().map(|(rest, _, _)| rest.clone()).collect();
    group.bench_function("character/f64_reference", |b| {
        single.install(|| {
            b.iter(|| {
                for ((rest, weights, part_transforms), out) in parts.iter().zip(out.iter_mut()) {
                    linear_blend(rest, weights, part_transforms, out);
                }
            })
        })
    });
    group.finish();
}

criterion_group!(benches, render, pose_positions);
criterion_main!(benches);
