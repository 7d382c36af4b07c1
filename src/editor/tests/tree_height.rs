//! The tree's height in the side panel, in every mode and window height, driven by input
//! events only (mode keys, clicks on the tree's rows).

use super::*;

/// How many of the tree's rows the window shows: their middle (where a click reaches them)
/// lies below the menu bar and the tree's heading, above the status bar, above what follows
/// the tree in the panel (rig mode's weights) and above animate mode's timeline where it
/// spans under the side panel.
fn rows_in_view(h: &Harness<'_, EditorApp>) -> usize {
    let canvas_top = h.state().placed.expect("the canvas was drawn").origin.y;
    let top = h.get_by_label("Tree").rect().bottom().max(canvas_top);
    let mut bottom = h.get_by_label_contains(" layers, ").rect().top();
    if let Some(weights) = h.query_by_label("Weights") {
        bottom = bottom.min(weights.rect().top());
    }
    let timeline = format!("Animation '{}'", h.state().animate.animation);
    let timeline = h.query_by_label(&timeline).map(|t| t.rect());
    let names: Vec<String> = h
        .state()
        .doc
        .state()
        .handles
        .names()
        .map(str::to_string)
        .collect();
    names
        .iter()
        .filter_map(|n| h.query_by_label(n))
        .map(|row| row.rect())
        .filter(|row| {
            let under_timeline =
                timeline.is_some_and(|t| t.left() < row.right() && row.center().y > t.top());
            (top..=bottom).contains(&row.center().y) && !under_timeline
        })
        .count()
}

/// The editor on the character in a window `height` points tall.
fn character_in_window(name: &str, height: f32) -> InFolder {
    let (dir, path) = character_rig(name);
    let mut h = harness_sized(
        EditorApp::new(Document::open(&path).expect("opens")),
        egui::vec2(1200.0, height),
    );
    h.run();
    InFolder { h, _dir: dir }
}

#[test]
fn the_tree_shows_a_screenful_of_rows_in_every_mode_and_window_height() {
    for height in [800.0, 1000.0, 640.0] {
        let mut h = character_in_window(&format!("tree-height-{height}"), height);
        let mut shown = Vec::new();
        for key in [Key::Num1, Key::Num2, Key::Num3] {
            h.key_press(key);
            h.run();
            shown.push((h.state().mode, rows_in_view(&h)));
        }
        for (mode, rows) in &shown {
            assert!(
                *rows >= MIN_ROWS,
                "{height} pt window, {mode:?} mode: {rows} rows of the tree in view ({shown:?})"
            );
        }
        // A taller window shows more rows (the tree follows the space, not a fixed height).
        if height > 900.0 {
            assert!(
                shown.iter().all(|(_, rows)| *rows >= 2 * MIN_ROWS),
                "{shown:?}"
            );
        }
    }
}

/// Rows of the tree any mode shows without scrolling, however short the window.
const MIN_ROWS: usize = 8;
