//! The editor driven through egui_kittest: real frames, simulated pointer and keys, checked
//! against the document. Widgets are clicked through [`click_shown`] and [`click_shown_by`]
//! (or [`press_shown_by`] where frames are stepped), which fail where a user could not click
//! them ([`shown`], shared with the integration test `tests/editor_portal.rs`), and brought
//! into view with the mouse wheel ([`wheel_into_view`]); clippy.toml disallows kittest's own
//! clicks and scrolls, so an exception says so at its place.

use super::rig_mode::distance;
use crate::geom::Point;

use super::*;

use crate::rig::PointHandle;

use eframe::egui::Pos2;

use egui_kittest::kittest::{By, NodeT, Queryable};

use egui_kittest::Harness;

use std::path::Path;

use tempfile::TempDir;

use std::sync::Arc;

mod animate;
mod apply_motion;
mod bind;
mod carried_points;
mod colorize;
mod colorize_split;
mod deform;
mod documents;
mod events;
mod files;
mod fit;
mod graph;
mod key_menu;
mod outputs;
mod physics;
mod pose;
mod proposal_template;
mod rig;
mod rows;
mod selection;
mod timeline;
mod tree_height;
mod tree_points;
mod tree_view;
mod workflow;

/// The checked clicks, shared with `tests/editor_portal.rs` (which includes the file by path).
mod shown;
use shown::{
    assert_shown, click_shown, click_shown_by, press_point, press_shown, press_shown_by,
    under_pointer,
};

/// Frames a background weight build may take before a test gives up (50 ms apart).
const BUILD_FRAMES: usize = 1200;

/// Frames one `Harness::run` may take before it fails (kittest's default is 4). A save or
/// autosave written on another thread wakes the UI when it ends (`file.rs`), at a moment that
/// depends on the machine's load: landing inside a `run`, each wake-up adds up to two frames
/// to the three a typed field usually takes, and a run may see the save's and the autosave's.
/// A UI that never stops repainting still fails.
const MAX_STEPS_PER_RUN: u64 = 8;

fn harness(app: EditorApp) -> Harness<'static, EditorApp> {
    harness_sized(app, egui::vec2(1200.0, 800.0))
}

/// [`harness`] in a window of `size` points.
fn harness_sized(app: EditorApp, size: egui::Vec2) -> Harness<'static, EditorApp> {
    Harness::builder()
        .with_size(size)
        .with_max_steps(MAX_STEPS_PER_RUN)
        .build_ui_state(|ui, app: &mut EditorApp| app.frame(ui), app)
}

/// The bundled character rigged with default options, saved (with absolute image paths) in a
/// fresh scratch folder: the folder (removed when it drops) and the rig's path.
fn character_rig(name: &str) -> (TempDir, PathBuf) {
    character_rig_with(name, false)
}

/// [`character_rig`] with, when `skins`, the other attachments of its slots and its skins, as
/// `sinew demo` rigs them (`layers.json`'s `attachments` and `skins`).
fn character_rig_with(name: &str, skins: bool) -> (TempDir, PathBuf) {
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
    let mut paths = paths;
    let attachments: std::collections::BTreeMap<String, String> = match skins {
        true => serde_json::from_value(list["attachments"].clone()).expect("attachments"),
        false => Default::default(),
    };
    paths.extend(attachments.keys().map(|n| assets.join(format!("{n}.png"))));
    let layers = crate::pipeline::load_layers(&paths).expect("layers");
    let handles: crate::rig::Handles = serde_json::from_str(
        &std::fs::read_to_string(assets.join("handles.json")).expect("handles.json"),
    )
    .expect("handles parse");
    let dir = crate::test_scratch::scratch(&format!("editor-{name}"));
    let (mut doc, _) = crate::pipeline::build_rig(&layers, &assets, &Default::default(), &handles)
        .expect("the character rigs");
    if skins {
        let skins = serde_json::from_value(list["skins"].clone()).expect("skins");
        doc.set_slots(&attachments, skins).expect("slots and skins");
    }
    for part in &mut doc.parts {
        part.image = assets.join(&part.image).to_string_lossy().into_owned();
    }
    let path = dir.path().join("character.json");
    doc.save(&path).expect("saved");
    (dir, path)
}

/// A harness with the scratch folder of the document it opened. When it drops, it first waits
/// for the editor's saves and autosaves still being written on other threads (as the editor
/// does at exit), then the harness drops, then the folder: no write lands in the folder as it
/// is removed (one that did left the folder behind, holding an autosave).
struct InFolder {
    h: Harness<'static, EditorApp>,
    _dir: TempDir,
}

impl Drop for InFolder {
    fn drop(&mut self) {
        self.h.state_mut().finish_writes();
    }
}

/// The editor on the document at `path` in `dir` (no frame run yet).
fn opened_in(dir: TempDir, path: &Path) -> InFolder {
    let h = harness(EditorApp::new(Document::open(path).expect("opens")));
    InFolder { h, _dir: dir }
}

impl std::ops::Deref for InFolder {
    type Target = Harness<'static, EditorApp>;
    fn deref(&self) -> &Self::Target {
        &self.h
    }
}

impl std::ops::DerefMut for InFolder {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.h
    }
}

/// The editor on [`character_rig`]`(name)`, after its first frames.
fn open_character(name: &str) -> InFolder {
    let (dir, path) = character_rig(name);
    let mut h = opened_in(dir, &path);
    h.run();
    h
}

fn screen(h: &Harness<'_, EditorApp>, canvas_px: impl Into<Point>) -> Pos2 {
    let canvas_px = canvas_px.into();
    h.state()
        .placed
        .expect("the canvas was drawn")
        .screen_from_canvas(canvas_px)
}

/// Press at `from`, move in steps, release at `to` (canvas px).
fn drag(h: &mut Harness<'_, EditorApp>, from: impl Into<Point>, to: impl Into<Point>) {
    let (from, to) = (from.into(), to.into());
    h.drag_at(screen(h, from));
    h.step();
    for k in 1..=4 {
        let t = k as f64 / 4.0;
        let p = from + t * (to - from);
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

/// A point well inside the torso at rest and away from the bones (a drag there moves the
/// drawing), canvas px.
fn torso_point(h: &Harness<'_, EditorApp>) -> Point {
    off_bone_point(h, "torso")
}

/// A rest vertex of part `name` that lies on the drawing but away from every bone's line
/// (more than twice the pick radius on screen), the one nearest the part's centroid: a drag
/// there moves the drawing, not a bone.
fn off_bone_point(h: &Harness<'_, EditorApp>, name: &str) -> Point {
    let scene = h.state().doc.posable().expect("posable").clone();
    let zoom = f64::from(h.state().placed.expect("drawn").view.zoom);
    let clear_px = 2.0 * f64::from(canvas::PICK_RADIUS_PT) / zoom;
    let part = scene
        .doc
        .parts
        .iter()
        .find(|p| p.name == name)
        .expect("part");
    let from_bones = |p: Point| {
        scene
            .doc
            .handles
            .bones
            .iter()
            .map(|b| crate::geom::segment_distance(p, b.head, b.tail).0)
            .fold(f64::INFINITY, f64::min)
    };
    // Interior vertices only (a vertex of the outline may sit on the drawing's edge).
    let boundary: std::collections::HashSet<u32> = part
        .mesh
        .triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .fold(std::collections::HashMap::new(), |mut m, (a, b)| {
            *m.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            m
        })
        .into_iter()
        .filter(|(_, n)| *n == 1)
        .flat_map(|((a, b), _)| [a, b])
        .collect();
    // The one nearest the part's centroid.
    let v = &part.mesh.vertices;
    let n = v.len() as f64;
    let c = v.iter().fold(Point::origin(), |a, p| a + p.coords / n);
    (0..v.len() as u32)
        .filter(|i| !boundary.contains(i))
        .map(|i| v[i as usize])
        .filter(|&p| from_bones(p) > clear_px)
        .min_by(|&a, &b| distance(a, c).total_cmp(&distance(b, c)))
        .expect("a vertex away from the bones")
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
    click_shown(h, label);
    h.key_press_modifiers(Modifiers::COMMAND, Key::A);
    h.run();
    h.get_by_label(label).type_text(text);
    h.run();
}

/// Lines (egui's `line_scroll_speed`, 40 pt) one turn of [`wheel_into_view`]'s wheel scrolls
/// at most; fewer when the widget is nearer its area's edge.
const WHEEL_LINES: f32 = 3.0;

/// Turns of the wheel [`wheel_into_view`] makes before it fails.
const WHEEL_TURNS: usize = 30;

/// How far inside its area [`wheel_into_view`] holds the pointer, pt.
const WHEEL_MARGIN_PT: f32 = 4.0;

/// Widgets [`holding_area`] points at, looking for one a user sees, before it fails.
const AREA_PROBES: usize = 40;

/// Brings the widget `by` finds into view as a user does: the pointer over the area holding it
/// (where [`holding_area`] finds it shown, nearest the widget), the mouse wheel turned towards
/// the widget a few lines at a time (one `run` each), until a user pointing at its centre
/// would be on it ([`assert_shown`]'s hit test). Fails after [`WHEEL_TURNS`] turns, or when the
/// widget lies in its area's view and still is not under the pointer (covered).
fn wheel_into_view(h: &mut Harness<'_, EditorApp>, by: By<'_>) {
    let what = format!("{by:?}");
    let line_pt = h.ctx.options(|o| o.input_options.line_scroll_speed);
    for _ in 0..WHEEL_TURNS {
        let (id, at) = press_point(&h.get(by.clone()));
        let screen = h.ctx.content_rect();
        if screen.contains(at) && under_pointer(h, at, id) {
            return;
        }
        let area = holding_area(h, &by, &what);
        let inside = area.shrink(WHEEL_MARGIN_PT.min(area.height() / 4.0));
        // Down (the content moves up: a negative wheel delta) when the widget is below.
        let beyond_pt = if at.y > inside.bottom() {
            inside.bottom() - at.y
        } else if at.y < inside.top() {
            inside.top() - at.y
        } else {
            panic!("{what}: at {at:?}, in its area's view {area:?}, not under the pointer");
        };
        let lines = (beyond_pt.abs() / line_pt).ceil().clamp(1.0, WHEEL_LINES);
        h.hover_at(inside.clamp(at));
        h.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Line,
            delta: egui::vec2(0.0, lines.copysign(beyond_pt)),
            phase: egui::TouchPhase::Move,
            modifiers: Modifiers::NONE,
        });
        h.run();
    }
    let (id, at) = press_point(&h.get(by));
    assert!(
        under_pointer(h, at, id),
        "{what}: not in view after {WHEEL_TURNS} turns of the wheel"
    );
}

/// Where a user sees the area holding the widget `by`: the visible part (egui's rect clipped by
/// its parents', as its hit test uses it) of the innermost Ui around the widget that shows any
/// of what it holds. Found by pointing at the widgets drawn nearest the widget in each Ui
/// around it, innermost first, until one is under the pointer; fails after [`AREA_PROBES`].
fn holding_area(h: &mut Harness<'_, EditorApp>, by: &By<'_>, what: &str) -> egui::Rect {
    let screen = h.ctx.content_rect();
    let (around, centre, levels) = {
        let node = h.get(by.clone());
        let centre = node.rect().center();
        let mut around = Vec::new();
        let mut levels: Vec<Vec<(egui::accesskit::NodeId, Pos2)>> = Vec::new();
        let mut seen = std::collections::HashSet::from([node.accesskit_node().locate().0]);
        let mut ui = node.accesskit_node().parent();
        while let Some(parent) = ui {
            around.push(parent.locate().0);
            let mut drawn: Vec<_> = node
                .new_related(parent)
                .children_recursive()
                .filter_map(|n| {
                    let id = n.accesskit_node().locate().0;
                    let at = n
                        .accesskit_node()
                        .bounding_box()
                        .map(|_| n.rect().center())?;
                    (seen.insert(id) && screen.contains(at)).then_some((id, at))
                })
                .collect();
            drawn.sort_by(|a, b| a.1.distance(centre).total_cmp(&b.1.distance(centre)));
            levels.push(drawn);
            ui = parent.parent();
        }
        (around, centre, levels)
    };
    let mut probes = 0;
    for (id, at) in levels.into_iter().flatten() {
        probes += 1;
        assert!(
            probes <= AREA_PROBES,
            "{what}: none of the {AREA_PROBES} widgets nearest its centre {centre:?} is in view"
        );
        if !under_pointer(h, at, id) {
            continue;
        }
        // egui's hit test takes a widget within its search radius of the pointer: the Uis
        // around it are read at the middle of its visible part.
        let shown = h.ctx.interaction_snapshot(|s| {
            s.contains_pointer
                .iter()
                .find(|w| w.accesskit_id() == id)
                .copied()
        });
        if let Some(visible) = shown.and_then(|w| h.ctx.read_response(w)) {
            let middle = visible.interact_rect.center();
            if !visible.interact_rect.contains(at) && !under_pointer(h, middle, id) {
                continue;
            }
        }
        let under = h.ctx.interaction_snapshot(|s| s.contains_pointer.clone());
        let innermost = around
            .iter()
            .find_map(|ui| under.iter().find(|w| w.accesskit_id() == *ui).copied());
        if let Some(ui) = innermost.and_then(|ui| h.ctx.read_response(ui)) {
            return ui.interact_rect;
        }
    }
    panic!("{what}: nothing around it is in view");
}

/// Wheels the widget labelled `label` (a tree row, say) into view ([`wheel_into_view`]), then
/// [`click_shown`]s it.
fn click_label(h: &mut Harness<'_, EditorApp>, label: &str) {
    wheel_into_view(h, By::new().label(label));
    click_shown(h, label);
}

/// Drags the tree row labelled `from` (pressed at its middle) and releases it on the row
/// labelled `onto` (a handle's row, or the "no parent" row), in pointer steps. Rows are found
/// as buttons: the weights readout beside the canvas may show the same names as text.
fn drag_row(h: &mut Harness<'_, EditorApp>, from: &str, onto: &str) {
    let target = |h: &Harness<'_, EditorApp>| {
        let row = h
            .query(button(onto))
            .unwrap_or_else(|| h.get_by_label(onto));
        row.rect().center()
    };
    wheel_into_view(h, button(from));
    let start = press_point(&h.get(button(from)));
    assert_shown(h, start, from);
    let start = start.1;
    h.drag_at(start);
    h.step();
    // Past egui's drag threshold, so the drop row for "no parent" shows.
    h.hover_at(start + egui::vec2(0.0, 12.0));
    h.step();
    h.step();
    // The target row is found again at every step, as an eye follows it: a drag near the
    // tree's edge scrolls it.
    let mut end = target(h);
    for k in 1..=4 {
        end = target(h);
        assert!(end.y > 0.0, "the row {onto} is scrolled out of view");
        h.hover_at(start + (end - start) * (k as f32 / 4.0));
        h.step();
    }
    h.drop_at(end);
    h.step();
    h.run();
}

/// Whether the tree shows `name` selected (egui reports a selectable label as toggled).
fn tree_selected(h: &Harness<'_, EditorApp>, name: &str) -> bool {
    h.get_by_label(name).accesskit_node().toggled() == Some(egui::accesskit::Toggled::True)
}

/// The combo box labelled `label`, for [`click_shown_by`] and lookups.
fn combo_box(label: &str) -> By<'_> {
    By::new().role(egui::accesskit::Role::ComboBox).label(label)
}

/// The button labelled `label` (not a window's title of the same text).
fn button(label: &str) -> By<'_> {
    By::new().role(egui::accesskit::Role::Button).label(label)
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

/// Opens the File menu, types `text` into its field `label` and closes the menu again.
fn type_in_file_menu(h: &mut Harness<'_, EditorApp>, label: &str, text: &str) {
    click_shown(h, "File");
    type_into(h, label, text);
    assert_eq!(h.get_by_label(label).value().as_deref(), Some(text));
    // The first Escape leaves the field, the second closes the menu.
    h.key_press(Key::Escape);
    h.run();
    h.key_press(Key::Escape);
    h.run();
    assert!(
        h.query_by_label(label).is_none(),
        "the File menu stayed open"
    );
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
fn the_help_overlay_lists_the_shortcuts() {
    let mut h = harness(EditorApp::new(Document::new()));
    h.run();
    h.key_press(Key::F1);
    h.run();
    for (keys, _) in SHORTCUTS {
        h.get_by_label(keys);
    }
}

/// Keys animation "nod": the head turned `degrees` at each `time_s`.
fn key_nod(app: &mut EditorApp, keys: &[(f64, f64)]) {
    for &(time_s, degrees) in keys {
        assert!(app.apply(Command::SetKey {
            animation: "nod".into(),
            time_s,
            pose: head_turned(degrees),
            keep: vec!["head".into()],
            sampling: Default::default(),
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

/// In animate mode, through the animation list and the numbers panel: a new animation renamed
/// "nod", the head (a click on the bone selects it) keyed at 0° at 0 s and at 20° at 0.5 s.
fn key_a_nod_from_the_numbers_panel(h: &mut Harness<'_, EditorApp>) {
    click_shown(h, "New animation");
    type_into(h, "Rename to:", "nod");
    click_shown(h, "Rename animation");
    click(h, Point::new(256.0, 150.0));
    assert_eq!(h.state().selected.as_deref(), Some("head"));
    for (frames, degrees) in [(0, 0.0), (12, 20.0)] {
        for _ in 0..frames {
            click_shown(h, "Next frame");
        }
        // 0° is the rest pose's: another number first, so the pose names the head.
        set_number(h, "Rotation", degrees + 5.0);
        set_number(h, "Rotation", degrees);
        click_shown(h, "Set key");
    }
}

/// Types `value` into the numbers panel's field `label` and enters it.
fn set_number(h: &mut Harness<'_, EditorApp>, label: &str, value: f64) {
    type_into(h, label, &value.to_string());
    h.key_press(Key::Enter);
    h.run();
}

/// Press and release at `at` (canvas px) without moving.
fn click(h: &mut Harness<'_, EditorApp>, at: impl Into<Point>) {
    let at = at.into();
    h.drag_at(screen(h, at));
    h.step();
    h.drop_at(screen(h, at));
    h.step();
    h.run();
}

/// Where the document's pose shows `bone`'s head, canvas px.
fn shown_head(h: &Harness<'_, EditorApp>, bone: &str) -> Point {
    let scene = h.state().doc.posable().expect("posable").clone();
    let shown = scene
        .handle_transforms(&h.state().doc.state().pose)
        .expect("forward kinematics");
    crate::rig::fk_edit::target(&scene.doc.handles, &shown, bone)
        .expect("a bone")
        .pivot_px
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

/// The character with animation "nod" (the head turned 0° at 0 s, 30° at 0.5 s) in its file.
fn character_with_nod(name: &str) -> (TempDir, PathBuf) {
    let (dir, path) = character_rig(name);
    let mut doc = crate::io::RigDocument::load(&path).expect("loads");
    let mut app = EditorApp::new(Document::open(&path).expect("opens"));
    key_nod(&mut app, &[(0.0, 0.0), (0.5, 30.0)]);
    doc.animations = app.doc.state().animations.clone();
    doc.save(&path).expect("saved");
    (dir, path)
}

/// Shift-click at `at` (canvas px) without moving: one frame per event, as a window sends them.
fn shift_click(h: &mut Harness<'_, EditorApp>, at: impl Into<Point>) {
    let at = at.into();
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
fn part_point(h: &Harness<'_, EditorApp>, name: &str) -> Point {
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
    let c = v.iter().fold(Point::origin(), |a, p| a + p.coords / n);
    let vertex = (0..v.len())
        .min_by(|&a, &b| distance(v[a], c).total_cmp(&distance(v[b], c)))
        .expect("vertices");
    (part, vertex)
}

/// Where the canvas shows the vertex [`part_point`] picks, px.
fn shown_part_point(h: &Harness<'_, EditorApp>, name: &str) -> Point {
    let (part, vertex) = central_vertex(h, name);
    let shown = shown_vertices(h)[part][vertex];
    Point::new(shown.x, shown.y)
}

/// The character with its skins, in animate mode on a new empty animation (made with the *New
/// animation* button); its harness and the animation's name.
fn new_animation_on_skinned_character(name: &str) -> (InFolder, String) {
    let (dir, path) = character_rig_with(name, true);
    let mut h = opened_in(dir, &path);
    h.run();
    h.key_press(Key::Num3);
    h.run();
    click_shown(&mut h, "New animation");
    let animation = h.state().animate.animation.clone();
    (h, animation)
}

/// The bag slot's attachment keys in `animation`: (time, attachment shown).
fn bag_attachment_keys(h: &Harness<'_, EditorApp>, animation: &str) -> Vec<(f64, Option<String>)> {
    let anim = crate::document::animation_named(h.state().doc.state(), animation);
    let swaps = anim.parts.get("bag").and_then(|p| p.attachment.clone());
    swaps
        .unwrap_or_default()
        .into_iter()
        .map(|k| (k.time, k.value))
        .collect()
}
