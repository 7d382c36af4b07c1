//! Colorize mode's split picker: chosen in the panel, seen in the saved image.

use super::*;
use crate::colorize::synthetic::{scene, SceneSpec};
use crate::colorize::{ColorizeOptions, RegionSplit, Scribbles};

/// Steps frames until the panel says "colorized" (the shown strokes' solve is done).
fn wait_until_colorized(h: &mut Harness<'_, EditorApp>) {
    for _ in 0..BUILD_FRAMES {
        h.step();
        if h.query_by_label("colorized").is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    h.run();
    assert!(
        h.query_by_label("colorized").is_some(),
        "never colorized: {:?}",
        h.state().message
    );
}

/// Opens the File menu, types `path` into its field `label`, and presses `button` there,
/// which must close the menu as every File action does; without a button, closes the menu
/// with Escape.
fn file_menu_action(
    h: &mut Harness<'_, EditorApp>,
    label: &str,
    path: &Path,
    button: Option<&str>,
) {
    click_shown(h, "File");
    let field = press_point(&h.get_by_label(label));
    assert_shown(h, field, label);
    type_into(h, label, &path.display().to_string());
    if let Some(button) = button {
        click_shown(h, button);
        assert!(
            h.query_by_label(label).is_none(),
            "\"{button}\" left the File menu open"
        );
        return;
    }
    // The first Escape leaves the field if it still has the focus, the next closes the menu.
    for _ in 0..2 {
        if h.query_by_label(label).is_some() {
            h.key_press(Key::Escape);
            h.run();
        }
    }
    assert!(
        h.query_by_label(label).is_none(),
        "the File menu stayed open"
    );
}

/// Presses the panel's "Save colorized PNG" and reads what it wrote.
fn saved(h: &mut Harness<'_, EditorApp>, path: &Path) -> image::RgbaImage {
    let _ = std::fs::remove_file(path);
    click_shown(h, "Save colorized PNG");
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.starts_with("saved"), "{message}");
    crate::io::load_png(path).expect("a PNG")
}

/// How many pixels of `a` and `b` differ.
fn differing(a: &image::RgbaImage, b: &image::RgbaImage) -> usize {
    assert_eq!(a.dimensions(), b.dimensions());
    a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count()
}

/// Picks `split` in the panel's "Split" picker.
fn pick_split(h: &mut Harness<'_, EditorApp>, split: &str) {
    click_shown_by(h, combo_box("Split"));
    click_shown(h, split);
    assert_eq!(h.get(combo_box("Split")).value().as_deref(), Some(split));
}

#[test]
fn the_split_picked_in_the_panel_colors_the_saved_image_as_sinew_colorize_does() {
    // Two background colors and no line between them: the split decides where they meet.
    let s = scene(&SceneSpec {
        size: 96,
        split_background: true,
        ..Default::default()
    });
    let tmp = crate::test_scratch::scratch("editor-split");
    let dir = tmp.path();
    let (lineart, scribbles) = (dir.join("undrawn.png"), dir.join("undrawn.json"));
    crate::io::save_png(&lineart, &s.lineart).expect("written");
    let file = serde_json::json!({ "strokes": s.strokes });
    std::fs::write(&scribbles, file.to_string()).expect("written");
    // What `sinew colorize` makes of them with `options` (the library's one-shot pipeline).
    let expected = |options: &ColorizeOptions| {
        let scribbles =
            Scribbles::from_strokes(&s.strokes, 96, 96, &options.scribbles).expect("scribbles");
        crate::colorize::colorize(&s.lineart, &scribbles, options, false)
            .expect("colorized")
            .image
    };

    let mut h = harness(EditorApp::new(Document::new()));
    h.run();
    h.key_press(Key::Num4);
    h.run();
    file_menu_action(
        &mut h,
        "Line-art PNG to colorize:",
        &lineart,
        Some("Open line art"),
    );
    file_menu_action(
        &mut h,
        "Scribbles JSON:",
        &scribbles,
        Some("Load scribbles"),
    );
    let out = dir.join("colored.png");
    file_menu_action(&mut h, "Colorized PNG:", &out, None);
    wait_until_colorized(&mut h);

    // The default, reach, with its α shown.
    assert_eq!(h.get(combo_box("Split")).value().as_deref(), Some("reach"));
    let reach = saved(&mut h, &out);
    assert_eq!(differing(&reach, &expected(&ColorizeOptions::default())), 0);

    // Depth: solved again, a different image, the command's; no α.
    pick_split(&mut h, "depth");
    assert!(h.query_by_label("α:").is_none());
    wait_until_colorized(&mut h);
    let depth = saved(&mut h, &out);
    let depth_options = ColorizeOptions {
        split: RegionSplit::Depth,
        ..Default::default()
    };
    assert_eq!(differing(&depth, &expected(&depth_options)), 0);
    let changed = differing(&depth, &reach);
    assert!(changed > 0, "the depth split drew what reach drew");

    // Back to reach with α 1 typed in.
    pick_split(&mut h, "reach");
    wait_until_colorized(&mut h);
    assert_eq!(differing(&saved(&mut h, &out), &reach), 0);
    let field = press_point(&h.get_by_label("α:"));
    assert_shown(&mut h, field, "α:");
    set_number(&mut h, "α:", 1.0);
    wait_until_colorized(&mut h);
    let alpha = saved(&mut h, &out);
    let alpha_options = ColorizeOptions {
        split_depth_exponent: 1.0,
        ..Default::default()
    };
    assert_eq!(differing(&alpha, &expected(&alpha_options)), 0);
    let alpha_changed = differing(&alpha, &reach);
    assert!(alpha_changed > 0, "α changed nothing");
    println!("depth changed {changed} px of reach's, α 1 {alpha_changed} px");
}
