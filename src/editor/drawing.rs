//! The canvas frame: what is drawn and which mode gets the pointer.
//!
//! In: the document, the mode, the gesture under way, the view. Out: the canvas painted — in
//! rig mode the layers at rest (with the selected handle's weights); in pose and animate mode
//! the posed drawing as `sinew render` draws it — and the pointer handed to the mode.
//!
//! A pose is drawn one way: posed by [`super::pose_mode::pose_frame`] (a static pose) or by the
//! library's [`crate::scene::Playhead`] (animate mode's playhead), listed back to front with
//! each part's tint and visibility by [`crate::playback::pose_draws`] (the list `sinew render`
//! draws), drawn by the library's renderer ([`Scene::draw_parts`]) into a pixmap of the canvas's
//! on-screen size in physical pixels, shown as one texture. The picture is kept while the rig,
//! the pose, the blend, the view and the canvas size stay the same, so idle frames cost nothing.

use super::canvas::{self, Placed, View};
use super::identity::Identity;
use super::{gizmo, EditorApp, Gesture, Mode, Tool};
use crate::pipeline::{Layer, Scene};
use crate::rig::{Bone, Pose};
use crate::skin::Blend;
use eframe::egui::{self, Color32, Pos2, Rect, Sense, TextureHandle};
use std::sync::Arc;
use std::time::Instant;

/// One part of a drawn picture, as the library's draw list gave it.
#[derive(Clone, Debug, PartialEq)]
pub struct DrawnPart {
    /// The part's index in the rig document.
    pub part: usize,
    pub name: String,
    /// Red, green, blue, alpha factors.
    pub tint: [f32; 4],
    pub visible: bool,
}

/// What a picture shows; a picture with the same key is the same picture.
#[derive(Clone, Debug, PartialEq)]
struct PictureKey {
    scene: Identity<Scene>,
    pose: Pose,
    blend: Blend,
    view: View,
    size_px: [u32; 2],
    pixels_per_point: f32,
}

/// The posed drawing rendered for the canvas.
pub struct Picture {
    key: PictureKey,
    texture: TextureHandle,
    /// The draw list it was drawn from, back to front.
    pub draws: Vec<DrawnPart>,
    /// Its pixels (premultiplied RGBA), one per physical pixel of `rect`.
    pub pixmap: tiny_skia::Pixmap,
    /// The screen rectangle it covers, points.
    pub rect: Rect,
    /// How long drawing it took, ms.
    pub draw_ms: f64,
}

impl Picture {
    /// The premultiplied RGBA pixel shown at screen point `at` (`None` outside the picture).
    pub fn pixel_at(&self, at: Pos2) -> Option<[u8; 4]> {
        let scale = self.pixmap.width() as f32 / self.rect.width();
        let p = (at - self.rect.min) * scale;
        if p.x < 0.0 || p.y < 0.0 {
            return None;
        }
        let c = self.pixmap.pixel(p.x as u32, p.y as u32)?;
        Some([c.red(), c.green(), c.blue(), c.alpha()])
    }
}

/// The canvas's textures: each layer's (rig mode) and the posed drawing's picture.
#[derive(Default)]
pub struct Drawing {
    layers: Vec<(Identity<Layer>, TextureHandle)>,
    /// The last picture of a posed drawing (pose and animate mode).
    pub picture: Option<Picture>,
}

impl EditorApp {
    /// The texture of each layer, uploaded once per layer image.
    pub(super) fn layer_textures(&mut self, ctx: &egui::Context) -> Vec<TextureHandle> {
        let layers = self.doc.state().layers.clone();
        let mut out = Vec::with_capacity(layers.len());
        for layer in &layers {
            if let Some((_, t)) = self.drawing.layers.iter().find(|(k, _)| k.is(layer)) {
                out.push(t.clone());
                continue;
            }
            let image = egui::ColorImage::from_rgba_unmultiplied(
                [layer.image.width() as usize, layer.image.height() as usize],
                layer.image.as_raw(),
            );
            let texture = ctx.load_texture(&layer.name, image, egui::TextureOptions::LINEAR);
            self.drawing
                .layers
                .push((Identity::of(layer), texture.clone()));
            out.push(texture);
        }
        self.drawing
            .layers
            .retain(|(k, _)| layers.iter().any(|l| k.is(l)));
        out
    }

    /// The picture of [`super::pose_mode::PoseMode::posed`] on the canvas `rect`, drawn anew
    /// only when what it shows changed.
    pub(super) fn picture(
        &mut self,
        ctx: &egui::Context,
        scene: &Arc<Scene>,
        rect: Rect,
        placed: &Placed,
    ) -> Result<(), String> {
        let Some(posed) = self.pose_mode.posed.as_ref().filter(|p| p.scene.is(scene)) else {
            // Nothing of this rig was posed yet (its first pose failed): nothing to show.
            self.drawing.picture = None;
            return Ok(());
        };
        let pixels_per_point = ctx.pixels_per_point();
        let size_px = [
            (rect.width() * pixels_per_point).round().max(1.0) as u32,
            (rect.height() * pixels_per_point).round().max(1.0) as u32,
        ];
        // The parts the tree hides are left out of the draw list.
        let pose = self.with_hidden_parts(&posed.pose);
        let key = PictureKey {
            scene: Identity::of(scene),
            pose: pose.clone(),
            blend: self.render_settings.blend,
            view: placed.view,
            size_px,
            pixels_per_point,
        };
        if let Some(picture) = &mut self.drawing.picture {
            if picture.key == key {
                picture.rect = rect;
                return Ok(());
            }
        }
        let started = Instant::now();
        let mut pixmap = tiny_skia::Pixmap::new(size_px[0], size_px[1])
            .ok_or_else(|| format!("cannot draw a {}×{} canvas", size_px[0], size_px[1]))?;
        let zoom = placed.view.zoom * pixels_per_point;
        let pan = placed.view.pan * pixels_per_point;
        let pixmap_from_canvas = tiny_skia::Transform::from_row(zoom, 0.0, 0.0, zoom, pan.x, pan.y);
        let draws = crate::playback::pose_draws(scene, &posed.positions, &pose);
        scene
            .draw_parts(&mut pixmap, &draws, pixmap_from_canvas)
            .map_err(|e| e.to_string())?;
        let drawn = draws
            .iter()
            .map(|d| DrawnPart {
                part: d.part,
                name: scene
                    .doc
                    .parts
                    .get(d.part)
                    .map(|p| p.name.clone())
                    .unwrap_or_default(),
                tint: [d.tint.r, d.tint.g, d.tint.b, d.tint.a],
                visible: d.visible,
            })
            .collect();
        let image = egui::ColorImage::from_rgba_premultiplied(
            [size_px[0] as usize, size_px[1] as usize],
            pixmap.data(),
        );
        let texture = match self.drawing.picture.take() {
            Some(mut old) => {
                old.texture.set(image, egui::TextureOptions::NEAREST);
                old.texture
            }
            None => ctx.load_texture("posed drawing", image, egui::TextureOptions::NEAREST),
        };
        self.drawing.picture = Some(Picture {
            key,
            texture,
            draws: drawn,
            pixmap,
            rect,
            draw_ms: started.elapsed().as_secs_f64() * 1e3,
        });
        Ok(())
    }

    pub(super) fn canvas(&mut self, ui: &mut egui::Ui) {
        if self.mode == Mode::Colorize {
            return self.colorize_canvas(ui);
        }
        let ctx = ui.ctx().clone();
        let textures = self.layer_textures(&ctx);
        let (response, painter) = ui.allocate_painter(ui.available_size(), Sense::click_and_drag());
        let rect = response.rect;
        painter.rect_filled(rect, 0.0, Color32::from_gray(40));
        if self.doc.state().layers.is_empty() {
            drop_hint(ui, rect);
        }
        let canvas_px = self
            .doc
            .state()
            .layers
            .first()
            .map(|l| l.canvas_px)
            .unwrap_or([512, 512]);
        let placed = self.place_canvas(&ctx, &response, canvas_px);
        let posable = self.doc.posable().cloned();
        let live_pose = match &self.gesture {
            Some(Gesture::PoseDrag { pose, .. }) => Some(pose.clone()),
            Some(Gesture::Fk(g)) => Some(g.preview.clone()),
            Some(Gesture::Numbers(pose)) => Some(pose.clone()),
            _ => None,
        };
        let mut shapes = Vec::new();
        let mut posed_handles = None;
        match (self.mode, &posable) {
            (Mode::Pose | Mode::Animate, Some(scene)) => {
                shapes.extend(self.onion_shapes(scene, &placed));
                // The playhead's frame when animate mode shows the animation as it plays, else
                // the pose edited.
                let playhead = self.mode == Mode::Animate
                    && live_pose.is_none()
                    && self.animate.shown.is_none();
                let pose = live_pose.unwrap_or_else(|| self.edited_pose());
                let posed = if playhead {
                    self.update_posed_at_playhead(scene)
                } else {
                    self.update_posed(scene, &pose)
                };
                let drawn = posed.and_then(|()| self.picture(&ctx, scene, rect, &placed));
                if let Err(e) = drawn {
                    self.fail(e);
                }
                if let Some(picture) = &self.drawing.picture {
                    let size = egui::vec2(
                        picture.pixmap.width() as f32,
                        picture.pixmap.height() as f32,
                    ) / ctx.pixels_per_point();
                    shapes.push(egui::Shape::image(
                        picture.texture.id(),
                        Rect::from_min_size(rect.min, size),
                        Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
                        Color32::WHITE,
                    ));
                }
                if let Some(posed) = &self.pose_mode.posed {
                    posed_handles = Some(posed.handles.clone());
                }
                for drag in &pose.ik {
                    let s = placed.screen_from_canvas(drag.to);
                    shapes.push(egui::Shape::circle_filled(s, 4.0, Color32::RED));
                }
            }
            _ => shapes.extend(self.rest_shapes(&placed, &textures, posable.is_some())),
        }
        let mut handles = posed_handles.unwrap_or_else(|| self.doc.state().handles.clone());
        match &self.gesture {
            Some(Gesture::NewBone { head, parent, tail }) => handles.bones.push(Bone {
                name: String::new(),
                parent: parent.clone(),
                head: *head,
                tail: *tail,
            }),
            Some(Gesture::MoveHandle { name, from, to }) => {
                super::rig_mode::move_handle(&mut handles, name, to - from)
            }
            _ => {}
        }
        shapes.extend(self.mesh_shapes(&placed));
        shapes.extend(canvas::handles(&placed, &handles, self.selected.as_deref()));
        shapes.extend(self.polygon_shapes(&placed, response.hover_pos()));
        if let (Mode::Pose | Mode::Animate, Some(scene)) = (self.mode, &posable) {
            if let Some(target) = self.fk_target(scene) {
                let active = match &self.gesture {
                    Some(Gesture::Fk(g)) => Some(g.kind),
                    _ => None,
                };
                shapes.extend(gizmo::shapes(&placed, &target, active));
            }
        }
        self.track_hover(&response, &placed);
        if self.mode == Mode::Rig && self.rig_mode.tool == Tool::Paint {
            shapes.extend(self.brush_shape(&placed));
        }
        painter.extend(shapes);
        match self.mode {
            Mode::Rig => self.rig_gestures(&ctx, &response, placed),
            Mode::Pose | Mode::Animate => {
                if let Some(scene) = posable {
                    self.pose_gestures(&ctx, &response, placed, &scene)
                }
            }
            Mode::Colorize => {}
        }
    }

    /// Places an image of `size_px` on the canvas `response` covers (fitted the first time,
    /// then as zoomed and panned), remembers it for picking and applies this frame's zoom and
    /// pan.
    pub(super) fn place_canvas(
        &mut self,
        ctx: &egui::Context,
        response: &egui::Response,
        size_px: [u32; 2],
    ) -> Placed {
        let rect = response.rect;
        let view = self.place_view(size_px, rect.size());
        let placed = Placed {
            view,
            origin: rect.min,
        };
        self.placed = Some(placed);
        self.zoom_and_pan(ctx, response, placed);
        placed
    }

    pub(super) fn zoom_and_pan(
        &mut self,
        ctx: &egui::Context,
        response: &egui::Response,
        placed: Placed,
    ) {
        if !response.hovered() {
            return;
        }
        let (scroll, pointer) = ctx.input(|i| (i.smooth_scroll_delta().y, i.pointer.hover_pos()));
        if scroll != 0.0 {
            if let (Some(view), Some(at)) = (self.view.as_mut(), pointer) {
                let anchor = placed.canvas_from_screen(at);
                view.zoom = (view.zoom * (scroll / 200.0).exp()).clamp(0.05, 32.0);
                // Keep the canvas point under the pointer where it was.
                let moved = Placed {
                    view: *view,
                    origin: placed.origin,
                }
                .screen_from_canvas(anchor);
                view.pan += at - moved;
            }
        }
        if response.dragged_by(egui::PointerButton::Middle) {
            if let Some(view) = self.view.as_mut() {
                view.pan += response.drag_delta();
            }
        }
    }
}

/// What an empty canvas says: where images come from (brighter while files hover over it).
fn drop_hint(ui: &mut egui::Ui, rect: Rect) {
    let hovering = ui.input(|i| !i.raw.hovered_files.is_empty());
    let color = if hovering {
        Color32::WHITE
    } else {
        Color32::from_gray(150)
    };
    let text = egui::RichText::new(DROP_HINT).size(18.0).color(color);
    ui.put(
        Rect::from_center_size(rect.center(), egui::vec2(rect.width().min(420.0), 60.0)),
        egui::Label::new(text).selectable(false),
    );
}

/// The empty canvas' hint.
pub const DROP_HINT: &str = "Drop PNG images here (or File → Import layer…)";
