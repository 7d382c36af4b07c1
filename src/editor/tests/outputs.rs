//! Outputs: Export Spine and Render from the editor.

use super::*;

#[test]
fn exports_for_spine_from_the_file_menu_function() {
    let (_dir, path) = character_rig("export");
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
        at: Point::new(10.0, 10.0),
        parent: None,
    }));
    let empty = path.parent().expect("a folder").join("none");
    let message = app.export_spine(&empty);
    assert!(message.contains("compute"), "{message}");
    assert_eq!(std::fs::read_dir(&empty).map(|d| d.count()).unwrap_or(0), 0);
}

#[test]
fn renders_the_current_animation_in_the_background() {
    let (dir, path) = character_rig("render");
    let mut h = opened_in(dir, &path);
    let gif = path.parent().expect("a folder").join("nod.gif");
    key_nod(h.state_mut(), &[(0.0, 0.0), (0.5, 20.0)]);
    h.run();
    h.key_press(Key::Num3);
    h.run();
    click_shown(&mut h, "nod");
    click_shown(&mut h, "File");
    click_shown(&mut h, "Render…");
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
    press_shown_by(&mut h, button("Render"));
    wait_for_render(&mut h, 50);
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.starts_with("rendered"), "{message}");
    let bytes = std::fs::read(&gif).expect("the GIF was written");
    assert!(bytes.starts_with(b"GIF89a"));
    // The settings reached the renderer: the GIF's logical screen is the half-scale canvas.
    let canvas_width = h.state().doc.state().layers[0].image.width();
    let width = u16::from_le_bytes([bytes[6], bytes[7]]);
    assert_eq!(u32::from(width), canvas_width.div_ceil(2));
    // Deleted from the list, "nod" is gone; the animation edited then has no keys yet, and
    // rendering it says so and writes no file.
    click_shown(&mut h, "Delete animation");
    assert!(h.state().doc.state().animations.is_empty());
    h.get_by_label("animation (no keys yet)");
    type_into(
        &mut h,
        "Render the current animation to (.gif, .png sheet or a folder):",
        &path.with_file_name("nope.gif").display().to_string(),
    );
    // The button, not the window's title.
    press_shown_by(&mut h, button("Render"));
    wait_for_render(&mut h, 20);
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.contains("no animation of that name"), "{message}");
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

#[test]
fn the_render_dialog_names_the_spine_export_its_runtime_curves_reproduce() {
    let (dir, path) = character_rig("render-spine");
    let mut h = opened_in(dir, &path);
    click_shown(&mut h, "File");
    click_shown(&mut h, "Render…");
    assert!(h.query_by_label("Spine version").is_none());
    click_shown(&mut h, "Curves as Spine's runtimes play them");
    let picker = combo_box("Spine version");
    assert_eq!(h.get(picker.clone()).value().as_deref(), Some("4.2"));
    click_shown_by(&mut h, picker);
    click_shown(&mut h, "4.1");
    type_into(&mut h, "Bake keys per second", "20");
    h.key_press(Key::Enter);
    h.run();
    let settings = &h.state().render_settings;
    assert_eq!(
        settings.sampling.curves,
        crate::anim::CurveEvaluation::SpineRuntime
    );
    assert_eq!(
        settings.export,
        crate::export::spine::played::ExportPlayed {
            version: crate::export::spine::SpineVersion::V4_1,
            bake_fps: 20.0,
        }
    );
}
