//! Golden-image tests: the bundled character, rigged from its layers and handles with default
//! options, rendered at rest, in the bundled poses (`assets/character/poses/`) and in its
//! bundled animations at fixed times, compared with the reviewed PNGs in `golden/`.
//!
//! Tolerance: on premultiplied RGBA8 (what compositing shows; the color of invisible pixels
//! is not compared), the largest channel difference must be at most [`MAX_CHANNEL_DIFF`] and
//! the PSNR at least [`MIN_PSNR_DB`]. Renders are deterministic, so on the machine that blessed
//! the references the difference is zero; the slack absorbs floating-point differences
//! between machines. One bone turned by 2° moves edges by whole pixels and fails both
//! (`a_two_degree_turn_fails`).
//!
//! A failing comparison writes `target/golden-failures/<name>.actual.png` and
//! `<name>.diff.png` (the difference ×8) and names them. To accept new renders on purpose:
//! `SINEW_BLESS=1 cargo test --test golden`, then look at every PNG in `golden/` before
//! committing.

mod common;

use image::{Rgba, RgbaImage};
use sinew::io::{load_png, save_png};
use sinew::pipeline::Scene;
use sinew::render;
use sinew::rig::pose::BonePose;
use sinew::rig::Pose;
use std::path::PathBuf;
use std::sync::OnceLock;

/// Largest premultiplied channel difference accepted, of 255.
const MAX_CHANNEL_DIFF: u8 = 2;
/// Smallest premultiplied PSNR accepted, dB.
const MIN_PSNR_DB: f64 = 50.0;
/// Scale of the difference image, so that small errors are visible.
const DIFF_GAIN: u16 = 8;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn assets() -> PathBuf {
    root().join("assets/character")
}

/// The character's scene, rigged once per test run.
fn scene() -> &'static Scene {
    static SCENE: OnceLock<Scene> = OnceLock::new();
    SCENE.get_or_init(common::character_scene)
}

fn render_pose(pose: &Pose) -> RgbaImage {
    render_pose_in(scene(), pose)
}

fn render_pose_in(scene: &Scene, pose: &Pose) -> RgbaImage {
    let positions = scene.pose_positions(pose).expect("the pose applies");
    render::rgba_from_pixmap(&scene.render(&positions).expect("renders"))
}

fn load_pose(name: &str) -> Pose {
    let path = assets().join("poses").join(format!("{name}.json"));
    serde_json::from_str(&std::fs::read_to_string(&path).expect("a pose file")).expect("a pose")
}

/// (largest premultiplied channel difference, premultiplied PSNR in dB).
fn difference(a: &RgbaImage, b: &RgbaImage) -> (u8, f64) {
    let max = render::max_channel_diff(&render::premultiplied(a), &render::premultiplied(b));
    (max, render::psnr_premultiplied(a, b))
}

fn within_tolerance(a: &RgbaImage, b: &RgbaImage) -> bool {
    let (max, psnr) = difference(a, b);
    max <= MAX_CHANNEL_DIFF && psnr >= MIN_PSNR_DB
}

fn diff_image(a: &RgbaImage, b: &RgbaImage) -> RgbaImage {
    let (pa, pb) = (render::premultiplied(a), render::premultiplied(b));
    let (pa, pb) = (pa.as_raw(), pb.as_raw());
    RgbaImage::from_fn(a.width(), a.height(), |x, y| {
        let i = 4 * (y * a.width() + x) as usize;
        let d = |k: usize| (u16::from(pa[i + k].abs_diff(pb[i + k])) * DIFF_GAIN).min(255) as u8;
        let alpha = d(3);
        Rgba([d(0).max(alpha), d(1).max(alpha), d(2).max(alpha), 255])
    })
}

/// Compares `actual` with `golden/<name>.png` (or writes it under `SINEW_BLESS=1`).
fn check_golden(name: &str, actual: &RgbaImage) {
    let golden = root().join("golden").join(format!("{name}.png"));
    if std::env::var("SINEW_BLESS").is_ok_and(|v| v == "1") {
        save_png(&golden, actual).expect("writes the golden image");
        eprintln!("blessed {}", golden.display());
        return;
    }
    let expected = load_png(&golden).unwrap_or_else(|e| {
        panic!("{e}: no golden image for '{name}'; review the render and bless it with SINEW_BLESS=1 cargo test --test golden")
    });
    if within_tolerance(actual, &expected) {
        return;
    }
    let (max, psnr) = difference(actual, &expected);
    let out = failures_dir();
    let actual_path = out.join(format!("{name}.actual.png"));
    let diff_path = out.join(format!("{name}.diff.png"));
    save_png(&actual_path, actual).expect("writes the actual render");
    if actual.dimensions() == expected.dimensions() {
        save_png(&diff_path, &diff_image(actual, &expected)).expect("writes the diff");
    }
    panic!(
        "'{name}' differs from {}: max channel difference {max} (allowed {MAX_CHANNEL_DIFF}), PSNR {psnr:.1} dB (required {MIN_PSNR_DB}); actual: {}, diff: {}",
        golden.display(),
        actual_path.display(),
        diff_path.display()
    );
}

fn failures_dir() -> PathBuf {
    let dir = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target"))
        .join("golden-failures");
    std::fs::create_dir_all(&dir).expect("creates the failures folder");
    dir
}

#[test]
fn rest_pose_matches_golden() {
    check_golden("rest", &render_pose(&Pose::default()));
}

#[test]
fn bundled_poses_match_golden() {
    for name in ["reach", "crouch", "stretch", "lift"] {
        check_golden(&format!("pose_{name}"), &render_pose(&load_pose(name)));
    }
}

#[test]
fn bundled_animations_match_golden_at_fixed_times() {
    let animations: std::collections::BTreeMap<String, serde_json::Value> = serde_json::from_str(
        &std::fs::read_to_string(assets().join("animations.json")).expect("animations.json"),
    )
    .expect("animations.json parses");
    let animations = sinew::anim::parse_animations(&animations).expect("the animations check");
    for (name, times_s) in [
        ("walk", [0.25, 0.6]),
        ("wave", [0.4, 1.1]),
        ("lift", [0.5, 1.0]),
    ] {
        let animation = &animations[name];
        for t in times_s {
            let pose = animation.sample(t, true);
            check_golden(
                &format!("{name}_{:04}ms", (t * 1000.0) as u32),
                &render_pose(&pose),
            );
        }
    }
}

#[test]
fn a_two_degree_turn_fails() {
    // The reach pose with one forearm turned 2° further must not pass as the reach pose.
    let mut pose = load_pose("reach");
    let forearm = pose
        .bones
        .entry("arm_lower_l".into())
        .or_insert_with(BonePose::default);
    forearm.rotate += 2.0;
    let turned = render_pose(&pose);
    let reference = render_pose(&load_pose("reach"));
    let (max, psnr) = difference(&turned, &reference);
    eprintln!("2° forearm turn: max channel difference {max}, PSNR {psnr:.1} dB");
    assert!(
        !within_tolerance(&turned, &reference),
        "a 2° turn passed the golden tolerance"
    );
}

#[test]
fn rig_and_render_are_deterministic_across_thread_counts() {
    // Weights, skinning and rendering all run on rayon; one thread and three must agree to
    // the byte.
    let pose = load_pose("crouch");
    let in_pool = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool")
            .install(|| render_pose_in(&common::character_scene(), &pose))
    };
    assert_eq!(in_pool(1).as_raw(), in_pool(3).as_raw());
}
