//! The editor's native file dialogs against a file-chooser portal on a private D-Bus session
//! bus, and its typed paths where the bus has no portal.
//!
//! A `dbus-daemon` is started for the test and `DBUS_SESSION_BUS_ADDRESS` points at it (this
//! binary holds this one test, so no other test sees the variable change). The portal is a
//! stand-in serving `org.freedesktop.portal.FileChooser` as xdg-desktop-portal does: a
//! request object path per call and a `Response` signal on it carrying the picked URIs (or
//! code 1, cancelled). The editor's side is the real one: rfd's portal backend through the
//! system's libdbus, driven by key presses and clicks on widgets found by their labels. The
//! clicks are the editor's unit tests' (`shown`, the same file): each fails where a user
//! pointing at the widget's centre would not be on it (egui's own hit test).
#![cfg(feature = "editor")]

mod command;
/// The checked clicks of the editor's unit tests, the same file.
#[path = "../src/editor/tests/shown.rs"]
mod shown;

use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use sinew::document::Document;
use sinew::editor::EditorApp;
use std::collections::{HashMap, VecDeque};
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use zbus::zvariant::{OwnedObjectPath, OwnedValue, Value};

use eframe::egui::{self, Key, Modifiers};
use shown::{click_shown, press_shown};

const PORTAL_NAME: &str = "org.freedesktop.portal.Desktop";
const PORTAL_PATH: &str = "/org/freedesktop/portal/desktop";

/// A private session bus, stopped when dropped.
struct Bus {
    daemon: std::process::Child,
    address: String,
}

impl Bus {
    fn start() -> Bus {
        let mut daemon = std::process::Command::new("dbus-daemon")
            .args(["--session", "--nofork", "--nopidfile", "--print-address=1"])
            .stdout(std::process::Stdio::piped())
            .spawn()
            .expect("dbus-daemon runs (Debian package dbus-daemon)");
        let mut address = String::new();
        std::io::BufReader::new(daemon.stdout.take().expect("stdout"))
            .read_line(&mut address)
            .expect("the bus prints its address");
        Bus {
            daemon,
            address: address.trim().to_string(),
        }
    }
}

impl Drop for Bus {
    fn drop(&mut self) {
        let _ = self.daemon.kill();
        let _ = self.daemon.wait();
    }
}

/// The stand-in portal: answers each call with the next path queued (`None`: the user
/// cancels) and records the calls.
#[derive(Clone, Default)]
struct FileChooser {
    answers: Arc<Mutex<VecDeque<Option<PathBuf>>>>,
    calls: Arc<Mutex<Vec<String>>>,
}

impl FileChooser {
    fn answer(
        &self,
        method: &str,
        header: &zbus::message::Header<'_>,
        conn: &zbus::Connection,
        title: &str,
        options: &HashMap<String, OwnedValue>,
    ) -> zbus::fdo::Result<OwnedObjectPath> {
        let flag = |key: &str| {
            options
                .get(key)
                .and_then(|v| bool::try_from(&**v).ok())
                .unwrap_or(false)
        };
        self.calls.lock().unwrap().push(format!(
            "{method} {title}{}",
            if flag("directory") { " (folder)" } else { "" }
        ));
        let token = options
            .get("handle_token")
            .and_then(|v| <&str>::try_from(&**v).ok().map(str::to_string))
            .unwrap_or_else(|| "t".into());
        let sender = header
            .sender()
            .map(|s| s.trim_start_matches(':').replace('.', "_"))
            .unwrap_or_default();
        let request = format!("{PORTAL_PATH}/request/{sender}/{token}");
        let answer = self.answers.lock().unwrap().pop_front().flatten();
        let conn = conn.clone();
        let path = request.clone();
        // The reply goes out first; the user "picks" a moment later.
        std::thread::spawn(move || {
            std::thread::sleep(std::time::Duration::from_millis(150));
            let mut results: HashMap<&str, Value> = HashMap::new();
            let code: u32 = match &answer {
                Some(p) => {
                    results.insert("uris", Value::from(vec![format!("file://{}", p.display())]));
                    0
                }
                None => 1,
            };
            pollster::block_on(conn.emit_signal(
                None::<&str>,
                path.as_str(),
                "org.freedesktop.portal.Request",
                "Response",
                &(code, results),
            ))
            .expect("the response is sent");
        });
        OwnedObjectPath::try_from(request).map_err(|e| zbus::fdo::Error::Failed(e.to_string()))
    }
}

#[zbus::interface(name = "org.freedesktop.portal.FileChooser")]
impl FileChooser {
    #[zbus(property, name = "version")]
    fn version(&self) -> u32 {
        3
    }

    fn open_file(
        &self,
        #[zbus(header)] header: zbus::message::Header<'_>,
        #[zbus(connection)] conn: &zbus::Connection,
        _parent_window: String,
        title: String,
        options: HashMap<String, OwnedValue>,
    ) -> zbus::fdo::Result<OwnedObjectPath> {
        self.answer("OpenFile", &header, conn, &title, &options)
    }

    fn save_file(
        &self,
        #[zbus(header)] header: zbus::message::Header<'_>,
        #[zbus(connection)] conn: &zbus::Connection,
        _parent_window: String,
        title: String,
        options: HashMap<String, OwnedValue>,
    ) -> zbus::fdo::Result<OwnedObjectPath> {
        self.answer("SaveFile", &header, conn, &title, &options)
    }
}

fn harness(app: EditorApp) -> Harness<'static, EditorApp> {
    Harness::builder()
        .with_size(egui::vec2(1200.0, 800.0))
        .build_ui_state(|ui, app: &mut EditorApp| app.frame(ui), app)
}

/// Steps frames (10 ms apart) until `done`, at most 10 s.
fn wait_for(h: &mut Harness<'_, EditorApp>, what: &str, done: impl Fn(&EditorApp) -> bool) {
    for _ in 0..1000 {
        if done(h.state()) {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
        h.step();
    }
    panic!("waited 10 s for {what}: {:?}", h.state().message);
}

/// An editor that asks the bus for a portal, as `sinew edit` does, once the bus answered.
fn editor_after_probe() -> Harness<'static, EditorApp> {
    let mut app = EditorApp::new(Document::new());
    app.use_native_dialogs_where_a_portal_answers();
    let mut h = harness(app);
    wait_for(&mut h, "the portal probe", |app| !app.dialogs.probing());
    h
}

fn bar_png(dir: &Path) -> PathBuf {
    let png = dir.join("bar.png");
    let bar = image::RgbaImage::from_fn(96, 48, |x, y| {
        let inside = (8..88).contains(&x) && (8..40).contains(&y);
        image::Rgba([200, 80, 40, if inside { 255 } else { 0 }])
    });
    sinew::io::save_png(&png, &bar).expect("written");
    png
}

#[test]
fn dialogs_are_native_where_a_portal_answers_and_typed_where_none_does() {
    // Dropped last: after the editor, its save threads and the portal's answers.
    let tmp = command::scratch("portal");
    let dir = tmp.path();
    let png = bar_png(dir);
    let json = dir.join("bar.json");
    let bus = Bus::start();
    // This binary's one test: no other thread reads the environment meanwhile.
    std::env::set_var("DBUS_SESSION_BUS_ADDRESS", &bus.address);

    // A bus without a portal: Ctrl+O opens the typed path window.
    let mut h = editor_after_probe();
    assert!(!h.state().dialogs.native());
    h.key_press_modifiers(Modifiers::COMMAND, Key::O);
    h.run();
    h.get_by_label("Path:");
    click_shown(&mut h, "Cancel");
    assert!(h.query_by_label("Path:").is_none());
    drop(h);

    // The portal comes up on the bus.
    let chooser = FileChooser::default();
    let _portal = pollster::block_on(async {
        zbus::connection::Builder::address(bus.address.as_str())?
            .name(PORTAL_NAME)?
            .serve_at(PORTAL_PATH, chooser.clone())?
            .build()
            .await
    })
    .expect("the stand-in portal is on the bus");
    let mut h = editor_after_probe();
    assert!(h.state().dialogs.native(), "the portal answered the probe");
    let answer = |path: Option<&Path>| {
        chooser
            .answers
            .lock()
            .unwrap()
            .push_back(path.map(Path::to_path_buf))
    };

    // File → Import layer…: the portal's OpenFile picks the PNG; no typed window.
    answer(Some(&png));
    click_shown(&mut h, "File");
    press_shown(&mut h, "Import layer…");
    h.run_steps(2);
    assert!(h.query_by_label("Path:").is_none());
    wait_for(&mut h, "the import", |app| {
        app.doc.state().layers.len() == 1
    });

    // Ctrl+Shift+S: SaveFile names the rig; the editor saves there.
    answer(Some(&json));
    h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::S);
    h.run_steps(2);
    wait_for(&mut h, "the save", |app| {
        app.doc.path.as_deref() == Some(json.as_path()) && !app.saving() && !app.doc.dirty()
    });
    assert!(json.is_file());

    // Ctrl+N, then Ctrl+O cancelled: nothing opens and the status says so.
    h.key_press_modifiers(Modifiers::COMMAND, Key::N);
    h.run();
    assert!(h.state().doc.path.is_none());
    answer(None);
    h.key_press_modifiers(Modifiers::COMMAND, Key::O);
    h.run_steps(2);
    wait_for(&mut h, "the cancel", |app| !app.dialogs.open());
    let message = h.state().message.clone().unwrap_or_default();
    assert!(
        message.contains("no file chosen"),
        "{message} {:?}",
        chooser.calls.lock().unwrap()
    );
    assert!(h.state().doc.path.is_none());

    // Ctrl+O again: OpenFile picks the saved rig.
    answer(Some(&json));
    h.key_press_modifiers(Modifiers::COMMAND, Key::O);
    h.run_steps(2);
    wait_for(&mut h, "the open", |app| {
        app.doc.path.as_deref() == Some(json.as_path())
    });
    assert_eq!(h.state().doc.state().layers.len(), 1);

    // Export Spine…: Browse… picks a folder for its field.
    let out = dir.join("spine-out");
    std::fs::create_dir_all(&out).expect("folder");
    answer(Some(&out));
    click_shown(&mut h, "File");
    click_shown(&mut h, "Export Spine…");
    press_shown(&mut h, "Browse…");
    h.run_steps(2);
    wait_for(&mut h, "the export folder", |app| !app.dialogs.open());
    assert_eq!(
        h.get_by_label("Export folder:").value().as_deref(),
        Some(out.display().to_string().as_str())
    );

    assert_eq!(
        *chooser.calls.lock().unwrap(),
        [
            "OpenFile Import layer",
            "SaveFile Save as",
            "OpenFile Open rig",
            "OpenFile Open rig",
            "OpenFile Export Spine to folder (folder)",
        ]
    );
    drop(h);
    std::env::remove_var("DBUS_SESSION_BUS_ADDRESS");
}
