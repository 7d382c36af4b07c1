//! Documents: bad files, saving and autosaving off the UI thread, closing with unsaved changes,
//! the view restored on reopening.

use super::*;

#[test]
fn bad_files_show_a_message_and_keep_the_document() {
    let (_dir, path) = character_rig("bad");
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

#[test]
fn saving_a_never_rigged_document_runs_off_the_ui_thread() {
    let tmp = crate::test_scratch::scratch("editor-save");
    let dir = tmp.path();
    let mut h = never_rigged_bar(dir);
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
        at: Point::new(40.0, 24.0),
        parent: None,
    }));
    wait_for(&mut h, |app| !app.saving());
    assert!(h.state().doc.dirty());
}

#[test]
fn closing_with_unsaved_changes_asks_first() {
    use closing::Closing;
    let tmp = crate::test_scratch::scratch("editor-close");
    let dir = tmp.path();
    let mut h = never_rigged_bar(dir);
    assert!(h.state().doc.dirty());
    let png = dir.join("bar.png");
    let png_bytes = std::fs::read(&png).expect("bar.png");
    // The File menu's path field holds the imported PNG: Save must not write over it.
    type_in_file_menu(&mut h, "Rig or PNG path:", &png.display().to_string());
    assert!(press_close_button(&mut h), "the close was not cancelled");
    assert_eq!(h.state().closing(), Closing::Asking);
    h.get_by_label(
        "Save the changes before closing? (Type a .json file name in the File menu first.)",
    );
    click_shown(&mut h, "Save");
    assert_eq!(h.state().closing(), Closing::Open);
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains(".json file name"), "{message}");
    assert_eq!(std::fs::read(&png).expect("bar.png"), png_bytes);
    // It asks for the path in a "Save as" window (over the menu bar); Escape dismisses it.
    h.get_by_label("Save as");
    h.get_by_label("Path:");
    h.key_press(Key::Escape);
    h.run();
    assert!(h.query_by_label("Path:").is_none());

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
    type_in_file_menu(&mut h, "Rig or PNG path:", &path.display().to_string());
    assert!(press_close_button(&mut h));
    h.get_by_label(&format!(
        "Save the changes to {} before closing?",
        path.display()
    ));
    click_shown(&mut h, "Save");
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
    let mut h = never_rigged_bar(dir);
    h.state_mut().request_close();
    h.run();
    click_shown(&mut h, "Don't save");
    assert_eq!(h.state().closing(), Closing::Allowed);
    let mut clean = harness(EditorApp::new(Document::new()));
    assert!(!press_close_button(&mut clean));
    assert_eq!(clean.state().closing(), Closing::Allowed);
}

#[test]
fn a_save_still_running_is_reported_after_reopening_and_finished_at_exit() {
    let tmp = crate::test_scratch::scratch("editor-reopen");
    let dir = tmp.path();
    let mut h = never_rigged_bar(dir);
    let path = dir.join("bar.json");
    h.state_mut().save_to(&path);
    let (_other_dir, other) = character_rig("reopen-save");
    h.state_mut().open(&other);
    assert!(h.state().saving());
    wait_for(&mut h, |app| !app.saving());
    let message = h.state().message.clone().unwrap_or_default();
    assert_eq!(message, format!("saved {}", path.display()));
    // The save belonged to the closed document: the open one is untouched.
    assert_eq!(h.state().doc.path.as_deref(), Some(other.as_path()));
    assert!(!view_path(&path).exists());

    // At exit the editor waits for writes still under way.
    let mut h = never_rigged_bar(dir);
    let path = dir.join("exit.json");
    h.state_mut().save_to(&path);
    let ctx = h.ctx.clone();
    h.state_mut().start_autosave(&path, &ctx);
    h.state_mut().finish_writes();
    assert!(path.is_file());
    assert!(crate::document::autosave_path(&path).is_file());
    assert!(!h.state().saving() && !h.state().autosaving());
}

#[test]
fn autosave_writes_a_never_rigged_document_off_the_ui_thread() {
    let tmp = crate::test_scratch::scratch("editor-autosave");
    let dir = tmp.path();
    let mut h = never_rigged_bar(dir);
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
}

#[test]
fn reopening_restores_the_view() {
    let (_dir, path) = character_rig("view");
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
