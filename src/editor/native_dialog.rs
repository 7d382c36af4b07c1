//! Native file dialogs where the desktop's file-chooser portal answers; the typed-path windows
//! of [`super::file_menu`] where none does (CI, Xvfb, a bare X server).
//!
//! In: File → Open…, Import layer…, Save as… (and Ctrl+O, Ctrl+Shift+S), and the Browse…
//! buttons of Export Spine (a folder) and Render (an output path). Out: the same calls of
//! [`super::file`] the typed paths make, or the window's field filled in.
//!
//! The dialogs are rfd's xdg-portal backend (`org.freedesktop.portal.FileChooser` over D-Bus,
//! through the system's libdbus loaded at run time). rfd reports a cancelled dialog and a
//! missing portal alike (no path), so whether a portal answers is asked first, once, on a
//! thread ([`file_chooser_portal_answers`]): the session bus is reached and the portal's
//! FileChooser `version` property read. Until that answer, and after a no, the typed windows
//! are used. Each dialog runs on its own thread; the editor keeps drawing meanwhile.

use super::file_menu::PathAction;
use super::EditorApp;
use eframe::egui;
use std::path::PathBuf;
use std::sync::mpsc::{self, Receiver, TryRecvError};

/// The portal's bus name, object and interface (the xdg-desktop-portal specification).
const PORTAL_NAME: &str = "org.freedesktop.portal.Desktop";
const PORTAL_PATH: &str = "/org/freedesktop/portal/desktop";
const FILE_CHOOSER: &str = "org.freedesktop.portal.FileChooser";

/// What a native dialog picks a path for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DialogFor {
    /// Open, Import layer or Save as: the path is acted on at once.
    Path(PathAction),
    /// Export Spine's folder field.
    ExportFolder,
    /// Render's output path field.
    RenderPath,
    /// *Apply motion*'s capture file (animate mode).
    MotionFile,
}

impl DialogFor {
    fn title(self) -> &'static str {
        match self {
            DialogFor::Path(PathAction::OpenRig) => "Open rig",
            DialogFor::Path(PathAction::ImportLayer) => "Import layer",
            DialogFor::Path(PathAction::SaveAs) => "Save as",
            DialogFor::ExportFolder => "Export Spine to folder",
            DialogFor::RenderPath => "Render to",
            DialogFor::MotionFile => "Apply motion from a capture file",
        }
    }
}

/// Whether native dialogs are used.
enum Availability {
    /// Typed paths only (the default: tests, and a desktop without a portal).
    Typed,
    /// Asking the session bus; typed paths until it answers.
    Probing(Receiver<bool>),
    Native,
}

/// The dialogs' state: whether a portal answers, and the dialog open now.
pub struct NativeDialogs {
    availability: Availability,
    pending: Option<(DialogFor, Receiver<Option<PathBuf>>)>,
}

impl Default for NativeDialogs {
    fn default() -> Self {
        NativeDialogs {
            availability: Availability::Typed,
            pending: None,
        }
    }
}

impl NativeDialogs {
    /// Whether a portal answered (the dialogs are native).
    pub fn native(&self) -> bool {
        matches!(self.availability, Availability::Native)
    }

    /// Whether the question to the session bus is still out.
    pub fn probing(&self) -> bool {
        matches!(self.availability, Availability::Probing(_))
    }

    /// Whether a native dialog is open.
    pub fn open(&self) -> bool {
        self.pending.is_some()
    }
}

/// Whether the session bus is reachable and a file-chooser portal on it answers (reading its
/// `version` property activates the portal service when the bus can start it). Blocks until
/// the bus answers: call it on a thread.
pub fn file_chooser_portal_answers() -> bool {
    pollster::block_on(async {
        let Ok(conn) = zbus::Connection::session().await else {
            return false;
        };
        let proxy = zbus::proxy::Builder::<zbus::Proxy>::new(&conn)
            .destination(PORTAL_NAME)
            .and_then(|b| b.path(PORTAL_PATH))
            .and_then(|b| b.interface(FILE_CHOOSER))
            .map(|b| b.cache_properties(zbus::proxy::CacheProperties::No));
        let Ok(builder) = proxy else {
            return false;
        };
        let Ok(proxy) = builder.build().await else {
            return false;
        };
        proxy.get_property::<u32>("version").await.is_ok()
    })
}

/// Shows the dialog for `purpose` (blocking until the user picks or cancels); `None` when
/// cancelled. `current` is the path the field or document has now.
fn run_dialog(purpose: DialogFor, current: Option<PathBuf>) -> Option<PathBuf> {
    let mut dialog = rfd::FileDialog::new().set_title(purpose.title());
    // A folder pick starts in the folder; a file pick beside the file, named as it is.
    let (dir, file_name) = match (&current, purpose) {
        (Some(p), DialogFor::ExportFolder) => (Some(p.as_path()), None),
        (Some(p), _) => (p.parent(), p.file_name()),
        (None, _) => (None, None),
    };
    if let Some(dir) = dir.filter(|d| d.is_dir()) {
        dialog = dialog.set_directory(dir);
    }
    if let Some(name) = file_name {
        dialog = dialog.set_file_name(name.to_string_lossy());
    }
    match purpose {
        DialogFor::Path(PathAction::OpenRig) => {
            dialog.add_filter("sinew rig", &["json"]).pick_file()
        }
        DialogFor::Path(PathAction::ImportLayer) => dialog
            .add_filter(
                "Images and layered files",
                &["png", "psd", "psb", "ora", "json"],
            )
            .pick_file(),
        DialogFor::Path(PathAction::SaveAs) => {
            dialog.add_filter("sinew rig", &["json"]).save_file()
        }
        DialogFor::ExportFolder => dialog.pick_folder(),
        DialogFor::RenderPath => dialog
            .add_filter("GIF, PNG sheet or folder", &["gif", "png"])
            .save_file(),
        DialogFor::MotionFile => dialog
            .add_filter("BVH motion capture", &["bvh", "BVH"])
            .pick_file(),
    }
}

impl EditorApp {
    /// Uses native dialogs once the session bus says a file-chooser portal answers (`sinew
    /// edit` calls this; the typed windows serve until then, and for good after a no).
    pub fn use_native_dialogs_where_a_portal_answers(&mut self) {
        let (tx, rx) = mpsc::channel();
        let repaint = self.repaint.clone();
        std::thread::spawn(move || {
            let _ = tx.send(file_chooser_portal_answers());
            if let Some(ctx) = repaint {
                ctx.request_repaint();
            }
        });
        self.dialogs.availability = Availability::Probing(rx);
    }

    /// Opens the native dialog for `purpose` if a portal answers; false when the caller is
    /// to use its typed path instead.
    pub(super) fn native_dialog(&mut self, purpose: DialogFor, current: Option<PathBuf>) -> bool {
        if !self.dialogs.native() {
            return false;
        }
        if self.dialogs.open() {
            self.message = Some("A file dialog is already open".into());
            return true;
        }
        let (tx, rx) = mpsc::channel();
        let repaint = self.repaint.clone();
        std::thread::spawn(move || {
            let _ = tx.send(run_dialog(purpose, current));
            if let Some(ctx) = repaint {
                ctx.request_repaint();
            }
        });
        self.dialogs.pending = Some((purpose, rx));
        true
    }

    /// The portal's answer and the open dialog's pick, acted on when they arrive.
    pub(super) fn poll_dialogs(&mut self, ctx: &egui::Context) {
        if let Availability::Probing(rx) = &self.dialogs.availability {
            match rx.try_recv() {
                Ok(true) => self.dialogs.availability = Availability::Native,
                Ok(false) | Err(TryRecvError::Disconnected) => {
                    self.dialogs.availability = Availability::Typed
                }
                Err(TryRecvError::Empty) => {
                    ctx.request_repaint_after(std::time::Duration::from_millis(100))
                }
            }
        }
        let Some((purpose, rx)) = self.dialogs.pending.take() else {
            return;
        };
        let picked = match rx.try_recv() {
            Ok(picked) => picked,
            Err(TryRecvError::Empty) => {
                self.dialogs.pending = Some((purpose, rx));
                ctx.request_repaint_after(std::time::Duration::from_millis(100));
                return;
            }
            Err(TryRecvError::Disconnected) => None,
        };
        let Some(path) = picked else {
            self.message = Some(format!("{}: no file chosen", purpose.title()));
            return;
        };
        match purpose {
            DialogFor::Path(PathAction::OpenRig) => self.open(&path),
            DialogFor::Path(PathAction::ImportLayer) => self.import_layer(&path),
            DialogFor::Path(PathAction::SaveAs) => self.save_as(&path),
            DialogFor::ExportFolder => self.export_dir = path.display().to_string(),
            DialogFor::RenderPath => self.render_path = path.display().to_string(),
            DialogFor::MotionFile => {
                self.motion.source = super::apply_motion::MotionSource::File;
                self.motion.file = path.display().to_string();
            }
        }
    }

    /// A Browse… button beside a path field, where native dialogs are used.
    pub(super) fn browse_button(&mut self, ui: &mut egui::Ui, purpose: DialogFor) {
        if !self.dialogs.native() {
            return;
        }
        let current = match purpose {
            DialogFor::ExportFolder => Some(PathBuf::from(self.export_dir.trim())),
            DialogFor::RenderPath => Some(PathBuf::from(self.render_path.trim())),
            DialogFor::MotionFile => Some(PathBuf::from(self.motion.file.trim())),
            DialogFor::Path(_) => None,
        };
        if ui
            .add_enabled(!self.dialogs.open(), egui::Button::new("Browse…"))
            .clicked()
        {
            self.native_dialog(purpose, current);
        }
    }
}
