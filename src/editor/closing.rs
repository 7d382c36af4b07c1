//! Closing the editor without losing work.
//!
//! In: the window's close requests (or [`EditorApp::request_close`]), the document's dirty
//! flag, and the saves and renders running on other threads. Out: the close cancelled while a
//! dialog asks whether to save the changes (Save, Don't save, Cancel; Escape cancels), or
//! while a save or a render finishes (a render can be left unfinished on request); keys and
//! dropped files do not reach the document behind the dialog. At exit the process waits for
//! background saves and autosaves, so none is cut off halfway (which left its temporary file
//! behind), and colorize strokes changed since their last autosave are autosaved.

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
    /// A save or a render is running on another thread; the window closes once it is done
    /// (and the document is clean).
    Waiting,
    /// The window may close.
    Allowed,
}

impl EditorApp {
    /// Asks to close the window: allowed at once when nothing is unsaved or running;
    /// otherwise the dialog asks, or the window waits for the save or render.
    pub fn request_close(&mut self) {
        if self.closing == Closing::Allowed {
            return;
        }
        self.closing = if self.doc.dirty() {
            Closing::Asking
        } else if self.saving() || self.rendering() {
            Closing::Waiting
        } else {
            Closing::Allowed
        };
    }

    /// Where a request to close the window stands.
    pub fn closing(&self) -> Closing {
        self.closing
    }

    /// Whether a dialog about closing is up (it takes the keyboard and dropped files).
    pub fn close_dialog_open(&self) -> bool {
        matches!(self.closing, Closing::Asking | Closing::Waiting)
    }

    /// Per frame, before anything reads the input: while the dialog is up, Escape cancels the
    /// close, and keys, text and dropped files are taken out of the input, so that shortcuts
    /// (Delete, undo, tool keys) and drops cannot change the document the dialog is about.
    pub(super) fn dialog_takes_input(&mut self, ctx: &egui::Context) {
        if !self.close_dialog_open() {
            return;
        }
        if ctx.input(|i| i.key_pressed(egui::Key::Escape)) {
            self.closing = Closing::Open;
        }
        ctx.input_mut(|i| {
            i.events.retain(|e| {
                !matches!(
                    e,
                    egui::Event::Key { .. }
                        | egui::Event::Text(_)
                        | egui::Event::Copy
                        | egui::Event::Cut
                        | egui::Event::Paste(_)
                )
            });
            i.raw.dropped_files.clear();
        });
    }

    /// The window's close button: a request, and the close cancelled (the window shown, so
    /// the dialog can be seen) while something is unsaved or running. Also called from
    /// [`eframe::App::logic`], which eframe runs without `ui` while the window is minimized.
    pub(super) fn close_requests(&mut self, ctx: &egui::Context) {
        if !ctx.input(|i| i.viewport().close_requested()) {
            return;
        }
        self.request_close();
        if self.closing != Closing::Allowed {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            ctx.send_viewport_cmd(egui::ViewportCommand::Minimized(false));
            ctx.send_viewport_cmd(egui::ViewportCommand::Focus);
        }
    }

    /// Per frame, after background work was polled: the window's close button, and the close
    /// once the save or render it waited for is done.
    pub(super) fn guard_close(&mut self, ctx: &egui::Context) {
        self.close_requests(ctx);
        if self.closing == Closing::Waiting && !self.saving() && !self.rendering() {
            // A failed save, or an edit while it ran, leaves changes to ask about again.
            if self.doc.dirty() {
                self.closing = Closing::Asking;
            } else {
                self.close(ctx);
            }
        }
    }

    /// Closes the window whatever is unsaved (Don't save, `--screenshot`).
    pub(super) fn close(&mut self, ctx: &egui::Context) {
        self.closing = Closing::Allowed;
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }

    /// The dialog of a pending close, if any.
    pub(super) fn close_dialog(&mut self, ctx: &egui::Context) {
        match self.closing {
            Closing::Asking => {
                let question = match self.save_target() {
                    Some(path) => {
                        format!("Save the changes to {} before closing?", path.display())
                    }
                    None => "Save the changes before closing? (Type a .json file name in the \
                             File menu first.)"
                        .into(),
                };
                egui::Modal::new(egui::Id::new("close-dialog")).show(ctx, |ui| {
                    ui.label(question);
                    ui.horizontal(|ui| {
                        if ui.button("Save").clicked() {
                            self.save_then_close(ctx);
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
            Closing::Waiting => {
                let what = match &self.saving {
                    Some(saving) => format!("Saving {}", saving.job.target().display()),
                    None => "Rendering".into(),
                };
                egui::Modal::new(egui::Id::new("close-dialog")).show(ctx, |ui| {
                    ui.label(format!("{what}: the window closes when it is done."));
                    ui.horizontal(|ui| {
                        if self.saving.is_none()
                            && ui
                                .button("Close now (the render stays unfinished)")
                                .clicked()
                        {
                            self.close(ctx);
                        }
                        if ui.button("Keep the window open").clicked() {
                            self.closing = Closing::Open;
                        }
                    });
                });
            }
            Closing::Open | Closing::Allowed => {}
        }
    }

    /// The dialog's Save: closes when saved, waits when the save (or a render) runs on, and
    /// keeps the window open when nothing was saved (the status bar says why).
    fn save_then_close(&mut self, ctx: &egui::Context) {
        self.save();
        self.closing = if self.saving() || (!self.doc.dirty() && self.rendering()) {
            Closing::Waiting
        } else if self.doc.dirty() {
            Closing::Open
        } else {
            Closing::Allowed
        };
        if self.closing == Closing::Allowed {
            self.close(ctx);
        }
    }

    /// At exit: autosaves colorize strokes changed since their last save or autosave, and
    /// waits for the saves and autosaves being written on other threads. Nothing shows the
    /// status bar any more, so their failures go to the terminal.
    pub fn finish_writes(&mut self) {
        let before = self.message.clone();
        self.autosave_scribbles();
        if self.message != before {
            if let Some(message) = &self.message {
                eprintln!("sinew edit: {message}");
            }
        }
        let waiting = self
            .saving
            .take()
            .map(|s| s.receive)
            .into_iter()
            .chain(self.autosaving.take());
        for receive in waiting {
            match receive.recv() {
                Ok(Ok(_)) => {}
                Ok(Err(e)) => eprintln!("sinew edit: {e}"),
                Err(_) => eprintln!("sinew edit: a writing thread stopped"),
            }
        }
    }
}
