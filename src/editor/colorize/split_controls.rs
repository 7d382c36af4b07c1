//! Colorize mode's split controls: how a region holding scribbles of several colors is split
//! (`sinew colorize --split` and, for reach, `--split-exponent`).
//!
//! In: the panel's picker and α field. Out: the editor's [`ColorizeOptions`], handed to the
//! open session (which drops the results solved with the old ones, so the shown strokes are
//! solved again) and kept for line art opened later.

use super::super::number_field::number_field;
use super::ColorizeEditor;
use crate::colorize::{ColorizeOptions, RegionSplit, MAX_SPLIT_DEPTH_EXPONENT};
use eframe::egui;

/// Change of α per pixel dragged on its field.
const ALPHA_DRAG_SPEED: f64 = 0.05;

/// What each split does, for its entry's tooltip.
fn help(split: RegionSplit) -> &'static str {
    match split {
        RegionSplit::Reach => {
            "Colors meet at necks; each scribble reaches in proportion to its size"
        }
        RegionSplit::Depth => "Boundaries where the region is narrowest",
        RegionSplit::Density => "Boundaries where ink crowds (G'MIC Smart Coloring's order)",
        RegionSplit::Weights => "The content-aware weights decide",
    }
}

impl ColorizeEditor {
    /// The "Split" picker, its entries named as `--split` names them, and with reach the "α:"
    /// field. A change re-solves the shown strokes; `Err` is a message for the status bar
    /// (options the session refuses, which then change nothing).
    pub(super) fn split_controls(&mut self, ui: &mut egui::Ui) -> Result<(), String> {
        let mut options = self.options.clone();
        egui::ComboBox::from_label("Split")
            .selected_text(options.split.name())
            .show_ui(ui, |ui| {
                for split in RegionSplit::ALL {
                    ui.selectable_value(&mut options.split, split, split.name())
                        .on_hover_text(help(split));
                }
            })
            .response
            .on_hover_text("How a region holding several colors is split");
        if options.split == RegionSplit::Reach {
            ui.horizontal(|ui| {
                let label = ui.label("α:");
                ui.add(
                    number_field(&mut options.split_depth_exponent)
                        .range(0.0..=MAX_SPLIT_DEPTH_EXPONENT)
                        .speed(ALPHA_DRAG_SPEED),
                )
                .labelled_by(label.id)
                .on_hover_text(
                    "A pixel d px from the lines costs d^−α to cross: the larger, the more \
                     the narrowest opening on a path decides",
                );
            });
        }
        if options == self.options {
            return Ok(());
        }
        self.set_options(options)
    }

    /// Colorizes with `options` from now on: the open session's results are dropped and the
    /// running solve cancelled; the picture shown stays until the new solve ends.
    fn set_options(&mut self, options: ColorizeOptions) -> Result<(), String> {
        if let Some(session) = &mut self.session {
            session
                .set_options(options.clone())
                .map_err(|e| e.to_string())?;
        }
        self.options = options;
        self.stop_solve();
        self.failed = None;
        self.latest_stale = true;
        Ok(())
    }
}
