//! One path from an animation and a time to posed vertices and pixels: a frame is a function of
//! (rig, animation, time), whatever the frame rate and whatever was played before it.
//!
//! Every bundled animation is rendered at 24 and at 30 fps the way `sinew render` does
//! (`playback::play` + `playback::render_animation`) and each frame is compared with the
//! single-frame pose at its time, the way `sinew pose --anim NAME --time T` poses it
//! (`Scene::handle_transforms` of the sampled pose): vertices within 0.01 px, pixels at PSNR
//! ≥ 50 dB. The same holds for a rig with momentum (secondary motion simulated at a fixed step
//! from the animation's start), where the single frame is asked of a fresh playhead.

mod common;

use image::RgbaImage;
use sinew::anim::Animation;
use sinew::pipeline::Scene;
use sinew::playback::{self, RenderSettings};
use sinew::scene::{PlayOptions, Playhead};
use sinew::skin::Blend;
use std::collections::BTreeMap;

const VERTEX_TOLERANCE_PX: f64 = 0.01;
const MIN_PSNR_DB: f64 = 50.0;

fn animations() -> BTreeMap<String, Animation> {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/character/animations.json");
    let json: BTreeMap<String, serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(path).expect("animations.json"))
            .expect("animations.json parses");
    sinew::anim::parse_animations(&json).expect("the animations check")
}

/// The largest distance between two sets of posed parts, px.
fn apart_px(a: &[Vec<sinew::geom::Point>], b: &[Vec<sinew::geom::Point>]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| {
            assert_eq!(p.len(), q.len());
            p.iter().zip(q).map(|(u, v)| (u - v).norm())
        })
        .fold(0.0, f64::max)
}

/// Renders every animation at 24 and 30 fps and checks each frame against the single-frame
/// pose at its time; returns the worst vertex distance and PSNR seen.
fn check_frames_against_single_poses(scene: &Scene, animations: &BTreeMap<String, Animation>) {
    for (name, animation) in animations {
        for fps in [24.0, 30.0] {
            let settings = RenderSettings {
                fps,
                ..Default::default()
            };
            let images = playback::render_animation(scene, name, animation, &settings, &|| {})
                .expect("renders");
            let times = playback::frame_times(animation.duration_s(), fps).expect("frame times");
            let frames = playback::play(scene, name, animation, &times, true, &Default::default())
                .expect("plays");
            assert_eq!(images.len(), times.len());
            let (mut worst_px, mut worst_db) = (0.0_f64, f64::INFINITY);
            for ((&time_s, frame), image) in times.iter().zip(&frames).zip(&images) {
                // A fresh playhead asked for this one time: nothing played before it.
                let mut head = Playhead::new(
                    scene,
                    animation,
                    PlayOptions {
                        looping: true,
                        ..Default::default()
                    },
                );
                let single = head.frame(time_s).expect("the single frame");
                let played = scene
                    .positions_from_transforms(&frame.transforms, &frame.pose, Blend::Linear)
                    .expect("positions");
                let posed = scene
                    .positions_from_transforms(&single.transforms, &single.pose, Blend::Linear)
                    .expect("positions");
                let px = apart_px(&played, &posed);
                let alone: RgbaImage =
                    playback::render_posed(scene, &posed, &single.pose).expect("draws");
                let db = sinew::render::psnr_rgba(image, &alone);
                worst_px = worst_px.max(px);
                worst_db = worst_db.min(db);
                assert!(
                    px <= VERTEX_TOLERANCE_PX,
                    "{name} at {fps} fps, t = {time_s:.4} s: the rendered frame is {px:.3e} px \
                     from the single pose"
                );
                assert!(
                    db >= MIN_PSNR_DB,
                    "{name} at {fps} fps, t = {time_s:.4} s: PSNR {db:.1} dB against the single pose"
                );
            }
            println!(
                "{name} at {fps} fps: {} frames, worst {worst_px:.1e} px, PSNR ≥ {worst_db:.1} dB",
                times.len()
            );
        }
    }
}

#[test]
fn bundled_animations_render_as_their_single_frame_poses_at_24_and_30_fps() {
    let scene = common::character_scene();
    check_frames_against_single_poses(&scene, &animations());
}

#[test]
fn frames_with_momentum_do_not_depend_on_the_frame_rate() {
    // The tail carries momentum: its motion is simulated from the animation's start at the rig's
    // fixed step, so a frame at t is the same whether played at 24 fps, at 30 fps, or alone.
    let (mut doc, images) = common::character_rig();
    // Momentum instead of the tail's physics constraint (the two are not combined).
    doc.handles.physics.clear();
    for name in ["tail_4", "tail_5", "tail_6"] {
        doc.options.ik.momentum.insert(name.into(), 0.03);
    }
    let scene = Scene::new(doc, &images).expect("a scene");
    // The walk with the tail's tip left unkeyed: free, it carries momentum.
    let animations: BTreeMap<String, Animation> = animations()
        .into_iter()
        .filter(|(name, _)| name == "walk")
        .map(|(name, mut walk)| {
            walk.bones
                .retain(|bone, _| !["tail_4", "tail_5", "tail_6"].contains(&bone.as_str()));
            (name, walk)
        })
        .collect();
    check_frames_against_single_poses(&scene, &animations);
    // And the motion is really secondary: the tail is not where forward kinematics puts it.
    let walk = &animations["walk"];
    let mut head = Playhead::new(&scene, walk, PlayOptions::default());
    let frame = head.frame(0.5).expect("a frame");
    let fk = scene.handle_transforms(&frame.pose).expect("fk");
    let lagged = frame
        .transforms
        .iter()
        .zip(&fk)
        .map(|(a, b)| (a.translation - b.translation).norm())
        .fold(0.0, f64::max);
    println!("momentum moves the tail up to {lagged:.2} px from forward kinematics");
    assert!(
        lagged > 0.5,
        "momentum left the tail where FK puts it ({lagged} px)"
    );
}

#[test]
fn no_bone_changes_length_under_ik_in_the_bundled_animations() {
    // Bones are rigid under the skinning IK (the rig allows no stretch): every bone's linear
    // part has the singular values forward kinematics gives it, in every frame of every
    // bundled animation, while the IK moves bones away from forward kinematics.
    let scene = common::character_scene();
    let bones = scene.doc.handles.bones.len();
    let mut moved_by_ik = 0;
    for (name, animation) in animations() {
        let times = playback::frame_times(animation.duration_s(), 30.0).expect("frame times");
        let frames = sinew::scene::frames(&scene, &animation, &times, PlayOptions::default())
            .expect("plays");
        let mut worst = 0.0_f64;
        for frame in &frames {
            let mut fk_pose = frame.pose.clone();
            fk_pose.ik.clear();
            let fk = scene.handle_transforms(&fk_pose).expect("fk");
            for (solved, fk) in frame.transforms[..bones].iter().zip(&fk[..bones]) {
                let (s, f) = (
                    solved.linear.svd(false, false).singular_values,
                    fk.linear.svd(false, false).singular_values,
                );
                worst = worst.max((s[0] - f[0]).abs()).max((s[1] - f[1]).abs());
                if (solved.linear - fk.linear).norm() > 1e-3 {
                    moved_by_ik += 1;
                }
            }
        }
        println!("{name}: bone scales differ from forward kinematics by {worst:.1e} at most");
        assert!(worst < 1e-9, "{name}: a bone changed length by {worst}");
    }
    assert!(moved_by_ik > 0, "no animation turns a bone by IK");
}
