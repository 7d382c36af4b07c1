//! The editor driven through egui_kittest: real frames, simulated pointer and keys, checked
//! against the document.

use super::rig_mode::distance;
use super::*;
use crate::rig::PointHandle;
use eframe::egui::Pos2;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use std::path::Path;
use std::sync::Arc;

mod files;
mod workflow;

/// Frames a background weight build may take before a test gives up (50 ms apart).
const BUILD_FRAMES: usize = 1200;

fn harness(app: EditorApp) -> Harness<'static, EditorApp> {
    Harness::builder()
        .with_size(egui::vec2(1200.0, 800.0))
        .build_ui_state(|ui, app: &mut EditorApp| app.frame(ui), app)
}

/// The bundled character rigged with default options, saved (with absolute image paths) in a
/// fresh folder.
fn character_rig(name: &str) -> PathBuf {
    let assets = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/character");
    let list: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(assets.join("layers.json")).expect("layers.json"),
    )
    .expect("layers.json parses");
    let paths: Vec<PathBuf> = list["layers"]
        .as_array()
        .expect("a layer list")
        .iter()
        .map(|n| assets.join(format!("{}.png", n.as_str().expect("a name"))))
        .collect();
    let layers = crate::pipeline::load_layers(&paths).expect("layers");
    let handles: crate::rig::Handles = serde_json::from_str(
        &std::fs::read_to_string(assets.join("handles.json")).expect("handles.json"),
    )
    .expect("handles parse");
    let dir = std::env::temp_dir().join(format!("sinew-editor-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let (mut doc, _) = crate::pipeline::build_rig(&layers, &assets, &Default::default(), &handles)
        .expect("the character rigs");
    for part in &mut doc.parts {
        part.image = assets.join(&part.image).to_string_lossy().into_owned();
    }
    let path = dir.join("character.json");
    doc.save(&path).expect("saved");
    path
}

/// The editor on [`character_rig`]`(name)`, after its first frames.
fn open_character(name: &str) -> Harness<'static, EditorApp> {
    let path = character_rig(name);
    let mut h = harness(EditorApp::new(Document::open(&path).expect("opens")));
    h.run();
    h
}

fn screen(h: &Harness<'_, EditorApp>, canvas_px: [f64; 2]) -> Pos2 {
    h.state()
        .placed
        .expect("the canvas was drawn")
        .screen_from_canvas(canvas_px)
}

/// Press at `from`, move in steps, release at `to` (canvas px).
fn drag(h: &mut Harness<'_, EditorApp>, from: [f64; 2], to: [f64; 2]) {
    h.drag_at(screen(h, from));
    h.step();
    for k in 1..=4 {
        let t = k as f64 / 4.0;
        let p = [
            from[0] + t * (to[0] - from[0]),
            from[1] + t * (to[1] - from[1]),
        ];
        h.hover_at(screen(h, p));
        h.step();
    }
    h.drop_at(screen(h, to));
    h.step();
    h.run();
}

fn wait_for_weights(h: &mut Harness<'_, EditorApp>) {
    for _ in 0..BUILD_FRAMES {
        h.step();
        if !h.state().computing() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    h.run();
    assert!(!h.state().computing(), "weights took too long");
}

/// A point well inside the torso at rest, canvas px.
fn torso_point(h: &Harness<'_, EditorApp>) -> [f64; 2] {
    part_point(h, "torso")
}

#[test]
fn rig_weigh_pose_undo_through_the_ui() {
    let mut h = open_character("flow");
    h.get_by_label("Weights are up to date");
    let bones_before = h.state().doc.state().handles.bones.len();
    let inside = torso_point(&h);
    let tail = [inside[0] + 12.0, inside[1] + 8.0];

    // Rig mode: draw a bone inside the torso with the bone tool.
    h.get_by_label("Bone").click();
    h.run();
    drag(&mut h, inside, tail);
    let handles = &h.state().doc.state().handles;
    assert_eq!(
        handles.bones.len(),
        bones_before + 1,
        "{:?}",
        h.state().message
    );
    let added = handles.bones.last().expect("a bone");
    assert!(
        distance(added.tail, tail) < 1.0,
        "{added:?}, wanted tail {tail:?}"
    );
    assert!(
        h.state().doc.posable().is_none(),
        "new handle: weights stale"
    );
    h.get_by_label("Weights need computing");

    // Computing runs in the background; the UI keeps drawing frames meanwhile.
    h.get_by_label("Compute weights").click();
    h.step();
    assert!(h.state().computing());
    h.step();
    h.get_by_label("Cancel");
    wait_for_weights(&mut h);
    assert!(h.state().doc.posable().is_some(), "{:?}", h.state().message);

    // Pose mode: drag a point of the torso; the pose gets a drag and the shape moves.
    h.key_press(Key::Num2);
    h.run();
    assert_eq!(h.state().mode, Mode::Pose);
    // The new bone is still selected, and its gizmo sits where the torso will be gripped: a
    // click on empty canvas deselects it.
    assert!(h.state().selected.is_some());
    click(&mut h, [4.0, 4.0]);
    assert_eq!(h.state().selected, None);
    let grip = torso_point(&h);
    drag(&mut h, grip, [grip[0] + 25.0, grip[1] - 15.0]);
    let pose = &h.state().doc.state().pose;
    assert_eq!(pose.ik.len(), 1, "{:?}", h.state().message);
    assert!(distance(pose.ik[0].at, grip) < 1.0);
    assert!(distance(pose.ik[0].to, [grip[0] + 25.0, grip[1] - 15.0]) < 1.0);
    let posed = h.state().pose_mode.posed.as_ref().expect("posed");
    let moved = posed
        .positions
        .iter()
        .flatten()
        .zip(
            h.state()
                .doc
                .posable()
                .expect("rig")
                .rest_positions()
                .iter()
                .flatten(),
        )
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(moved > 10.0, "the shape moved only {moved} px");

    // Undo the drag with the keyboard, then redo it.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert!(h.state().doc.state().pose.ik.is_empty());
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    h.run();
    assert_eq!(h.state().doc.state().pose.ik.len(), 1);
}

#[test]
fn bad_files_show_a_message_and_keep_the_document() {
    let path = character_rig("bad");
    let dir = path.parent().expect("a folder").to_path_buf();
    let mut app = EditorApp::new(Document::open(&path).expect("opens"));
    let layers = app.doc.state().layers.len();

    let corrupt = dir.join("corrupt.png");
    std::fs::write(&corrupt, b"\x89PNG\r\n\x1a\nnot really").expect("written");
    app.import_layer(&corrupt);
    assert!(app.message.is_some());
    assert_eq!(app.doc.state().layers.len(), layers);

    let mut newer: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).expect("read")).expect("json");
    newer["version"] = serde_json::json!(99);
    let newer_path = dir.join("newer.json");
    std::fs::write(&newer_path, newer.to_string()).expect("written");
    app.message = None;
    app.open(&newer_path);
    let message = app.message.clone().expect("a message");
    assert!(message.contains("newer.json"), "{message}");
    assert_eq!(app.doc.path.as_deref(), Some(path.as_path()));
    assert_eq!(app.doc.state().layers.len(), layers);

    // The message reaches the window's status bar.
    let mut h = harness(app);
    h.run();
    h.get_by_label(&message);
}

/// Steps frames (up to 5 s) until `done` says the background work is.
fn wait_for(h: &mut Harness<'_, EditorApp>, done: impl Fn(&EditorApp) -> bool) {
    for _ in 0..500 {
        if done(h.state()) {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
        h.step();
    }
}

/// A fresh folder `dir` with `bar.png` in it: a 96×48 canvas, opaque over x 8..88, y 8..40.
fn bar_png(dir: &Path) -> PathBuf {
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).expect("scratch dir");
    let png = dir.join("bar.png");
    let bar = image::RgbaImage::from_fn(96, 48, |x, y| {
        let inside = (8..88).contains(&x) && (8..40).contains(&y);
        image::Rgba([200, 80, 40, if inside { 255 } else { 0 }])
    });
    crate::io::save_png(&png, &bar).expect("written");
    png
}

/// Clicks the text field labelled `label`, selects what it holds (Ctrl+A) and types `text`
/// over it.
fn type_into(h: &mut Harness<'_, EditorApp>, label: &str, text: &str) {
    h.get_by_label(label).click();
    h.run();
    h.key_press_modifiers(Modifiers::COMMAND, Key::A);
    h.run();
    h.get_by_label(label).type_text(text);
    h.run();
}

/// An editor on a document of one 96×48 bar layer (saved as `DIR/bar.png`), never rigged.
fn never_rigged_bar(dir: &Path) -> Harness<'static, EditorApp> {
    let png = bar_png(dir);
    let mut app = EditorApp::new(Document::new());
    app.import_layer(&png);
    let mut h = harness(app);
    h.run();
    // Saving needs meshes: a document never rigged is traced and meshed to be written.
    assert!(h.state().doc.save_needs_build());
    h
}

#[test]
fn saving_a_never_rigged_document_runs_off_the_ui_thread() {
    let dir = std::env::temp_dir().join(format!("sinew-editor-save-{}", std::process::id()));
    let mut h = never_rigged_bar(&dir);
    let path = dir.join("bar.json");
    let message = h.state_mut().save_to(&path);
    assert!(message.starts_with("saving"), "{message}");
    assert!(h.state().saving());
    // A second save waits for the first.
    let again = h.state_mut().save_to(&path);
    assert!(again.starts_with("still saving"), "{again}");
    wait_for(&mut h, |app| !app.saving());
    assert!(!h.state().saving(), "the save did not finish");
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.starts_with("saved"), "{message}");
    assert_eq!(h.state().doc.path.as_deref(), Some(path.as_path()));
    assert!(!h.state().doc.dirty());
    assert!(view_path(&path).is_file());
    assert_eq!(
        Document::open(&path).expect("opens").state().layers.len(),
        1
    );

    // An edit made while the save is written keeps the document modified.
    h.state_mut().save_to(&path);
    h.state_mut().apply(Command::AddPoint(PointHandle {
        name: "late".into(),
        at: [40.0, 24.0],
    }));
    wait_for(&mut h, |app| !app.saving());
    assert!(h.state().doc.dirty());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Presses the window's close button, as eframe reports it; true when the editor cancelled
/// the close.
fn press_close_button(h: &mut Harness<'_, EditorApp>) -> bool {
    h.input_mut()
        .viewports
        .entry(egui::ViewportId::ROOT)
        .or_default()
        .events
        .push(egui::ViewportEvent::Close);
    h.step();
    let cancelled = h
        .output()
        .viewport_output
        .get(&egui::ViewportId::ROOT)
        .is_some_and(|v| v.commands.contains(&egui::ViewportCommand::CancelClose));
    h.run();
    cancelled
}

#[test]
fn closing_with_unsaved_changes_asks_first() {
    use closing::Closing;
    let dir = std::env::temp_dir().join(format!("sinew-editor-close-{}", std::process::id()));
    let mut h = never_rigged_bar(&dir);
    assert!(h.state().doc.dirty());
    let png = dir.join("bar.png");
    let png_bytes = std::fs::read(&png).expect("bar.png");
    // The File menu's path field holds the imported PNG: Save must not write over it.
    h.state_mut().open_path = png.display().to_string();
    assert!(press_close_button(&mut h), "the close was not cancelled");
    assert_eq!(h.state().closing(), Closing::Asking);
    h.get_by_label(
        "Save the changes before closing? (Type a .json file name in the File menu first.)",
    );
    h.get_by_label("Save").click();
    h.run();
    assert_eq!(h.state().closing(), Closing::Open);
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains(".json file name"), "{message}");
    assert_eq!(std::fs::read(&png).expect("bar.png"), png_bytes);

    // Keys and drops do not reach the document behind the dialog; Escape cancels it.
    h.state_mut().request_close();
    h.run();
    let handles = h.state().doc.state().handles.clone();
    h.key_press(Key::P);
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(h.state().closing(), Closing::Asking);
    assert_eq!(h.state().doc.state().handles, handles);
    assert_eq!(
        h.state().doc.state().layers.len(),
        1,
        "undo ran behind the dialog"
    );
    h.key_press(Key::Escape);
    h.run();
    assert_eq!(h.state().closing(), Closing::Open);

    // With a file name, the save runs off the UI thread and the window closes once it is
    // written.
    let path = dir.join("bar.json");
    h.state_mut().open_path = path.display().to_string();
    assert!(press_close_button(&mut h));
    h.get_by_label(&format!(
        "Save the changes to {} before closing?",
        path.display()
    ));
    h.get_by_label("Save").click();
    h.run();
    // (A small save may already be done by the end of the frames run.)
    assert!(
        h.state().saving() || h.state().closing() == Closing::Allowed,
        "{:?}",
        h.state().closing()
    );
    if h.state().saving() {
        assert_eq!(h.state().closing(), Closing::Waiting);
    }
    wait_for(&mut h, |app| app.closing() == Closing::Allowed);
    assert_eq!(h.state().closing(), Closing::Allowed);
    assert!(!h.state().doc.dirty());
    assert!(path.is_file());
    // Once allowed, the close button is no longer cancelled.
    assert!(!press_close_button(&mut h));

    // Discarding closes at once; a clean document closes without asking.
    let mut h = never_rigged_bar(&dir);
    h.state_mut().request_close();
    h.run();
    h.get_by_label("Don't save").click();
    h.run();
    assert_eq!(h.state().closing(), Closing::Allowed);
    let mut clean = harness(EditorApp::new(Document::new()));
    assert!(!press_close_button(&mut clean));
    assert_eq!(clean.state().closing(), Closing::Allowed);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_save_still_running_is_reported_after_reopening_and_finished_at_exit() {
    let dir = std::env::temp_dir().join(format!("sinew-editor-reopen-{}", std::process::id()));
    let mut h = never_rigged_bar(&dir);
    let path = dir.join("bar.json");
    h.state_mut().save_to(&path);
    let other = character_rig("reopen-save");
    h.state_mut().open(&other);
    assert!(h.state().saving());
    wait_for(&mut h, |app| !app.saving());
    let message = h.state().message.clone().unwrap_or_default();
    assert_eq!(message, format!("saved {}", path.display()));
    // The save belonged to the closed document: the open one is untouched.
    assert_eq!(h.state().doc.path.as_deref(), Some(other.as_path()));
    assert!(!view_path(&path).exists());

    // At exit the editor waits for writes still under way.
    let mut h = never_rigged_bar(&dir);
    let path = dir.join("exit.json");
    h.state_mut().save_to(&path);
    let ctx = h.ctx.clone();
    h.state_mut().start_autosave(&path, &ctx);
    h.state_mut().finish_writes();
    assert!(path.is_file());
    assert!(crate::document::autosave_path(&path).is_file());
    assert!(!h.state().saving() && !h.state().autosaving());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn autosave_writes_a_never_rigged_document_off_the_ui_thread() {
    let dir = std::env::temp_dir().join(format!("sinew-editor-autosave-{}", std::process::id()));
    let mut h = never_rigged_bar(&dir);
    let path = dir.join("bar.json");
    let ctx = h.ctx.clone();
    h.state_mut().start_autosave(&path, &ctx);
    assert!(h.state().autosaving());
    wait_for(&mut h, |app| !app.autosaving());
    assert!(!h.state().autosaving(), "the autosave did not finish");
    assert_eq!(h.state().message, None);
    let autosaved = crate::document::autosave_path(&path);
    let reopened = Document::open(&autosaved).expect("the autosave opens");
    assert_eq!(reopened.state().layers.len(), 1);

    // A failure reaches the status bar.
    let nowhere = dir.join("missing/bar.json");
    h.state_mut().start_autosave(&nowhere, &ctx);
    wait_for(&mut h, |app| !app.autosaving());
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.starts_with("autosave failed"), "{message}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_help_overlay_lists_the_shortcuts() {
    let mut h = harness(EditorApp::new(Document::new()));
    h.run();
    h.key_press(Key::F1);
    h.run();
    for (keys, _) in SHORTCUTS {
        h.get_by_label(keys);
    }
}

#[test]
fn set_two_keys_and_scrub_the_timeline() {
    let mut h = open_character("animate");
    h.key_press(Key::Num3);
    h.run();
    assert_eq!(h.state().mode, Mode::Animate);
    let grip = torso_point(&h);
    let first = [grip[0] + 20.0, grip[1] - 10.0];
    drag(&mut h, grip, first);
    assert_eq!(
        h.state().edited_pose().ik.len(),
        1,
        "{:?}",
        h.state().message
    );
    h.get_by_label("Set key").click();
    h.run();
    for _ in 0..24 {
        h.get_by_label("Next frame").click();
        h.run();
    }
    assert!(
        (h.state().animate.time_s - 1.0).abs() < 1e-9,
        "{}",
        h.state().animate.time_s
    );
    // Grab the pin where the first key left it and move it to the other side.
    let second = [grip[0] - 20.0, grip[1] - 10.0];
    drag(&mut h, first, second);
    h.get_by_label("Set key").click();
    h.run();
    let anim = crate::document::animation_named(h.state().doc.state(), "animation");
    assert_eq!(crate::document::key_times(&anim), vec![0.0, 1.0]);
    for _ in 0..12 {
        h.get_by_label("Previous frame").click();
        h.run();
    }
    let halfway = h.state().edited_pose();
    assert_eq!(halfway.ik.len(), 1);
    assert!(
        distance(halfway.ik[0].to, [grip[0], grip[1] - 10.0]) < 1.0,
        "{:?}",
        halfway.ik[0].to
    );
    // The canvas shows that pose: the posed mesh was solved for it.
    assert_eq!(
        h.state().pose_mode.posed.as_ref().expect("posed").pose,
        halfway
    );
    // Setting keys is undoable like any edit.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    let anim = crate::document::animation_named(h.state().doc.state(), "animation");
    assert_eq!(crate::document::key_times(&anim), vec![0.0]);
}

#[test]
fn reopening_restores_the_view() {
    let path = character_rig("view");
    let mut app = EditorApp::new(Document::open(&path).expect("opens"));
    app.mode = Mode::Animate;
    app.view = Some(View {
        zoom: 2.5,
        pan: egui::vec2(-40.0, 12.0),
    });
    app.selected = Some("head".into());
    app.animate.time_s = 0.75;
    app.timeline.looping = false;
    app.timeline.onion.enabled = true;
    app.timeline.onion.frames = 3;
    app.render_settings.fps = 12.0;
    let message = app.save_to(&path);
    assert!(message.starts_with("saved"), "{message}");
    let mut reopened = EditorApp::new(Document::new());
    reopened.open(&path);
    assert_eq!(reopened.view_state(), app.view_state());
    assert!(reopened.message.is_none());
    // A view file written before loop, onion skins and render settings were kept still opens,
    // with their defaults.
    let old = r#"{"zoom": 1.5, "pan": [0, 0], "mode": "pose", "selected": null,
        "animation": "animation", "time_s": 0.0}"#;
    let state: ViewState = serde_json::from_str(old).expect("an older view file");
    assert!(state.looping);
    assert_eq!(state.onion, animate_mode::OnionOptions::default());
    assert_eq!(state.render, crate::playback::RenderSettings::default());
    // Hand-edited values come back inside the ranges the UI edits.
    let mut wild = state;
    wild.render.fps = 1e300;
    wild.render.scale = f64::NAN;
    wild.onion.frames = 1000;
    wild.onion.opacity = -3.0;
    reopened.restore_view(wild);
    let restored = reopened.view_state();
    assert_eq!(restored.render.fps, crate::playback::MAX_FPS);
    assert_eq!(restored.render.scale, 1.0);
    assert_eq!(restored.onion.frames, animate_mode::MAX_ONION_FRAMES);
    assert_eq!(restored.onion.opacity, 0.05);
}

#[test]
fn exports_for_spine_from_the_file_menu_function() {
    let path = character_rig("export");
    let mut app = EditorApp::new(Document::open(&path).expect("opens"));
    let dir = path.parent().expect("a folder").join("spine");
    // The menu's options reach the exporter: Spine 4.3, at most 2 influences per vertex.
    app.spine_options.version = crate::export::spine::SpineVersion::V4_3;
    app.spine_options.max_influences = Some(2);
    let message = app.export_spine(&dir);
    assert!(message.starts_with("exported"), "{message}");
    for file in ["character.json", "character.atlas"] {
        assert!(dir.join(file).is_file(), "{file} missing: {message}");
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("character.json")).expect("the skeleton"))
            .expect("JSON");
    let version = json["skeleton"]["spine"].as_str().expect("a version");
    assert!(version.starts_with("4.3"), "{version}");
    // Without current weights there is nothing to export, and nothing is written.
    app.apply(Command::AddPoint(PointHandle {
        name: "extra".into(),
        at: [10.0, 10.0],
    }));
    let empty = path.parent().expect("a folder").join("none");
    let message = app.export_spine(&empty);
    assert!(message.contains("compute"), "{message}");
    assert_eq!(std::fs::read_dir(&empty).map(|d| d.count()).unwrap_or(0), 0);
}

#[test]
fn renders_the_current_animation_in_the_background() {
    let path = character_rig("render");
    let mut h = harness(EditorApp::new(Document::open(&path).expect("opens")));
    let gif = path.parent().expect("a folder").join("nod.gif");
    key_nod(h.state_mut(), &[(0.0, 0.0), (0.5, 20.0)]);
    h.run();
    h.key_press(Key::Num3);
    h.run();
    type_into(&mut h, "Animation", "nod");
    h.get_by_label("File").click();
    h.run();
    h.get_by_label("Render…").click();
    h.run();
    type_into(
        &mut h,
        "Render the current animation to (.gif, .png sheet or a folder):",
        &gif.display().to_string(),
    );
    for (field, value) in [
        ("Frames per second", "8"),
        ("Scale (output px per canvas px)", "0.5"),
    ] {
        type_into(&mut h, field, value);
        h.key_press(Key::Enter);
        h.run();
    }
    // The button, not the window's title.
    h.get_by_role_and_label(egui::accesskit::Role::Button, "Render")
        .click();
    wait_for_render(&mut h, 50);
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.starts_with("rendered"), "{message}");
    let bytes = std::fs::read(&gif).expect("the GIF was written");
    assert!(bytes.starts_with(b"GIF89a"));
    // The settings reached the renderer: the GIF's logical screen is the half-scale canvas.
    let canvas_width = h.state().doc.state().layers[0].image.width();
    let width = u16::from_le_bytes([bytes[6], bytes[7]]);
    assert_eq!(u32::from(width), canvas_width.div_ceil(2));
    // An animation the document does not have: a message, no file.
    type_into(&mut h, "Animation", "nope");
    type_into(
        &mut h,
        "Render the current animation to (.gif, .png sheet or a folder):",
        &path.with_file_name("nope.gif").display().to_string(),
    );
    // The button, not the window's title.
    h.get_by_role_and_label(egui::accesskit::Role::Button, "Render")
        .click();
    wait_for_render(&mut h, 20);
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("nope"), "{message}");
    assert!(!path.with_file_name("nope.gif").exists());
}

/// Steps frames until the background render ends, sleeping `pause_ms` between them.
fn wait_for_render(h: &mut Harness<'_, EditorApp>, pause_ms: u64) {
    for _ in 0..BUILD_FRAMES {
        h.step();
        if !h.state().rendering() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(pause_ms));
    }
}

/// Keys animation "nod": the head turned `degrees` at each `time_s`.
fn key_nod(app: &mut EditorApp, keys: &[(f64, f64)]) {
    for &(time_s, degrees) in keys {
        assert!(app.apply(Command::SetKey {
            animation: "nod".into(),
            time_s,
            pose: head_turned(degrees),
        }));
    }
}

/// A pose with only the head turned by `degrees`.
fn head_turned(degrees: f64) -> Pose {
    let mut pose = Pose::default();
    pose.bones.insert(
        "head".into(),
        crate::rig::pose::BonePose {
            rotate: degrees,
            ..Default::default()
        },
    );
    pose
}

/// Press and release at `at` (canvas px) without moving.
fn click(h: &mut Harness<'_, EditorApp>, at: [f64; 2]) {
    h.drag_at(screen(h, at));
    h.step();
    h.drop_at(screen(h, at));
    h.step();
    h.run();
}

/// Where the document's pose shows `bone`'s head, canvas px.
fn shown_head(h: &Harness<'_, EditorApp>, bone: &str) -> [f64; 2] {
    let scene = h.state().doc.posable().expect("posable").clone();
    let shown = scene
        .handle_transforms(&h.state().doc.state().pose)
        .expect("forward kinematics");
    crate::rig::fk_edit::target(&scene.doc.handles, &shown, bone)
        .expect("a bone")
        .pivot_px
}

#[test]
fn rotate_with_r_and_grab_with_the_gizmo_in_pose_mode() {
    let mut h = open_character("gizmo");
    h.key_press(Key::Num2);
    h.run();
    // The chest bone runs up from (256, 262) to (256, 198): click its middle to select it.
    let pivot = [256.0, 262.0];
    click(&mut h, [256.0, 225.0]);
    assert_eq!(h.state().selected.as_deref(), Some("chest"));

    // R, then a quarter turn counter-clockwise on screen about the head, then a click.
    h.hover_at(screen(&h, [pivot[0] + 60.0, pivot[1]]));
    h.step();
    h.key_press(Key::R);
    h.step();
    for p in [
        [pivot[0] + 42.0, pivot[1] - 42.0],
        [pivot[0], pivot[1] - 60.0],
    ] {
        h.hover_at(screen(&h, p));
        h.step();
    }
    assert!(
        h.state().doc.state().pose.bones.is_empty(),
        "previewed, not committed"
    );
    click(&mut h, [pivot[0], pivot[1] - 60.0]);
    let rotate = h.state().doc.state().pose.bones["chest"].rotate;
    assert!((rotate - 90.0).abs() < 0.5, "turned {rotate}°");

    // Undo takes the whole turn back.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert!(h.state().doc.state().pose.bones.is_empty());

    // Escape cancels a modal grab.
    h.hover_at(screen(&h, [300.0, 300.0]));
    h.step();
    h.key_press(Key::G);
    h.step();
    h.hover_at(screen(&h, [320.0, 280.0]));
    h.step();
    h.key_press(Key::Escape);
    h.run();
    assert!(h.state().doc.state().pose.bones.is_empty());

    // Dragging the gizmo's centre moves the head by the drag on the canvas.
    drag(&mut h, pivot, [pivot[0] + 10.0, pivot[1] - 4.0]);
    let head = shown_head(&h, "chest");
    assert!(
        distance(head, [pivot[0] + 10.0, pivot[1] - 4.0]) < 0.5,
        "head at {head:?}"
    );
}

/// Steps frames until `done` holds (50 ms apart), or fails after [`BUILD_FRAMES`].
fn wait_until(h: &mut Harness<'_, EditorApp>, what: &str, done: impl Fn(&EditorApp) -> bool) {
    for _ in 0..BUILD_FRAMES {
        h.step();
        if done(h.state()) {
            h.run();
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    panic!("{what} took too long");
}

#[test]
fn cages_regions_mesh_preview_and_automatic_rig_in_rig_mode() {
    let mut h = open_character("rigtools");
    assert_eq!(h.state().mode, Mode::Rig);
    let before = h.state().doc.state().handles.clone();

    // A cage: four clicks, then a click on the first vertex closes it.
    h.get_by_label("Cage").click();
    h.run();
    let square = [
        [150.0, 150.0],
        [360.0, 150.0],
        [360.0, 380.0],
        [150.0, 380.0],
    ];
    for p in square {
        click(&mut h, p);
    }
    assert!(h.state().doc.state().handles.cages.is_empty(), "still open");
    click(&mut h, square[0]);
    let cages = &h.state().doc.state().handles.cages;
    assert_eq!(cages.len(), 1);
    assert_eq!(cages[0].polygon.len(), 4);
    assert!(distance(cages[0].polygon[2], square[2]) < 0.5);
    let cage = cages[0].name.clone();
    assert_eq!(h.state().selected.as_deref(), Some(cage.as_str()));

    // A region: three clicks and Enter.
    h.get_by_label("Region").click();
    h.run();
    for p in [[240.0, 250.0], [270.0, 250.0], [255.0, 280.0]] {
        click(&mut h, p);
    }
    h.key_press(Key::Enter);
    h.run();
    assert_eq!(h.state().doc.state().handles.regions.len(), 1);

    // The select tool drags the cage by its outline.
    h.get_by_label("Select").click();
    h.run();
    drag(&mut h, [255.0, 150.0], [265.0, 140.0]);
    let moved = &h.state().doc.state().handles.cages[0].polygon;
    assert!(distance(moved[0], [160.0, 140.0]) < 0.5, "{moved:?}");

    // The traced mesh, rebuilt live when a meshing option changes.
    h.get_by_label("Show the traced mesh").scroll_to_me();
    h.run();
    h.get_by_label("Show the traced mesh").click();
    wait_until(&mut h, "the mesh preview", |app| {
        !app.previewing() && app.preview_vertex_count().is_some()
    });
    let fine = h.state().preview_vertex_count().expect("a preview");
    let mut options = h.state().doc.state().options.clone();
    options.mesh.max_area_fraction *= 16.0;
    assert!(h.state_mut().apply(Command::SetOptions(options)));
    wait_until(&mut h, "the coarser preview", |app| {
        !app.previewing() && app.preview_vertex_count() != Some(fine)
    });
    let coarse = h.state().preview_vertex_count().expect("a preview");
    assert!(
        coarse < fine,
        "{coarse} vertices at a 16× area limit, {fine} before"
    );

    // The automatic rig replaces the handles; undo brings the hand-made ones back.
    let hand_made = h.state().doc.state().handles.clone();
    h.get_by_label("Propose handles").scroll_to_me();
    h.run();
    h.get_by_label("Propose handles").click();
    wait_until(&mut h, "the automatic rig", |app| {
        !app.rig_tools.proposing()
    });
    let proposed = h.state().doc.state().handles.clone();
    assert!(!proposed.bones.is_empty(), "{:?}", h.state().message);
    assert_ne!(proposed, hand_made);
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(h.state().doc.state().handles, hand_made);
    assert_ne!(hand_made, before);
}

/// Steps frames until colorize mode's background solve is done and the session has a result.
fn wait_for_colorize(h: &mut Harness<'_, EditorApp>) {
    for _ in 0..BUILD_FRAMES {
        h.step();
        let c = &h.state().colorize;
        if !c.solving() && c.session.as_ref().is_some_and(|s| s.result().is_some()) {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    h.run();
    let c = &h.state().colorize;
    assert!(
        c.session.as_ref().is_some_and(|s| s.result().is_some()),
        "no colorized result: {:?}",
        h.state().message
    );
}

/// Colorize mode's stroke count, if a line art is open.
fn stroke_count(h: &Harness<'_, EditorApp>) -> Option<usize> {
    let session = h.state().colorize.session.as_ref()?;
    Some(session.strokes().len())
}

/// Colorize mode's current result (the test fails without one).
fn colorize_result(h: &Harness<'_, EditorApp>) -> Arc<crate::colorize::Colorized> {
    let session = h.state().colorize.session.as_ref().expect("a session");
    session.result().expect("a result").clone()
}

/// A generated one-circle colorize scene of `size` px, its line art written as `file` in a
/// fresh scratch folder `sinew-editor-NAME-PID`: the scene, the folder and the line art's path.
fn one_circle_lineart(
    name: &str,
    size: u32,
    file: &str,
) -> (crate::colorize::synthetic::Scene, PathBuf, PathBuf) {
    let s = crate::colorize::synthetic::scene(&crate::colorize::synthetic::SceneSpec {
        size,
        shapes: 1,
        ..Default::default()
    });
    let dir = std::env::temp_dir().join(format!("sinew-editor-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let lineart = dir.join(file);
    crate::io::save_png(&lineart, &s.lineart).expect("written");
    (s, dir, lineart)
}

#[test]
fn colorize_two_scribbles_then_undo_one() {
    use crate::colorize::synthetic::PALETTE;
    let (s, dir, lineart) = one_circle_lineart("colorize", 128, "lineart.png");
    let corrupt = dir.join("corrupt.png");
    std::fs::write(&corrupt, b"\x89PNG\r\n\x1a\nnot really").expect("written");
    // Share of the non-line pixels of true color `region` that `image` colors `want`.
    let share = |image: &image::RgbaImage, region: [u8; 3], want: [u8; 3]| {
        let (mut n, mut good) = (0, 0);
        for (i, (t, p)) in s.truth.pixels().zip(image.pixels()).enumerate() {
            if !s.is_line[i] && [t[0], t[1], t[2]] == region {
                n += 1;
                good += ([p[0], p[1], p[2]] == want) as usize;
            }
        }
        good as f64 / n.max(1) as f64
    };

    let mut h = harness(EditorApp::new(Document::new()));
    h.run();
    h.key_press(Key::Num4);
    h.run();
    assert_eq!(h.state().mode, Mode::Colorize);
    // A corrupt PNG: a message, nothing opened.
    h.state_mut().open_lineart(&corrupt);
    assert!(h.state().colorize.session.is_none());
    assert!(h.state().message.is_some());
    h.state_mut().open_lineart(&lineart);
    h.run();
    assert!(
        h.state().colorize.session.is_some(),
        "{:?}",
        h.state().message
    );

    // The background's scribble along the top margin, the circle's across its middle.
    let (background, circle) = (&s.strokes[0].points, &s.strokes[1].points);
    h.state_mut().colorize.width_px = 4.0;
    h.state_mut().colorize.color = PALETTE[10];
    drag(&mut h, background[0], background[1]);
    h.state_mut().colorize.color = PALETTE[0];
    drag(&mut h, circle[0], circle[1]);
    let session = h.state().colorize.session.as_ref().expect("a session");
    assert_eq!(session.strokes().len(), 2, "{:?}", h.state().message);
    assert_eq!(session.palette(), vec![PALETTE[10], PALETTE[0]]);
    let drawn = &session.strokes()[1].points_px;
    assert!(distance(drawn[0], circle[0]) < 1.0, "{drawn:?}");
    assert!(distance(*drawn.last().expect("points"), circle[1]) < 1.0);
    wait_for_colorize(&mut h);
    let two = colorize_result(&h);
    assert!(share(&two.image, PALETTE[0], PALETTE[0]) > 0.98);
    assert!(share(&two.image, PALETTE[10], PALETTE[10]) > 0.98);

    // Bad line art now keeps the open one and its strokes.
    h.state_mut().open_lineart(&corrupt);
    assert_eq!(stroke_count(&h), Some(2));

    // Undo the circle's scribble with the keyboard: the background's color takes everything.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(stroke_count(&h), Some(1));
    wait_for_colorize(&mut h);
    let one = colorize_result(&h);
    assert!(share(&one.image, PALETTE[0], PALETTE[10]) > 0.99);

    // Saved atomically, as shown.
    let out = dir.join("colored.png");
    let message = h.state_mut().save_colorized(&out);
    assert!(message.starts_with("saved"), "{message}");
    assert_eq!(crate::io::load_png(&out).expect("a PNG"), one.image);

    // The eraser (key E) takes the stroke it is clicked on; undo brings back the stroke and
    // its result, without solving again.
    h.key_press(Key::E);
    h.run();
    let middle = [
        (background[0][0] + background[1][0]) / 2.0,
        background[0][1],
    ];
    h.drag_at(screen(&h, middle));
    h.step();
    h.drop_at(screen(&h, middle));
    h.step();
    h.run();
    let c = &h.state().colorize;
    assert_eq!(c.session.as_ref().map(|s| s.strokes().len()), Some(0));
    assert!(c.shown_result().is_none());
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    let result = h.state().colorize.shown_result().cloned().expect("shown");
    assert!(Arc::ptr_eq(&result, &one));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn colorize_scribbles_save_load_and_autosave() {
    use crate::colorize::session::{ScribbleStroke, SessionCommand};
    use crate::colorize::synthetic::PALETTE;
    let (s, dir, lineart) = one_circle_lineart("scribbles", 96, "cat.png");
    let strokes: Vec<ScribbleStroke> = [PALETTE[10], PALETTE[0]]
        .iter()
        .zip(&s.strokes)
        .map(|(&color, stroke)| ScribbleStroke {
            color,
            width_px: stroke.width,
            points_px: stroke.points.clone(),
        })
        .collect();

    let mut h = harness(EditorApp::new(Document::new()));
    h.state_mut().open_lineart(&lineart);
    h.run();
    let saved = dir.join("cat.scribbles.json");
    assert_eq!(
        h.state().colorize.scribbles_path,
        saved.display().to_string()
    );
    for stroke in &strokes {
        assert!(h
            .state_mut()
            .apply_colorize(SessionCommand::AddStroke(stroke.clone())));
    }
    h.run();

    // The panel's button writes the scribble file `sinew colorize --scribbles` reads.
    h.get_by_label("Save scribbles").click();
    h.run();
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.starts_with("saved 2 strokes"), "{message}");
    let text = std::fs::read_to_string(&saved).expect("saved");
    assert_eq!(
        crate::colorize::session::strokes_from_json(&text).expect("a scribble file"),
        strokes
    );

    // Saved strokes are not autosaved again; a change is, beside the scribble file.
    let autosaved = dir.join("cat.scribbles.autosave.json");
    h.state_mut().autosave_scribbles();
    assert!(!autosaved.exists());
    assert!(h.state_mut().apply_colorize(SessionCommand::Clear));
    assert!(h
        .state_mut()
        .apply_colorize(SessionCommand::AddStroke(strokes[1].clone())));
    h.state_mut().autosave_scribbles();
    let text = std::fs::read_to_string(&autosaved).expect("autosaved");
    assert_eq!(
        crate::colorize::session::strokes_from_json(&text).expect("a scribble file"),
        strokes[1..]
    );

    // Loading replaces the strokes as one undo step; a bad file leaves them.
    assert!(h.state_mut().load_scribbles(&saved));
    assert_eq!(stroke_count(&h), Some(2));
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(stroke_count(&h), Some(1));
    let bad = dir.join("bad.json");
    std::fs::write(&bad, "not json").expect("written");
    assert!(!h.state_mut().load_scribbles(&bad));
    assert!(h
        .state()
        .message
        .as_deref()
        .is_some_and(|m| m.starts_with("cannot load")));
    assert_eq!(stroke_count(&h), Some(1));

    // Cleared strokes are autosaved as none, whatever the path field holds.
    h.state_mut().colorize.scribbles_path = String::new();
    assert!(h.state_mut().apply_colorize(SessionCommand::Clear));
    h.state_mut().autosave_scribbles();
    let text = std::fs::read_to_string(&autosaved).expect("autosaved");
    assert_eq!(
        crate::colorize::session::strokes_from_json(&text).expect("a scribble file"),
        Vec::new()
    );

    // At exit, strokes changed since the last autosave are written too.
    assert!(h
        .state_mut()
        .apply_colorize(SessionCommand::AddStroke(strokes[0].clone())));
    h.state_mut().finish_writes();
    let text = std::fs::read_to_string(&autosaved).expect("autosaved");
    assert_eq!(
        crate::colorize::session::strokes_from_json(&text).expect("a scribble file"),
        strokes[..1]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn paint_weights_with_a_locked_handle_through_the_ui() {
    let mut h = open_character("paint");
    h.get_by_label("Weights are up to date");
    let torso = |app: &EditorApp| {
        let scene = app.doc.posable().expect("posable").clone();
        let index = scene
            .doc
            .parts
            .iter()
            .position(|p| p.name == "torso")
            .expect("a torso");
        (scene, index)
    };
    let (scene, index) = torso(h.state());
    let before = scene.doc.parts[index].weights.clone().expect("weights");
    let column = |w: &crate::io::WeightsDoc, name: &str| -> Vec<f64> {
        let c = w.handles.iter().position(|h| h == name).expect("a column") as u32;
        w.rows
            .iter()
            .map(|r| r.iter().find(|e| e.0 == c).map_or(0.0, |e| e.1))
            .collect()
    };

    // Lock the head from its box in the handle list, select the chest, take the brush.
    h.get_by_label("lock head").click();
    h.run();
    assert!(
        h.state().doc.state().locked.contains("head"),
        "{:?}",
        h.state().message
    );
    h.get_by_label("chest").click();
    h.run();
    assert_eq!(h.state().selected.as_deref(), Some("chest"));
    h.get_by_label("Paint").click();
    h.run();
    h.get_by_label("Subtract");
    assert_eq!(h.state().paint.mode, crate::weights::BrushMode::Add);
    h.state_mut().paint.options.radius_px = 24.0;
    h.state_mut().paint.options.strength = 0.5;

    // One stroke across the hip–chest joint. While it runs, the canvas shows a preview; the
    // document changes once, at release, to exactly that preview.
    let (from, to) = ([240.0, 262.0], [272.0, 262.0]);
    h.drag_at(screen(&h, from));
    h.step();
    for k in 1..=4 {
        let t = k as f64 / 4.0;
        h.hover_at(screen(&h, [from[0] + t * (to[0] - from[0]), from[1]]));
        h.step();
    }
    let preview = h.state().shown_rows(index).expect("a preview").to_vec();
    assert_eq!(
        torso(h.state()).0.doc.parts[index].weights.as_ref(),
        Some(&before),
        "the document waits for the release"
    );
    h.drop_at(screen(&h, to));
    h.step();
    h.run();
    let (scene, index) = torso(h.state());
    let after = scene.doc.parts[index].weights.clone().expect("weights");
    assert_eq!(after.rows, preview);
    let (chest0, chest1) = (column(&before, "chest"), column(&after, "chest"));
    let v = &scene.doc.parts[index].mesh.vertices;
    let raised = (0..v.len())
        .filter(|&i| distance(v[i], [256.0, 262.0]) < 12.0)
        .map(|i| chest1[i] - chest0[i])
        .fold(0.0, f64::max);
    assert!(
        raised > 0.1,
        "chest rose by {raised}: {:?}",
        h.state().message
    );
    let head = column(&before, "head");
    assert!(head.iter().any(|&w| w > 0.01), "the head weighs the torso");
    for (a, b) in head.iter().zip(column(&after, "head")) {
        assert_eq!(a.to_bits(), b.to_bits(), "the locked head column changed");
    }
    for row in &after.rows {
        let sum: f64 = row.iter().map(|e| e.1).sum();
        assert!((sum - 1.0).abs() < 1e-9, "{row:?}");
    }
    // The side panel reads out the weights under the pointer.
    h.get_by_label_contains("torso vertex");

    // The stroke is one undo step.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    let (scene, index) = torso(h.state());
    assert_eq!(scene.doc.parts[index].weights.as_ref(), Some(&before));
    assert!(h.state().doc.state().locked.contains("head"));

    // Redo the stroke, lock the chest too and recompute: the painted chest stays.
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    h.run();
    h.get_by_label("lock chest").click();
    h.run();
    h.get_by_label("Compute weights").click();
    wait_for_weights(&mut h);
    let (scene, index) = torso(h.state());
    let recomputed = scene.doc.parts[index].weights.clone().expect("weights");
    assert_eq!(h.state().message.as_deref(), Some("weights computed"));
    assert_eq!(column(&recomputed, "chest"), chest1);
    for row in &recomputed.rows {
        let sum: f64 = row.iter().map(|e| e.1).sum();
        assert!((sum - 1.0).abs() < 1e-9, "{row:?}");
    }
}

/// Press at `from`, move in steps, release at `to` (screen points).
fn drag_screen(h: &mut Harness<'_, EditorApp>, from: Pos2, to: Pos2) {
    h.drag_at(from);
    h.step();
    for k in 1..=4 {
        h.hover_at(from + (to - from) * (k as f32 / 4.0));
        h.step();
    }
    h.drop_at(to);
    h.step();
    h.run();
}

fn click_screen(h: &mut Harness<'_, EditorApp>, at: Pos2) {
    h.drag_at(at);
    h.step();
    h.drop_at(at);
    h.step();
    h.run();
}

fn head(channel: crate::anim::edit::TransformChannel) -> crate::anim::edit::TimelineId {
    crate::anim::edit::TimelineId::Bone {
        bone: "head".into(),
        channel,
    }
}

/// (time, value, curve) of the head's rotate keys in the document, as the file writes them.
fn head_rotate_keys(h: &Harness<'_, EditorApp>) -> Vec<(f64, f64, serde_json::Value)> {
    let anim = crate::document::animation_named(h.state().doc.state(), "nod");
    let json = serde_json::to_value(anim).expect("an animation writes as JSON");
    json["bones"]["head"]["rotate"]
        .as_array()
        .map(|keys| {
            keys.iter()
                .map(|k| {
                    (
                        k["time"].as_f64().unwrap_or(f64::NAN),
                        k["value"].as_f64().unwrap_or(f64::NAN),
                        k.get("curve").cloned().unwrap_or(serde_json::Value::Null),
                    )
                })
                .collect()
        })
        .unwrap_or_default()
}

fn times_of(h: &Harness<'_, EditorApp>, channel: crate::anim::edit::TransformChannel) -> Vec<f64> {
    let anim = crate::document::animation_named(h.state().doc.state(), "nod");
    crate::anim::edit::timelines(&anim)
        .into_iter()
        .find(|(t, _)| *t == head(channel))
        .map(|(_, times)| times)
        .unwrap_or_default()
}

fn key_on_sheet(
    h: &Harness<'_, EditorApp>,
    channel: crate::anim::edit::TransformChannel,
    time_s: f64,
) -> Pos2 {
    h.state()
        .timeline
        .sheet
        .as_ref()
        .expect("the dopesheet was drawn")
        .key_pos(&head(channel), time_s)
        .expect("a row for the channel")
}

#[test]
fn dopesheet_select_move_copy_paste_curve_and_undo() {
    use crate::anim::edit::{KeyRef, TransformChannel::*};
    let mut h = open_character("dopesheet");
    h.key_press(Key::Num3);
    h.run();
    type_into(&mut h, "Animation", "nod");
    // Two keys from the pose: the head at 0° at 0 s and at 20° at 0.5 s.
    for (frames, degrees) in [(0, 0.0), (12, 20.0)] {
        for _ in 0..frames {
            h.get_by_label("Next frame").click();
            h.run();
        }
        h.state_mut().animate.shown = Some(head_turned(degrees));
        h.get_by_label("Set key").click();
        h.run();
    }
    assert_eq!(
        head_rotate_keys(&h),
        vec![
            (0.0, 0.0, serde_json::Value::Null),
            (0.5, 20.0, serde_json::Value::Null)
        ],
        "{:?}",
        h.state().message
    );
    assert_eq!(times_of(&h, Translate), vec![0.0, 0.5]);

    // Select the rotate key at 0.5 s: the playhead goes there.
    let at = key_on_sheet(&h, Rotate, 0.5);
    click_screen(&mut h, at);
    let selected = KeyRef {
        timeline: head(Rotate),
        time_s: 0.5,
    };
    assert_eq!(h.state().timeline.selection, vec![selected.clone()]);
    assert!((h.state().animate.time_s - 0.5).abs() < 1e-9);

    // Drag it to 0.75 s (a little off: it snaps to the frame); only that channel moves.
    let sheet = h.state().timeline.sheet.clone().expect("sheet");
    let to = Pos2::new(
        sheet.x_of(0.75) + 0.2 * sheet.px_per_s / 24.0,
        sheet.rows[0].1,
    );
    let from = key_on_sheet(&h, Rotate, 0.5);
    drag_screen(&mut h, from, to);
    let rotate = head_rotate_keys(&h);
    assert_eq!(rotate.len(), 2, "{:?}", h.state().message);
    assert!((rotate[1].0 - 0.75).abs() < 1e-9, "{rotate:?}");
    assert_eq!(rotate[1].1, 20.0);
    assert_eq!(times_of(&h, Translate), vec![0.0, 0.5]);
    assert!((h.state().timeline.selection[0].time_s - 0.75).abs() < 1e-9);

    // Copy it, put the playhead at 1 s on the ruler, paste: a 20° key at 1 s.
    h.get_by_label("Copy keys").click();
    h.run();
    let ruler_y = sheet.ruler.center().y;
    click_screen(&mut h, Pos2::new(sheet.x_of(1.0), ruler_y));
    assert!(
        (h.state().animate.time_s - 1.0).abs() < 1e-9,
        "{}",
        h.state().animate.time_s
    );
    h.get_by_label("Paste keys").click();
    h.run();
    let rotate = head_rotate_keys(&h);
    assert_eq!(rotate.len(), 3, "{:?}", h.state().message);
    assert!(
        (rotate[2].0 - 1.0).abs() < 1e-9 && rotate[2].1 == 20.0,
        "{rotate:?}"
    );

    // Select the first key and make its segment a Bézier: handles at the thirds.
    let at = key_on_sheet(&h, Rotate, 0.0);
    click_screen(&mut h, at);
    assert_eq!(h.state().timeline.selection.len(), 1);
    h.get_by_label("Bézier").click();
    h.run();
    let curve = head_rotate_keys(&h)[0].2.clone();
    let numbers: Vec<f64> = serde_json::from_value(curve.clone()).expect("a Bézier: {curve}");
    let expected = [0.25, 20.0 / 3.0, 0.5, 40.0 / 3.0];
    assert!(
        numbers
            .iter()
            .zip(expected)
            .all(|(a, b)| (a - b).abs() < 1e-9),
        "{numbers:?}"
    );

    // Drag the first handle down and right: one more undo step, the handle stays in the segment.
    let layout = h.state().timeline.curve.clone().expect("the curve editor");
    let [first, _] = layout.handles.expect("Bézier handles");
    drag_screen(&mut h, first, first + egui::vec2(30.0, 25.0));
    let dragged: Vec<f64> =
        serde_json::from_value(head_rotate_keys(&h)[0].2.clone()).expect("still a Bézier");
    assert!(dragged[0] > numbers[0] + 1e-3, "{dragged:?}");
    assert!(dragged[1] < numbers[1] - 1e-3, "{dragged:?}");
    assert!(
        dragged[0] <= 0.75 && dragged[2..] == numbers[2..],
        "{dragged:?}"
    );

    // Undo, step by step, back to the two keys as set.
    let undo = |h: &mut Harness<'_, EditorApp>| {
        h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
        h.run();
    };
    undo(&mut h);
    assert_eq!(head_rotate_keys(&h)[0].2, curve);
    undo(&mut h);
    assert_eq!(head_rotate_keys(&h)[0].2, serde_json::Value::Null);
    undo(&mut h);
    assert_eq!(head_rotate_keys(&h).len(), 2);
    undo(&mut h);
    assert_eq!(times_of(&h, Rotate), vec![0.0, 0.5]);

    // Box-select the column at 0.5 s (all four channels) and delete it with the Delete key.
    let sheet = h.state().timeline.sheet.clone().expect("sheet");
    let (top, bottom) = (
        sheet.rows.first().expect("rows").1 - 8.0,
        sheet.rows.last().expect("rows").1 + 8.0,
    );
    drag_screen(
        &mut h,
        Pos2::new(sheet.x_of(0.5) - 10.0, top),
        Pos2::new(sheet.x_of(0.5) + 10.0, bottom),
    );
    assert_eq!(h.state().timeline.selection.len(), 4);
    h.key_press(Key::Delete);
    h.run();
    for channel in [Rotate, Translate, Scale, Shear] {
        assert_eq!(times_of(&h, channel), vec![0.0]);
    }
    assert!(
        h.state().doc.state().handles.names().any(|n| n == "head"),
        "Delete took the keys, not a handle"
    );
    undo(&mut h);
    assert_eq!(times_of(&h, Shear), vec![0.0, 0.5]);
}

/// The character with animation "nod" (the head turned 0° at 0 s, 30° at 0.5 s) in its file.
fn character_with_nod(name: &str) -> PathBuf {
    let path = character_rig(name);
    let mut doc = crate::io::RigDocument::load(&path).expect("loads");
    let mut app = EditorApp::new(Document::open(&path).expect("opens"));
    key_nod(&mut app, &[(0.0, 0.0), (0.5, 30.0)]);
    doc.animations = app.doc.state().animations.clone();
    doc.save(&path).expect("saved");
    path
}

#[test]
fn playback_steps_frames_loops_or_stops_and_onion_skins_show_neighbours() {
    let path = character_with_nod("playback");
    let mut h = harness(EditorApp::new(Document::open(&path).expect("opens")));
    h.run();
    h.key_press(Key::Num3);
    h.run();
    type_into(&mut h, "Animation", "nod");
    assert_eq!(h.state().animate.animation, "nod");
    let fps = h.state().render_settings.fps;
    let on_frame = |t: f64| ((t * fps) - (t * fps).round()).abs() < 1e-6;
    // Play (a click; the playing editor asks for frame after frame, so frames are stepped).
    h.get_by_label("Play").click();
    h.step();
    let mut wrapped = false;
    let mut last = 0.0;
    for _ in 0..240 {
        h.step();
        let t = h.state().animate.time_s;
        assert!(on_frame(t) && t < 0.5 - 1e-9, "{t}");
        wrapped |= t < last;
        last = t;
    }
    assert!(wrapped, "playback never looped");
    // Without looping it stops on the last key.
    h.get_by_label("Pause").click();
    h.step();
    h.run();
    h.get_by_label("Loop").click();
    h.run();
    assert!(!h.state().timeline.looping);
    h.get_by_label("Play").click();
    h.step();
    for _ in 0..240 {
        h.step();
        if h.query_by_label("Play").is_some() {
            break;
        }
    }
    h.run();
    h.get_by_label("Play");
    assert!((h.state().animate.time_s - 0.5).abs() < 1e-9);
    // Playing again from the end starts over (Space plays and pauses too).
    // (The harness' clock moves a quarter second a frame: the press's frame shows the
    // rewind, the release's frame has played on.)
    h.key_down(Key::Space);
    h.step();
    assert_eq!(h.state().animate.time_s, 0.0);
    assert!(h.state().animate.playing);
    h.key_up(Key::Space);
    h.step();
    assert!(h.state().animate.time_s > 0.0);
    h.key_press(Key::Space);
    h.step();
    h.run();
    h.get_by_label("Play");

    // Onion skins: at the end only earlier frames exist; in the middle both sides.
    let frames_to =
        |h: &Harness<'_, EditorApp>, t: f64| ((t - h.state().animate.time_s) * fps).round() as i64;
    let steps = frames_to(&h, 0.5);
    let button = if steps > 0 {
        "Next frame"
    } else {
        "Previous frame"
    };
    for _ in 0..steps.abs() {
        h.get_by_label(button).click();
        h.run();
    }
    assert!((h.state().animate.time_s - 0.5).abs() < 1e-9);
    h.get_by_label("Onion skin").click();
    h.run();
    let scene = h.state().doc.posable().expect("posable").clone();
    let placed = h.state().placed.expect("placed");
    let at_end = h.state_mut().onion_shapes(&scene, &placed);
    for _ in 0..frames_to(&h, 0.25).abs() {
        h.get_by_label("Previous frame").click();
        h.run();
    }
    assert!((h.state().animate.time_s - 0.25).abs() < 1e-9);
    let middle = h.state_mut().onion_shapes(&scene, &placed);
    assert!(!at_end.is_empty());
    assert_eq!(
        middle.len(),
        2 * at_end.len(),
        "two frames each side vs two before"
    );
    h.get_by_label("Onion skin").click();
    h.run();
    assert!(h.state_mut().onion_shapes(&scene, &placed).is_empty());
}

#[test]
fn keyboard_copy_paste_and_shift_click_in_the_dopesheet() {
    use crate::anim::edit::{KeyRef, TransformChannel::*};
    let mut h = open_character("keyboard");
    key_nod(h.state_mut(), &[(0.0, 0.0), (0.5, 30.0)]);
    h.key_press(Key::Num3);
    h.run();
    type_into(&mut h, "Animation", "nod");
    // Click one key, shift-click another: both selected; shift-click again: deselected.
    let at = key_on_sheet(&h, Rotate, 0.5);
    click_screen(&mut h, at);
    let translate = key_on_sheet(&h, Translate, 0.5);
    // One frame per event: shift down, press, release, shift up.
    h.event(egui::Event::ModifiersChanged(Modifiers::SHIFT));
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos: translate,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Modifiers::SHIFT,
        });
    }
    h.event(egui::Event::ModifiersChanged(Modifiers::NONE));
    h.step();
    h.run();
    let selection = &h.state().timeline.selection;
    assert_eq!(selection.len(), 2, "{selection:?}");
    assert!(selection.contains(&KeyRef {
        timeline: head(Translate),
        time_s: 0.5
    }));
    assert!(
        (h.state().animate.time_s - 0.5).abs() < 1e-9,
        "a plain click moves the playhead to its key"
    );
    // Ctrl+C, playhead to 1 s, Ctrl+V: both keys pasted at 1 s.
    h.key_press_modifiers(Modifiers::COMMAND, Key::C);
    h.run();
    assert_eq!(h.state().timeline.clipboard.len(), 2);
    h.state_mut().set_time(1.0);
    h.key_press_modifiers(Modifiers::COMMAND, Key::V);
    h.run();
    assert_eq!(times_of(&h, Rotate), vec![0.0, 0.5, 1.0]);
    assert_eq!(times_of(&h, Translate), vec![0.0, 0.5, 1.0]);
    assert_eq!(times_of(&h, Scale), vec![0.0, 0.5], "not copied");
    assert_eq!(head_rotate_keys(&h)[2].1, 30.0);
    // The pasted keys are the selection now; Delete removes exactly them.
    h.key_press(Key::Delete);
    h.run();
    assert_eq!(times_of(&h, Rotate), vec![0.0, 0.5]);
    assert_eq!(times_of(&h, Translate), vec![0.0, 0.5]);
}

/// Shift-click at `at` (canvas px) without moving: one frame per event, as a window sends them.
fn shift_click(h: &mut Harness<'_, EditorApp>, at: [f64; 2]) {
    let pos = screen(h, at);
    h.hover_at(pos);
    h.step();
    h.event(egui::Event::ModifiersChanged(Modifiers::SHIFT));
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Modifiers::SHIFT,
        });
        h.step();
    }
    h.event(egui::Event::ModifiersChanged(Modifiers::NONE));
    h.step();
    h.run();
}

/// The posed vertices the canvas shows.
fn shown_vertices(h: &Harness<'_, EditorApp>) -> Vec<Vec<crate::geom::Point>> {
    h.state()
        .pose_mode
        .posed
        .as_ref()
        .expect("posed")
        .positions
        .clone()
}

/// The largest distance between corresponding vertices, px.
fn largest_move(a: &[Vec<crate::geom::Point>], b: &[Vec<crate::geom::Point>]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| {
            assert_eq!(p.len(), q.len());
            p.iter().zip(q).map(|(u, v)| (u - v).norm())
        })
        .fold(0.0, f64::max)
}

/// A rest vertex of part `name` near its centroid (on the drawing), canvas px.
fn part_point(h: &Harness<'_, EditorApp>, name: &str) -> [f64; 2] {
    let (part, vertex) = central_vertex(h, name);
    h.state().doc.posable().expect("posable").doc.parts[part]
        .mesh
        .vertices[vertex]
}

/// The part named `name` and its vertex nearest the centroid of its rest vertices (it lies on
/// the drawing).
fn central_vertex(h: &Harness<'_, EditorApp>, name: &str) -> (usize, usize) {
    let scene = h.state().doc.posable().expect("posable").clone();
    let part = scene
        .doc
        .parts
        .iter()
        .position(|p| p.name == name)
        .expect("the part");
    let v = &scene.doc.parts[part].mesh.vertices;
    let n = v.len() as f64;
    let c = v
        .iter()
        .fold([0.0, 0.0], |a, p| [a[0] + p[0] / n, a[1] + p[1] / n]);
    let vertex = (0..v.len())
        .min_by(|&a, &b| distance(v[a], c).total_cmp(&distance(v[b], c)))
        .expect("vertices");
    (part, vertex)
}

/// Where the canvas shows the vertex [`part_point`] picks, px.
fn shown_part_point(h: &Harness<'_, EditorApp>, name: &str) -> [f64; 2] {
    let (part, vertex) = central_vertex(h, name);
    let shown = shown_vertices(h)[part][vertex];
    [shown.x, shown.y]
}

#[test]
fn pins_leave_the_drawing_where_it_is() {
    let mut h = open_character("pins");
    h.key_press(Key::Num2);
    h.run();
    assert_eq!(h.state().mode, Mode::Pose);
    let rest = shown_vertices(&h);
    let (torso, head, arm) = (
        part_point(&h, "torso"),
        part_point(&h, "head"),
        part_point(&h, "arm_lower_l"),
    );

    // Three pins in the rest pose, no drag: nothing moves.
    for (k, at) in [torso, head, arm].into_iter().enumerate() {
        shift_click(&mut h, at);
        assert_eq!(
            h.state().doc.state().pose.ik.len(),
            k + 1,
            "{:?}",
            h.state().message
        );
        let moved = largest_move(&rest, &shown_vertices(&h));
        assert!(moved < 1e-6, "pin {k} moved the drawing by {moved} px");
    }

    // Drag the head's pin away, then pin the other arm where the drag left it: nothing moves.
    drag(&mut h, head, [head[0] + 30.0, head[1] - 10.0]);
    let pose = &h.state().doc.state().pose;
    assert_eq!(pose.ik.len(), 3, "the drag moved the head's pin");
    assert!(distance(pose.ik[1].to, [head[0] + 30.0, head[1] - 10.0]) < 1e-3);
    let dragged = shown_vertices(&h);
    assert!(
        largest_move(&rest, &dragged) > 5.0,
        "the drag posed the drawing"
    );
    // Where the drag has carried the other arm.
    let other_arm = shown_part_point(&h, "arm_lower_r");
    shift_click(&mut h, other_arm);
    let pin = h.state().doc.state().pose.ik.last().expect("a pin").clone();
    assert_eq!(h.state().doc.state().pose.ik.len(), 4);
    // The pin holds the gripped point where the drag had put it: its target is the point of the
    // drawing shown before, interpolated in the rest triangle the skinning IK grips.
    let scene = h.state().doc.posable().expect("posable").clone();
    let meshes = scene.skinned_meshes().expect("meshes");
    let (m, t, w) =
        crate::ik::rig::grip(&meshes, crate::geom::Point::new(pin.at[0], pin.at[1]), 0.0)
            .expect("gripped");
    assert_eq!(meshes.len(), dragged.len(), "every part is weighted");
    let shown = meshes[m].triangles[t]
        .iter()
        .zip(w)
        .fold([0.0, 0.0], |s, (&v, w)| {
            let p = dragged[m][v as usize];
            [s[0] + w * p.x, s[1] + w * p.y]
        });
    assert!(
        distance(pin.to, shown) < 1e-9,
        "pinned at {:?}, shown at {shown:?}",
        pin.to
    );

    // Clear pins, rest pose, one pin: the same as one pin on a fresh document.
    h.get_by_label("Clear pins").click();
    h.run();
    h.get_by_label("Rest pose").click();
    h.run();
    assert_eq!(h.state().doc.state().pose, Pose::default());
    shift_click(&mut h, torso);
    let mut fresh = open_character("pins-fresh");
    fresh.key_press(Key::Num2);
    fresh.run();
    shift_click(&mut fresh, torso);
    assert_eq!(h.state().doc.state().pose, fresh.state().doc.state().pose);
    assert_eq!(h.state().doc.state().pose.ik.len(), 1);
    let apart = largest_move(&shown_vertices(&h), &shown_vertices(&fresh));
    assert!(apart == 0.0, "the same pose drawn {apart} px apart");
    assert!(largest_move(&rest, &shown_vertices(&h)) < 1e-6);
}

#[test]
fn the_canvas_draws_the_poses_draw_order_tint_and_visibility() {
    // A document whose animation hides the head, tints the bag and brings the torso to the
    // front, opened through File → Open.
    let path = character_rig("draw-list");
    let mut doc = crate::io::RigDocument::load(&path).expect("loads");
    let mut order: Vec<String> = doc.parts.iter().map(|p| p.name.clone()).collect();
    order.retain(|n| n != "torso");
    order.push("torso".into());
    doc.animations.insert(
        "show".into(),
        crate::anim::Animation::from_json(
            "show",
            &serde_json::json!({
                "parts": {
                    "head": {"visible": [{"time": 0, "value": false}]},
                    "bag": {"color": [{"time": 0, "value": "ff000080"}]}
                },
                "draw_order": [{"time": 0, "value": order}]
            }),
        )
        .expect("an animation"),
    );
    doc.save(&path).expect("saved");
    let mut h = harness(EditorApp::new(Document::new()));
    h.run();
    h.get_by_label("File").click();
    h.run();
    let field = h.get_by_label("Rig or PNG path:");
    field.focus();
    field.type_text(&path.display().to_string());
    h.run();
    h.get_by_label("Open rig").click();
    h.run();
    assert_eq!(
        h.state().doc.path.as_deref(),
        Some(path.as_path()),
        "{:?}",
        h.state().message
    );
    h.key_press(Key::Escape);
    h.key_press(Key::Num3);
    h.run();
    assert_eq!(h.state().mode, Mode::Animate);
    assert_eq!(h.state().animate.animation, "show");

    // The draw list the canvas used is the pose's.
    let picture = h.state().drawing.picture.as_ref().expect("a picture");
    let names: Vec<&str> = picture.draws.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(names, order.iter().map(String::as_str).collect::<Vec<_>>());
    let part = |name: &str| {
        picture
            .draws
            .iter()
            .find(|d| d.name == name)
            .expect("drawn")
            .clone()
    };
    assert!(!part("head").visible);
    assert!(part("torso").visible);
    let bag = part("bag").tint;
    assert!((bag[0] - 1.0).abs() < 1e-6 && bag[1] == 0.0 && bag[2] == 0.0);
    assert!((bag[3] - 128.0 / 255.0).abs() < 1e-3, "{bag:?}");

    // Its pixels are what the library draws for that pose, and differ from the drawings of
    // the document's order or a visible head.
    let scene = h.state().doc.posable().expect("posable").clone();
    let pose = h.state().edited_pose();
    assert_eq!(pose.draw_order.as_ref(), Some(&order));
    let positions = scene.pose_positions(&pose).expect("poses");
    let placed = h.state().placed.expect("placed");
    let ppp = h.ctx.pixels_per_point();
    let (zoom, pan) = (placed.view.zoom * ppp, placed.view.pan * ppp);
    let draw = |pose: &Pose| {
        let mut pixmap =
            tiny_skia::Pixmap::new(picture.pixmap.width(), picture.pixmap.height()).expect("size");
        crate::playback::draw_pose(
            &scene,
            &mut pixmap,
            &positions,
            pose,
            tiny_skia::Transform::from_row(zoom, 0.0, 0.0, zoom, pan.x, pan.y),
        )
        .expect("drawn");
        pixmap
    };
    assert!(
        picture.pixmap.data() == draw(&pose).data(),
        "the canvas is not the render"
    );
    let mut in_rig_order = pose.clone();
    in_rig_order.draw_order = None;
    assert!(picture.pixmap.data() != draw(&in_rig_order).data());
    let mut head_shown = pose.clone();
    head_shown.parts.remove("head");
    assert!(picture.pixmap.data() != draw(&head_shown).data());
    // Where only the head is drawn at rest, the canvas shows nothing.
    let head = part_point(&h, "head");
    let shown = picture.pixel_at(screen(&h, head)).expect("on the canvas");
    let with_head = draw(&head_shown);
    let p = (screen(&h, head) - picture.rect.min) * ppp;
    let visible_head = with_head.pixel(p.x as u32, p.y as u32).expect("inside");
    assert!(visible_head.alpha() > 0, "the head covers its own middle");
    assert_eq!(shown[3], 0, "the hidden head was drawn");
}

/// The issue's requirement after a drag. The editor places the pin where the point is shown
/// (checked above); with bones that keep their length the skinning IK is not convex, and a cold
/// solve of one more constraint could settle in another local optimum nearby (16 px away here).
/// The static pose's answer takes its drags in order ([`crate::ik::fast::FastIk::solve_static`]):
/// a pin already met adds nothing.
#[test]
fn a_pin_after_a_drag_leaves_the_drawing_where_it_is() {
    let mut h = open_character("pin-after-drag");
    h.key_press(Key::Num2);
    h.run();
    let (torso, head, arm) = (
        part_point(&h, "torso"),
        part_point(&h, "head"),
        part_point(&h, "arm_lower_l"),
    );
    for at in [torso, head, arm] {
        shift_click(&mut h, at);
    }
    drag(&mut h, head, [head[0] + 30.0, head[1] - 10.0]);
    let dragged = shown_vertices(&h);
    let other_arm = shown_part_point(&h, "arm_lower_r");
    shift_click(&mut h, other_arm);
    assert_eq!(h.state().doc.state().pose.ik.len(), 4);
    let moved = largest_move(&dragged, &shown_vertices(&h));
    assert!(
        moved < 1e-6,
        "a pin after a drag moved the drawing by {moved} px"
    );
}
