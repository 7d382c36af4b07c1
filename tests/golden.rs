//! Golden-image tests: the bundled character, rigged from its layers and handles with default
//! options, rendered at rest, in the bundled poses (`assets/character/poses/`) and in its
//! bundled animations at fixed times, and in its second skin, compared with the reviewed PNGs in
//! `golden/`.
//!
//! Tolerance: on premultiplied RGBA8 (what compositing shows; the color of invisible pixels
//! is not compared), the largest channel difference must be at most 2 and the PSNR at least
//! 50 dB (`common::golden::premultiplied_tolerance`). Renders are deterministic, so on the machine that blessed
//! the references the difference is zero; the slack absorbs floating-point differences
//! between machines. One bone turned by 2° moves edges by whole pixels and fails both
//! (`a_two_degree_turn_fails`).
//!
//! A failing comparison writes `target/golden-failures/<name>.actual.png` and
//! `<name>.diff.png` (the difference ×8) and names them. To accept new renders on purpose:
//! `SINEW_BLESS=1 cargo test --test golden`, then look at every PNG in `golden/` before
//! committing.

mod common;

use common::golden::{premultiplied_difference, premultiplied_tolerance};
use image::RgbaImage;
use sinew::pipeline::Scene;
use sinew::rig::Pose;
use std::path::PathBuf;
use std::sync::OnceLock;

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

/// Compares `actual` with `golden/<name>.png` (or writes it under `SINEW_BLESS=1`).
fn check_golden(name: &str, actual: &RgbaImage) {
    common::golden::check(name, actual, "golden", premultiplied_tolerance);
}

fn render_pose(pose: &Pose) -> RgbaImage {
    render_pose_in(scene(), pose)
}

/// What `sinew pose --pose P -o OUT.png` draws: the one pose path, then the one draw.
fn render_pose_in(scene: &Scene, pose: &Pose) -> RgbaImage {
    let positions = scene.pose_positions(pose).expect("the pose applies");
    sinew::playback::render_posed(scene, &positions, pose).expect("renders")
}

fn load_pose(name: &str) -> Pose {
    let path = assets().join("poses").join(format!("{name}.json"));
    serde_json::from_str(&std::fs::read_to_string(&path).expect("a pose file")).expect("a pose")
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
        ("walk", &[0.25, 0.6][..]),
        // 0.4 s and 1.1 s: the open hand (attachment keys); 0.6 s: the slot's own closed hand.
        ("wave", &[0.4, 0.6, 1.1]),
        ("lift", &[0.5, 1.0]),
        // The belly squash (deform keys) on landing, and the tail's physics mid-hop.
        ("hop", &[0.4, 0.67]),
    ] {
        let animation = &animations[name];
        for &t in times_s {
            // What `sinew pose --anim NAME --time T` and every frame of `sinew render` show.
            let frame =
                sinew::playback::play(scene(), name, animation, &[t], true, &Default::default())
                    .expect("plays")
                    .remove(0);
            let positions = scene()
                .positions_from_transforms(
                    &frame.transforms,
                    &frame.pose,
                    sinew::skin::Blend::Linear,
                )
                .expect("positions");
            check_golden(
                &format!("{name}_{:04}ms", (t * 1000.0) as u32),
                &sinew::playback::render_posed(scene(), &positions, &frame.pose).expect("renders"),
            );
        }
    }
}

#[test]
fn skin_swap_matches_golden() {
    // The `pail` skin swaps the lantern for a pail (another attachment of the `bag` slot), at
    // rest and in the crouch pose; without a skin the same scene draws the lantern (`rest`).
    let mut pail = common::character_scene();
    pail.set_skins(&["pail".to_string()])
        .expect("the demo has a pail skin");
    check_golden("skin_pail_rest", &render_pose_in(&pail, &Pose::default()));
    check_golden(
        "skin_pail_crouch",
        &render_pose_in(&pail, &load_pose("crouch")),
    );
}

#[test]
fn a_two_degree_turn_fails() {
    // The reach pose with one forearm turned 2° further must not pass as the reach pose.
    let mut pose = load_pose("reach");
    let forearm = pose.bones.entry("arm_lower_l".into()).or_default();
    forearm.rotate += 2.0;
    let turned = render_pose(&pose);
    let reference = render_pose(&load_pose("reach"));
    let (max, psnr) = premultiplied_difference(&turned, &reference);
    eprintln!("2° forearm turn: max channel difference {max}, PSNR {psnr:.1} dB");
    assert!(
        premultiplied_tolerance(&turned, &reference).is_err(),
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
