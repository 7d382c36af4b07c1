//! The File menu, its windows and its shortcuts, driven by input events only: clicks on
//! widgets found by their label, typed text, keys with modifiers.

use super::*;

/// An empty folder of its own for one test, removed when the result drops.
fn scratch(name: &str) -> TempDir {
    crate::test_scratch::scratch(&format!("editor-{name}"))
}

#[test]
fn the_file_menus_field_takes_a_click_and_typing_and_imports_a_png() {
    let tmp = scratch("menu-field");
    let dir = tmp.path();
    let png = bar_png(dir);
    let mut h = harness(EditorApp::new(Document::new()));
    h.run();
    click_shown(&mut h, "File");
    // A click into the field keeps the menu open (its buttons are still there) and the field
    // takes the typing.
    type_into(&mut h, "Rig or PNG path:", &png.display().to_string());
    assert_eq!(
        h.get_by_label("Rig or PNG path:").value().as_deref(),
        Some(png.display().to_string().as_str())
    );
    click_shown(&mut h, "Import layer");
    assert_eq!(
        h.state().doc.state().layers.len(),
        1,
        "{:?}",
        h.state().message
    );
    // The action closed the menu.
    assert!(h.query_by_label("Import layer").is_none());
    // The modified document shows so; typing S in a field never reaches a shortcut.
    h.get_by_label_contains("modified");
}

#[test]
fn ctrl_s_saves_as_ctrl_n_starts_over_ctrl_o_opens_and_nothing_is_saved_without_layers() {
    let tmp = scratch("shortcuts");
    let dir = tmp.path();
    let png = bar_png(dir);
    let json = dir.join("bar.json");
    let mut h = harness(EditorApp::new(Document::new()));
    h.run();

    // An empty document cannot be saved: the save says why and writes nothing.
    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run();
    h.get_by_label("Save to this path");
    type_into(
        &mut h,
        "Path:",
        &dir.join("empty.json").display().to_string(),
    );
    h.key_press(Key::Enter);
    h.run();
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("no layers to save"), "{message}");
    assert!(!dir.join("empty.json").exists());
    assert!(h.state().log.errors() >= 1);

    // Import through File → Import layer…, the path typed in its window.
    click_shown(&mut h, "File");
    click_shown(&mut h, "Import layer…");
    type_into(&mut h, "Path:", &png.display().to_string());
    click_shown(&mut h, "Import");
    assert_eq!(h.state().doc.state().layers.len(), 1);
    assert!(h.state().doc.dirty());

    // Ctrl+S on a document never saved asks where (a PNG path is refused), then saves there.
    h.key_press_modifiers(Modifiers::COMMAND, Key::S);
    h.run();
    type_into(&mut h, "Path:", &png.display().to_string());
    h.key_press(Key::Enter);
    h.run();
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains(".json"), "{message}");
    assert!(
        crate::io::load_png(&png).is_ok(),
        "the PNG was written over"
    );
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::S);
    h.run();
    type_into(&mut h, "Path:", &json.display().to_string());
    h.key_press(Key::Enter);
    h.run();
    wait_for(&mut h, |app| !app.saving());
    assert_eq!(h.state().doc.path.as_deref(), Some(json.as_path()));
    assert!(!h.state().doc.dirty(), "{:?}", h.state().message);
    assert!(json.is_file());
    assert_eq!(h.state().recent.first(), Some(&json));

    // Ctrl+N: a clean document starts over at once.
    h.key_press_modifiers(Modifiers::COMMAND, Key::N);
    h.run();
    assert!(h.state().doc.path.is_none());
    assert_eq!(h.state().doc.state().layers.len(), 0);

    // Ctrl+O: the path window; Open.
    h.key_press_modifiers(Modifiers::COMMAND, Key::O);
    h.run();
    type_into(&mut h, "Path:", &json.display().to_string());
    click_shown(&mut h, "Open");
    assert_eq!(h.state().doc.path.as_deref(), Some(json.as_path()));
    assert_eq!(h.state().doc.state().layers.len(), 1);

    // A modified document asks before Ctrl+N throws it away.
    click_shown(&mut h, "File");
    click_shown(&mut h, "Import layer…");
    type_into(&mut h, "Path:", &png.display().to_string());
    click_shown(&mut h, "Import");
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("already exists"), "{message}");
    // The mode key's frames run before the Point tool is looked for and clicked: a user
    // sees rig mode's tools before pointing at one.
    h.key_press(Key::Num1);
    h.run();
    assert_eq!(h.state().mode, Mode::Rig);
    click_shown(&mut h, "Point");
    click(&mut h, Point::new(40.0, 24.0));
    assert!(h.state().doc.dirty());
    h.key_press_modifiers(Modifiers::COMMAND, Key::N);
    h.run();
    click_shown(&mut h, "Keep editing");
    assert_eq!(h.state().doc.path.as_deref(), Some(json.as_path()));
    h.key_press_modifiers(Modifiers::COMMAND, Key::N);
    h.run();
    click_shown(&mut h, "Discard and start new");
    assert!(h.state().doc.path.is_none());
    // Undoing back to the saved state is clean again (after reopening, then one edit).
    h.key_press_modifiers(Modifiers::COMMAND, Key::O);
    h.run();
    type_into(&mut h, "Path:", &json.display().to_string());
    h.key_press(Key::Enter);
    h.run();
    click_shown(&mut h, "Point");
    click(&mut h, Point::new(40.0, 24.0));
    assert!(h.state().doc.dirty());
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert!(!h.state().doc.dirty());
    assert!(h.query_by_label_contains("modified").is_none());
}

#[test]
fn a_quick_ctrl_s_in_pose_mode_saves_and_never_scales() {
    let mut h = open_character("ctrl-s");
    let path = h.state().doc.path.clone().expect("a file");
    h.key_press(Key::Num2);
    h.run();
    click(&mut h, Point::new(256.0, 225.0));
    assert_eq!(h.state().selected.as_deref(), Some("chest"));
    h.hover_at(screen(&h, Point::new(300.0, 240.0)));
    h.step();
    // Ctrl down, S down and up, Ctrl up, all within one frame (as a quick press arrives from
    // the window system; the harness' own chord spreads them over frames).
    let key = |pressed| egui::Event::Key {
        key: Key::S,
        physical_key: None,
        pressed,
        repeat: false,
        modifiers: Modifiers::COMMAND,
    };
    h.input_mut().events.extend([
        egui::Event::ModifiersChanged(Modifiers::COMMAND),
        key(true),
        key(false),
        egui::Event::ModifiersChanged(Modifiers::NONE),
    ]);
    h.step();
    h.hover_at(screen(&h, Point::new(330.0, 260.0)));
    h.step();
    h.run();
    assert!(h.state().gesture.is_none(), "Ctrl+S started a scale");
    let message = h.state().message.clone().unwrap_or_default();
    assert_eq!(message, format!("saved {}", path.display()));
    // S alone still scales.
    h.key_press(Key::S);
    h.step();
    assert!(matches!(h.state().gesture, Some(Gesture::Fk(_))));
    h.key_press(Key::Escape);
    h.run();
}

#[test]
fn messages_expire_from_the_status_bar_and_errors_stay_in_the_log() {
    let mut h = harness(EditorApp::new(Document::new()));
    h.run();
    h.key_press_modifiers(Modifiers::COMMAND, Key::O);
    h.run();
    type_into(&mut h, "Path:", "/nonexistent/rig.json");
    h.key_press(Key::Enter);
    h.run();
    let message = h.state().message.clone().expect("an error");
    h.get_by_label(&message);
    // Frames go by (the harness' clock): the status bar lets it go, the log keeps it.
    for _ in 0..((messages::MESSAGE_SHOWN_S + 1.0) * 60.0) as usize {
        h.step();
    }
    h.run();
    assert!(h.query_by_label(&message).is_none());
    click_shown(&mut h, "Log (1 errors)");
    h.get_by_label_contains("/nonexistent/rig.json");
}

/// A file dropped on the window, as the window system hands it to egui.
#[derive(Debug)]
struct Dropped(PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &Path {
        &self.0
    }
    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

#[test]
fn an_empty_canvas_asks_for_images_and_takes_a_dropped_png() {
    let tmp = scratch("drop");
    let dir = tmp.path();
    let png = bar_png(dir);
    let mut h = harness(EditorApp::new(Document::new()));
    h.run();
    h.get_by_label(drawing::DROP_HINT);
    h.input_mut()
        .dropped_files
        .push(std::sync::Arc::new(Dropped(png.clone())));
    h.run();
    assert_eq!(
        h.state().doc.state().layers.len(),
        1,
        "{:?}",
        h.state().message
    );
    assert!(h.query_by_label(drawing::DROP_HINT).is_none());
}

#[test]
fn a_dropped_psd_becomes_its_visible_layers() {
    let tmp = scratch("drop-psd");
    let dir = tmp.path();
    std::fs::create_dir_all(dir).unwrap();
    let psd = dir.join("character.psd");
    let fixture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/layered/character.psd");
    std::fs::copy(fixture, &psd).unwrap();
    let mut h = harness(EditorApp::new(Document::new()));
    h.run();
    h.input_mut()
        .dropped_files
        .push(std::sync::Arc::new(Dropped(psd.clone())));
    h.run();
    let names: Vec<String> = h
        .state()
        .doc
        .state()
        .layers
        .iter()
        .map(|l| l.name.clone())
        .collect();
    assert_eq!(
        names,
        ["torso", "arm_l/upper", "arm_l/hand", "head", "leaf"],
        "{:?}",
        h.state().message
    );
    // Hidden layers are not parts: the status bar says so.
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("'sketch' is hidden"), "{message}");
    assert!(dir.join("character.parts/arm_l/hand.png").is_file());
    // Each layer keeps its own pixels (the hand is 20×20 px at (78, 96) on a 120×160 canvas),
    // not a canvas-sized copy.
    let layers = h.state().doc.state().layers.clone();
    let hand = layers
        .iter()
        .find(|l| l.name == "arm_l/hand")
        .expect("the hand");
    assert_eq!(hand.canvas_px, [120, 160]);
    assert!(hand.image.width() <= 20 && hand.image.height() <= 20);
    assert!(
        hand.offset_px[0] >= 78 && hand.offset_px[1] >= 96,
        "{:?}",
        hand.offset_px
    );
}

#[test]
fn export_spine_from_its_window_refuses_to_write_over_the_document() {
    let mut h = open_character("export-window");
    let path = h.state().doc.path.clone().expect("a file");
    let dir = path.parent().expect("a folder").to_path_buf();
    let before = std::fs::read(&path).expect("the document");
    click_shown(&mut h, "File");
    click_shown(&mut h, "Export Spine…");
    // Into the document's own folder, the export's character.json would be the document.
    type_into(&mut h, "Export folder:", &dir.display().to_string());
    click_shown(&mut h, "Export");
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("would overwrite an input"), "{message}");
    assert_eq!(std::fs::read(&path).expect("the document"), before);
    let spine = dir.join("spine");
    type_into(&mut h, "Export folder:", &spine.display().to_string());
    // The game preset's limits, as `--preset game` sets them.
    click_shown(&mut h, "Game preset");
    click_shown(&mut h, "Export");
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.starts_with("exported"), "{message}");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(spine.join("character.json")).expect("the export"))
            .expect("JSON");
    let limit = crate::export::spine::GAME_PRESET_MAX_VERTICES;
    let mut meshes = 0;
    for slot in json["skins"][0]["attachments"]
        .as_object()
        .expect("slots")
        .values()
    {
        for mesh in slot.as_object().expect("attachments").values() {
            let uvs = mesh["uvs"].as_array().expect("uvs").len() / 2;
            assert!(uvs <= limit, "{uvs} vertices");
            meshes += 1;
        }
    }
    assert!(meshes > 0);
}
