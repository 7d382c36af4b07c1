//! Colorize mode: scribbles, the background solve, undo, saving and loading scribbles.

use super::*;

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
/// fresh scratch folder `sinew-editor-NAME-XXXXXX`: the scene, the folder (removed when it
/// drops) and the line art's path.
fn one_circle_lineart(
    name: &str,
    size: u32,
    file: &str,
) -> (crate::colorize::synthetic::Scene, TempDir, PathBuf) {
    let s = crate::colorize::synthetic::scene(&crate::colorize::synthetic::SceneSpec {
        size,
        shapes: 1,
        ..Default::default()
    });
    let dir = crate::test_scratch::scratch(&format!("editor-{name}"));
    let lineart = dir.path().join(file);
    crate::io::save_png(&lineart, &s.lineart).expect("written");
    (s, dir, lineart)
}

#[test]
fn colorize_two_scribbles_then_undo_one() {
    use crate::colorize::synthetic::PALETTE;
    let (s, tmp, lineart) = one_circle_lineart("colorize", 128, "lineart.png");
    let dir = tmp.path();
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
    set_number(&mut h, "Brush px:", 4.0);
    assert_eq!(h.state().colorize.width_px, 4.0);
    let hex = |color: [u8; 3]| format!("#{}", crate::colorize::scribbles::hex(color));
    type_into(&mut h, "Color hex:", &hex(PALETTE[10]));
    h.key_press(Key::Enter);
    h.run();
    assert_eq!(h.state().colorize.color, PALETTE[10]);
    drag(&mut h, background[0], background[1]);
    type_into(&mut h, "Color hex:", &hex(PALETTE[0]));
    h.key_press(Key::Enter);
    h.run();
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
}

#[test]
fn colorize_scribbles_save_load_and_autosave() {
    use crate::colorize::session::{ScribbleStroke, SessionCommand};
    use crate::colorize::synthetic::PALETTE;
    let (s, tmp, lineart) = one_circle_lineart("scribbles", 96, "cat.png");
    let dir = tmp.path();
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
    click_shown(&mut h, "Save scribbles");
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
    click_shown(&mut h, "File");
    click_shown(&mut h, "Scribbles JSON:");
    h.key_press_modifiers(Modifiers::COMMAND, Key::A);
    h.key_press(Key::Backspace);
    h.run();
    assert_eq!(h.state().colorize.scribbles_path, "");
    h.key_press(Key::Escape);
    h.run();
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
}
