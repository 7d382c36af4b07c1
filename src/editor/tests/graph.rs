//! Animate mode's graph view driven by input events only: every channel of the selected
//! handle drawn at once with a legend, a window that resizes, handles that drag.

use super::*;
use crate::anim::edit::TransformChannel::*;
use crate::editor::graph_view::GraphLayout;

/// The legend's curves of a head keyed in every transform channel, in order.
const HEAD_CURVES: [&str; 7] = [
    "head rotate",
    "head translate x",
    "head translate y",
    "head scale x",
    "head scale y",
    "head shear x",
    "head shear y",
];

/// The bundled character in animate mode with the head keyed at 0° at 0 s and 20° at 0.5 s
/// from the numbers panel (every transform channel gets keys).
fn nodding_head(name: &str) -> InFolder {
    let mut h = open_character(name);
    h.key_press(Key::Num3);
    h.run();
    key_a_nod_from_the_numbers_panel(&mut h);
    h
}

/// Where the graph view drew last frame.
fn graph(h: &Harness<'_, EditorApp>) -> GraphLayout {
    h.state().timeline.graph.layout.clone().expect("the graph")
}

fn rotate_numbers(h: &Harness<'_, EditorApp>) -> Vec<f64> {
    serde_json::from_value(head_rotate_keys(h)[0].2.clone()).expect("a Bézier")
}

#[test]
fn the_graph_view_draws_every_channel_of_the_handle_resizes_and_drags_handles() {
    let mut h = nodding_head("graph-view");
    // The rotate key at 0 s made a Bézier in the one-segment curve editor.
    let at = key_on_sheet(&h, Rotate, 0.0);
    click_screen(&mut h, at);
    click_shown(&mut h, "Bézier");
    let numbers = rotate_numbers(&h);

    // The graph view: seven curves, each named in the legend.
    click_shown(&mut h, "Graph view");
    let names = HEAD_CURVES;
    for name in names {
        h.get_by_label(name);
    }
    let layout = graph(&h);
    let drawn: Vec<&str> = layout.curves.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(drawn, names);
    // Only the rotate curve is a Bézier: its two handles are drawn, no other curve has any.
    let handles: Vec<usize> = layout.curves.iter().map(|c| c.handles.len()).collect();
    assert_eq!(handles, [2, 0, 0, 0, 0, 0, 0]);

    // The window's corner dragged out: the plot grows with it.
    let before = layout.rect;
    let corner = before.right_bottom() + egui::vec2(16.0, 16.0);
    drag_screen(&mut h, corner, corner + egui::vec2(160.0, 100.0));
    let after = graph(&h).rect;
    assert!(
        after.width() > before.width() + 100.0 && after.height() > before.height() + 60.0,
        "{before:?} → {after:?}"
    );

    // The legend hides a curve and shows it again.
    click_shown(&mut h, "head translate x");
    let shown = |h: &Harness<'_, EditorApp>| {
        let layout = graph(h);
        layout
            .curves
            .iter()
            .map(|c| c.name.clone())
            .collect::<Vec<_>>()
    };
    assert!(!shown(&h).iter().any(|n| n == "head translate x"));
    assert_eq!(shown(&h).len(), 6);
    click_shown(&mut h, "head translate x");
    assert_eq!(shown(&h).len(), 7);

    // The rotate curve's first handle dragged right and down: a later, lower handle.
    let layout = graph(&h);
    let first = layout.curves[0].handles[0].2;
    drag_screen(&mut h, first, first + egui::vec2(30.0, 25.0));
    let dragged = rotate_numbers(&h);
    assert!(dragged[0] > numbers[0] + 1e-3, "{dragged:?} vs {numbers:?}");
    assert!(dragged[1] < numbers[1] - 1e-3, "{dragged:?} vs {numbers:?}");
    assert!(
        dragged[0] <= 0.5 && dragged[2..] == numbers[2..],
        "{dragged:?}"
    );

    // One undo step puts it back.
    h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    h.run();
    assert_eq!(rotate_numbers(&h), numbers);
}

#[test]
fn the_graph_view_labels_its_axes_and_draws_every_curve_on_one_scale_on_request() {
    let mut h = nodding_head("graph-axes");
    click_shown(&mut h, "Graph view");

    // Seven curves, each over its own range: the time axis is labelled, the value axis not
    // (its numbers would mean seven things).
    let first = graph(&h);
    assert_eq!(first.curves.len(), 7);
    assert!(first.value_ticks.is_empty(), "{:?}", first.value_ticks);
    let times: Vec<f64> = first.time_ticks.iter().map(|t| t.0).collect();
    assert!(times.first() == Some(&0.0) && times.len() >= 2, "{times:?}");
    for (t, x) in &first.time_ticks {
        let f = (x - first.rect.left()) / first.rect.width();
        assert!((f64::from(f) - (t - first.start_s) / (first.end_s - first.start_s)).abs() < 1e-3);
    }
    assert!(
        first
            .curves
            .iter()
            .any(|c| (c.low, c.high) != (first.curves[0].low, first.curves[0].high)),
        "rotate (degrees) and scale (factors) have different ranges"
    );

    // Same scale: one range for every curve, and value ticks that mean it. The rotate key's
    // 20° sits on the tick labelled 20.
    click_shown(&mut h, "Same scale");
    let shared = graph(&h);
    let (low, high) = (shared.curves[0].low, shared.curves[0].high);
    assert!(shared.curves.iter().all(|c| (c.low, c.high) == (low, high)));
    assert!(low <= 0.0 && high >= 20.0, "{low}..{high}");
    let tick = |value: f64, l: &GraphLayout| {
        l.value_ticks
            .iter()
            .find(|t| (t.0 - value).abs() < 1e-9)
            .map(|t| t.1)
    };
    let y20 = tick(20.0, &shared).expect("a tick at 20");
    let y0 = tick(0.0, &shared).expect("a tick at 0");
    let expect =
        |v: f64| shared.rect.bottom() - ((v - low) / (high - low)) as f32 * shared.rect.height();
    assert!((y20 - expect(20.0)).abs() < 0.01 && (y0 - expect(0.0)).abs() < 0.01);
    assert!(y20 < y0, "larger values higher up");

    // Back to a range per curve, every curve but the rotation hidden: the axis is labelled
    // in the rotation's own range.
    click_shown(&mut h, "Same scale");
    for name in &HEAD_CURVES[1..] {
        click_shown(&mut h, name);
    }
    let rotate = graph(&h);
    assert_eq!(rotate.curves.len(), 1);
    let (low, high) = (rotate.curves[0].low, rotate.curves[0].high);
    assert!(
        low > -5.0 && high < 25.0,
        "the rotation's own range: {low}..{high}"
    );
    assert!(tick(20.0, &rotate).is_some() && tick(0.0, &rotate).is_some());
    assert!(rotate.value_ticks.iter().all(|t| t.0 >= low && t.0 <= high));
}
