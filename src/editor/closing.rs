//! Closing the editor without losing work.
//!
//! In: the window's close requests (or [`EditorApp::request_close`]), the document's dirty
//! flag and the saves being written on other threads. Out: the close cancelled while a dialog
//! asks whether to save the changes (Save, Don't save, Cancel); a save still being written
//! finishes before the window closes; at exit the process waits for background writes, so
//! neither a save nor an autosave is cut off halfway (which left its temporary file behind),
//! and colorize strokes changed since their last autosave are autosaved.

use super::EditorApp;
use eframe::egui;

/// Where a request to close the window stands.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Closing {
    /// Nobody asked to close.
    #[default]
    Open,
    /// The document has unsaved changes: the dialog asks what to do with them.
    Asking,
    /// A save is being written on another thread; the window closes once it is done and the
    /// document is clean.
    AfterSave,
    /// The window may close.
    Allowed,
}

impl EditorApp {
    /// Asks to close the window: allowed at once when nothing is unsaved or being saved;
    /// otherwise the dialog asks, or the window waits for the save being written.
    pub fn request_close(&mut self) {
        if self.closing == Closing::Allowed {
            return;
        }
        self.closing = if self.doc.dirty {
            Closing::Asking
        } else if self.saving() {
            Closing::AfterSave
        } else {
            Closing::Allowed
        };
    }

    /// Where a request to close the window stands.
    pub fn closing(&self) -> Closing {
        self.closing
    }

    /// Per frame, after background saves were polled: turns the window's close button into a
    /// request (cancelling the close while something is unsaved), and closes once a save the
    /// close waited for is done.
    pub(super) fn guard_close(&mut self, ctx: &egui::Context) {
        if ctx.input(|i| i.viewport().close_requested()) {
            self.request_close();
            if self.closing != Closing::Allowed {
                ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            }
        }
        if self.closing == Closing::AfterSave && !self.saving() {
            // A failed save, or an edit while it ran, leaves changes to ask about again.
            if self.doc.dirty {
                self.closing = Closing::Asking;
            } else {
                self.close(ctx);
            }
        }
    }

    fn close(&mut self, ctx: &egui::Context) {
        self.closing = Closing::Allowed;
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }

    /// The dialog of a pending close, if any.
    pub(super) fn close_dialog(&mut self, ctx: &egui::Context) {
        let name = self
            .doc
            .path
            .as_ref()
            .and_then(|p| p.file_name())
            .map_or_else(
                || "the document".into(),
                |n| n.to_string_lossy().into_owned(),
            );
        match self.closing {
            Closing::Asking => {
                egui::Modal::new(egui::Id::new("close-dialog")).show(ctx, |ui| {
                    ui.label(format!("Save the changes to {name} before closing?"));
                    ui.horizontal(|ui| {
                        if ui.button("Save").clicked() {
                            self.save();
                            self.closing = if self.saving() {
                                Closing::AfterSave
                            } else if self.doc.dirty {
                                // Not saved (no file name, or an error): the status bar says
                                // why, and the window stays.
                                Closing::Open
                            } else {
                                Closing::Allowed
                            };
                            if self.closing == Closing::Allowed {
                                self.close(ctx);
                            }
                        }
                        if ui.button("Don't save").clicked() {
                            self.close(ctx);
                        }
                        if ui.button("Cancel").clicked() {
                            self.closing = Closing::Open;
                        }
                    });
                });
            }
            Closing::AfterSave => {
                egui::Modal::new(egui::Id::new("close-dialog")).show(ctx, |ui| {
                    ui.label(format!("Saving {name}: the window closes when it is done."));
                    if ui.button("Keep the window open").clicked() {
                        self.closing = Closing::Open;
                    }
                });
            }
            Closing::Open | Closing::Allowed => {}
        }
    }

    /// At exit: autosaves colorize strokes changed since their last save or autosave, and
    /// waits for the saves and autosaves being written on other threads.
    pub fn finish_writes(&mut self) {
        self.autosave_scribbles();
        if let Some(saving) = self.saving.take() {
            let _ = saving.receive.recv();
        }
        if let Some(receive) = self.autosaving.take() {
            let _ = receive.recv();
        }
    }
}
