//! The View menu and its keys: zoom to fit (Home), frame the selection (F), actual size
//! (Ctrl+0: one canvas px per screen point); and the fitted view following the canvas area.
//!
//! In: the keys, the menu's clicks, the selected handle (where the canvas shows it) and the
//! canvas area's size. Out: the canvas's [`View`] (zoom and pan), set on the next frame where
//! the canvas area is known ([`EditorApp::place_view`]). A view the editor fitted and the user
//! has not zoomed or panned since is fitted again when the canvas area changes size (animate
//! mode's timeline takes the bottom of the window, a window is resized): the whole canvas stays
//! in view. A view the user made (wheel, pan, F, Ctrl+0, a saved view) is kept as it is.

use super::canvas::{self, View};
use super::{EditorApp, Mode};
use crate::geom::Point;
use eframe::egui::{self, Key, Modifiers, Vec2};

/// Margin around what a view change fits, screen points.
const FIT_MARGIN_PT: f32 = 24.0;
/// The smallest box (canvas px) "frame the selection" zooms to: a point is framed with its
/// surroundings, not magnified without end.
const MIN_FRAMED_PX: f64 = 96.0;
/// The zoom range (screen points per canvas px), as the mouse wheel's.
const ZOOM_RANGE: (f32, f32) = (0.05, 32.0);

/// A change of the canvas area's width or height (points) above which an untouched fitted view
/// is fitted again (below it: rounding as panels settle).
const AREA_CHANGE_PT: f32 = 0.5;

/// The view the editor fitted last, and the canvas area (points) it fitted it to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fitted {
    pub area: Vec2,
    pub view: View,
}

/// A view change waiting for the canvas area's size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewRequest {
    /// The whole canvas in the area.
    Fit,
    /// A box (canvas px, min and max corners) in the area, centred.
    Frame(Point, Point),
    /// One canvas px per screen point, about the area's centre.
    ActualSize,
}

impl EditorApp {
    /// Home, F and Ctrl+0 (not while typing).
    pub(super) fn view_shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.text_edit_focused() || self.mode == Mode::Colorize {
            return;
        }
        let (fit, frame, actual) = ctx.input_mut(|i| {
            (
                super::file_menu::plain_key(i, Key::Home),
                super::file_menu::plain_key(i, Key::F),
                i.consume_key(Modifiers::COMMAND, Key::Num0),
            )
        });
        if fit {
            self.view_request = Some(ViewRequest::Fit);
        }
        if frame {
            self.frame_selection();
        }
        if actual {
            self.view_request = Some(ViewRequest::ActualSize);
        }
    }

    /// The View menu, each entry with its key.
    pub(super) fn view_menu_button(&mut self, ui: &mut egui::Ui) {
        ui.menu_button("View", |ui| {
            if ui
                .add(egui::Button::new("Zoom to fit").shortcut_text("Home"))
                .on_hover_text("the whole canvas in view (kept so as the window or mode changes)")
                .clicked()
            {
                self.view_request = Some(ViewRequest::Fit);
                ui.close();
            }
            if ui
                .add_enabled(
                    self.selected.is_some(),
                    egui::Button::new("Frame selection").shortcut_text("F"),
                )
                .clicked()
            {
                self.frame_selection();
                ui.close();
            }
            if ui
                .add(egui::Button::new("Actual size (100 %)").shortcut_text("Ctrl+0"))
                .clicked()
            {
                self.view_request = Some(ViewRequest::ActualSize);
                ui.close();
            }
        });
    }

    /// Frames the selected handle where the canvas shows it (posed in pose and animate mode);
    /// with nothing selected, the whole canvas.
    pub fn frame_selection(&mut self) {
        let posed = match self.mode {
            Mode::Pose | Mode::Animate => self.pose_mode.posed.as_ref().map(|p| &p.handles),
            _ => None,
        };
        let handles = posed.unwrap_or(&self.doc.state().handles);
        let corners = self
            .selected
            .as_deref()
            .map(|name| handle_corners(handles, name))
            .unwrap_or_default();
        self.view_request = Some(match bounds(&corners) {
            Some((min, max)) => ViewRequest::Frame(min, max),
            None => ViewRequest::Fit,
        });
    }

    /// Whether the view is the one the editor fitted last (the user has not zoomed or panned
    /// since); true before the first frame too.
    pub fn view_untouched(&self) -> bool {
        match (self.view, self.fitted) {
            (None, _) => true,
            (Some(view), Some(fitted)) => view == fitted.view,
            (Some(_), None) => false,
        }
    }

    /// The view to draw with in an area of `area` points showing a canvas of `canvas_px`:
    /// the pending request applied, or the view as it is (fitted the first time, and again
    /// when the area changed size while the view is [untouched](Self::view_untouched)).
    pub(super) fn place_view(&mut self, canvas_px: [u32; 2], area: Vec2) -> View {
        let resized = self.fitted.is_some_and(|f| {
            let change = (f.area - area).abs();
            change.x > AREA_CHANGE_PT || change.y > AREA_CHANGE_PT
        });
        let refit = self.view.is_none() || (resized && self.view_untouched());
        let current = self.view.unwrap_or_else(|| canvas::fit(canvas_px, area));
        let fit = || {
            let view = canvas::fit(canvas_px, area);
            (view, Some(Fitted { area, view }))
        };
        let (view, fitted) = match self.view_request.take() {
            None if refit => fit(),
            None => (current, self.fitted),
            Some(ViewRequest::Fit) => fit(),
            Some(ViewRequest::ActualSize) => {
                // The canvas point at the area's centre stays there.
                let centre = (area / 2.0 - current.pan) / current.zoom;
                let view = View {
                    zoom: 1.0,
                    pan: area / 2.0 - centre,
                };
                (view, self.fitted)
            }
            Some(ViewRequest::Frame(min, max)) => (frame(min, max, area), self.fitted),
        };
        self.view = Some(view);
        self.fitted = fitted;
        view
    }
}

/// The view showing the box `min`..`max` (canvas px, grown to [`MIN_FRAMED_PX`]) centred in
/// an area of `area` points.
pub fn frame(min: Point, max: Point, area: Vec2) -> View {
    let centre = Vec2::new(
        ((min[0] + max[0]) / 2.0) as f32,
        ((min[1] + max[1]) / 2.0) as f32,
    );
    let size = Vec2::new(
        (max[0] - min[0]).max(MIN_FRAMED_PX) as f32,
        (max[1] - min[1]).max(MIN_FRAMED_PX) as f32,
    );
    let zoom = ((area.x - 2.0 * FIT_MARGIN_PT) / size.x)
        .min((area.y - 2.0 * FIT_MARGIN_PT) / size.y)
        .clamp(ZOOM_RANGE.0, ZOOM_RANGE.1);
    View {
        zoom,
        pan: area / 2.0 - centre * zoom,
    }
}

/// The points that outline handle `name`: a bone's head and tail, a point, a polygon's
/// vertices.
fn handle_corners(handles: &crate::rig::Handles, name: &str) -> Vec<Point> {
    if let Some(b) = handles.bones.iter().find(|b| b.name == name) {
        return vec![b.head, b.tail];
    }
    if let Some(p) = handles.points.iter().find(|p| p.name == name) {
        return vec![p.at];
    }
    let cages = handles.cages.iter().map(|c| (&c.name, &c.polygon));
    let regions = handles.regions.iter().map(|r| (&r.name, &r.polygon));
    cages
        .chain(regions)
        .find(|(n, _)| *n == name)
        .map(|(_, polygon)| polygon.clone())
        .unwrap_or_default()
}

fn bounds(points: &[Point]) -> Option<(Point, Point)> {
    let first = *points.first()?;
    Some(points.iter().fold((first, first), |(lo, hi), p| {
        (
            Point::new(lo.x.min(p.x), lo.y.min(p.y)),
            Point::new(hi.x.max(p.x), hi.y.max(p.y)),
        )
    }))
}
