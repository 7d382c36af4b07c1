//! Editor frame time while a point of the bundled character is dragged in pose mode.
//!
//! Drives the real editor (`sinew::editor::EditorApp`) through egui_kittest without a window:
//! each measured frame is one pointer move of a drag across the torso, so it includes egui's
//! layout, the skinning-IK solve (warm-started), skinning and building the textured meshes —
//! everything but the GPU upload and draw, which the GPU does (Mesa's software GL without
//! one). Prints the median, the 10th–90th percentile range and the worst frame (the first
//! frame of the drag included).
//!
//! Target: under 16 ms per frame (60 Hz). `cargo bench --bench editor`.

#[path = "../tests/common/mod.rs"]
mod common;

use egui_kittest::Harness;
use sinew::document::Document;
use sinew::editor::{EditorApp, Mode};
use sinew::geom::Point;
use std::time::Instant;

/// Frames measured (pointer moves during one drag).
const FRAMES: usize = 120;

fn main() {
    let scene = common::character_scene();
    let assets = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/character");
    let mut doc = scene.doc.clone();
    for part in &mut doc.parts {
        part.image = assets.join(&part.image).to_string_lossy().into_owned();
    }
    // Removed when dropped at the end of main, or while a panic unwinds.
    let dir = tempfile::Builder::new()
        .prefix("sinew-bench-editor-")
        .tempdir()
        .expect("scratch dir");
    let path = dir.path().join("character.json");
    doc.save(&path).expect("saved");
    let mut app = EditorApp::new(Document::open(&path).expect("opens"));
    app.mode = Mode::Pose;
    let mut h = Harness::builder()
        .with_size(eframe::egui::vec2(1280.0, 800.0))
        .build_ui_state(|ui, app: &mut EditorApp| app.frame(ui), app);
    h.run();
    // The editor precomputes the skinning IK on another thread as soon as the rig is posable;
    // an animator takes longer than this to reach for the mouse.
    std::thread::sleep(std::time::Duration::from_millis(500));
    // Grip the torso's vertex nearest its centroid.
    let torso = &scene
        .doc
        .parts
        .iter()
        .find(|p| p.name == "torso")
        .expect("torso")
        .mesh;
    let n = torso.vertices.len() as f64;
    let c = torso
        .vertices
        .iter()
        .fold(Point::origin(), |a, p| a + p.coords / n);
    let grip = *torso
        .vertices
        .iter()
        .min_by(|a, b| {
            let d = |p: &Point| (p - c).norm();
            d(a).total_cmp(&d(b))
        })
        .expect("vertices");
    let placed = h.state().placed.expect("drawn");
    h.drag_at(placed.screen_from_canvas(grip));
    h.step();
    let mut frames_ms = Vec::with_capacity(FRAMES);
    let mut own_ms = Vec::with_capacity(FRAMES);
    for k in 0..FRAMES {
        let a = k as f64 / FRAMES as f64 * std::f64::consts::TAU;
        let to = Point::new(grip.x + 40.0 * a.sin(), grip.y - 30.0 * (1.0 - a.cos()));
        h.hover_at(placed.screen_from_canvas(to));
        let start = Instant::now();
        h.step();
        frames_ms.push(start.elapsed().as_secs_f64() * 1e3);
        own_ms.push(h.state().last_frame_ms);
    }
    h.drop_at(placed.screen_from_canvas(grip));
    h.step();
    let report = |name: &str, v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        let q = |f: f64| v[((v.len() - 1) as f64 * f).round() as usize];
        println!(
            "editor/{name}: median {:.2} ms [p10 {:.2} – p90 {:.2}], worst {:.2} ms over {} frames",
            q(0.5),
            q(0.1),
            q(0.9),
            q(1.0),
            v.len()
        );
    };
    report("drag_frame", &mut frames_ms);
    report("drag_frame_app_only", &mut own_ms);
    assert!(
        h.state().doc.state().pose.ik.len() == 1,
        "the drag did not reach the document: {:?}",
        h.state().message
    );
}
