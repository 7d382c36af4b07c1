//! Messages for the user: the status bar shows the latest for [`MESSAGE_SHOWN_S`]; every
//! message, errors marked, stays in the log window (the status bar's *Log* button).
//!
//! In: [`EditorApp::message`] as any part of the editor sets it ([`EditorApp::fail`] for an
//! error). Out: the status bar's text while it is fresh, and the log.

use super::EditorApp;
use eframe::egui::{self, Color32};

/// Seconds a message stays in the status bar.
pub const MESSAGE_SHOWN_S: f64 = 8.0;
/// How long after a message expires the frame that takes it away is asked for, seconds.
const EXPIRY_REPAINT_MARGIN_S: f64 = 0.1;

/// Messages the log keeps; older ones are dropped.
pub const MAX_LOGGED: usize = 500;

/// One message as logged.
#[derive(Clone, Debug, PartialEq)]
pub struct Logged {
    /// Seconds since the editor started (egui's clock).
    pub time_s: f64,
    pub text: String,
    pub error: bool,
}

/// The messages so far and when the latest appeared.
#[derive(Default)]
pub struct MessageLog {
    pub entries: Vec<Logged>,
    /// The message last logged, to see when [`EditorApp::message`] changes.
    last: Option<String>,
    /// When it appeared.
    since_s: f64,
    /// The log window is open.
    pub open: bool,
}

impl MessageLog {
    pub fn errors(&self) -> usize {
        self.entries.iter().filter(|e| e.error).count()
    }
}

impl EditorApp {
    /// Reports an error: the status bar shows it, the log keeps it marked as one.
    pub fn fail(&mut self, text: impl Into<String>) {
        self.message = Some(text.into());
        self.message_is_error = true;
    }

    /// Logs the message if it changed since the last frame (called at the start and the end of
    /// each frame).
    pub(super) fn log_message(&mut self, now_s: f64) {
        if self.message != self.log.last {
            self.log.last = self.message.clone();
            self.log.since_s = now_s;
            if let Some(text) = &self.message {
                self.log.entries.push(Logged {
                    time_s: now_s,
                    text: text.clone(),
                    error: self.message_is_error,
                });
                let excess = self.log.entries.len().saturating_sub(MAX_LOGGED);
                self.log.entries.drain(..excess);
            }
        }
        self.message_is_error = false;
    }

    /// The message the status bar shows now: the latest, while it is fresh.
    pub fn shown_message(&self, now_s: f64) -> Option<&str> {
        self.message
            .as_deref()
            .filter(|_| now_s - self.log.since_s < MESSAGE_SHOWN_S)
    }

    /// The status bar's message and its log button.
    pub(super) fn message_ui(&mut self, ui: &mut egui::Ui) {
        let now = ui.input(|i| i.time);
        let errors = self.log.errors();
        let label = if errors > 0 {
            format!("Log ({errors} errors)")
        } else {
            "Log".to_string()
        };
        if ui.button(label).clicked() {
            self.log.open = !self.log.open;
        }
        let latest_error = self.log.entries.last().is_some_and(|e| e.error);
        if let Some(message) = self.shown_message(now) {
            ui.separator();
            if latest_error {
                ui.colored_label(Color32::from_rgb(230, 90, 80), message);
            } else {
                ui.label(message);
            }
        }
        // One more frame when the message expires, to take it off the status bar: a little
        // after, never "now" (egui takes a frame off the delay, and a delay within a frame of the
        // expiry would become a repaint loop until the clock passes it).
        if self.message.is_some() {
            let left = MESSAGE_SHOWN_S - (now - self.log.since_s);
            if left > 0.0 {
                ui.ctx()
                    .request_repaint_after(std::time::Duration::from_secs_f64(
                        left + EXPIRY_REPAINT_MARGIN_S,
                    ));
            }
        }
    }

    /// The log window: every message, newest first, errors in red.
    pub(super) fn log_window(&mut self, ctx: &egui::Context) {
        let mut open = self.log.open;
        egui::Window::new("Messages")
            .open(&mut open)
            .default_height(300.0)
            .show(ctx, |ui| {
                if ui.button("Clear").clicked() {
                    self.log.entries.clear();
                }
                egui::ScrollArea::vertical().show(ui, |ui| {
                    for entry in self.log.entries.iter().rev() {
                        let text = format!("{:>8.1} s  {}", entry.time_s, entry.text);
                        if entry.error {
                            ui.colored_label(Color32::from_rgb(230, 90, 80), text);
                        } else {
                            ui.label(text);
                        }
                    }
                });
            });
        self.log.open = open;
    }
}
