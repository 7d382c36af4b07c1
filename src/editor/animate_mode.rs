//! Animate mode: the animation edited, the playhead and its playback, the pose shown at the
//! playhead and the onion skins.
//!
//! In: the document's animation, the playhead, the frame rate (File → Render's). Out: the pose
//! at the playhead, sampled as `sinew render` samples it (its curve evaluation), and posed
//! through the one pose path ([`super::pose_mode::pose_frame`]); the onion skins' outlines of the
//! neighbouring frames. The dopesheet and the curve editor are [`super::timeline`]'s.

use super::identity::Identity;
use super::{canvas, EditorApp, Mode};
use crate::anim::edit::KEY_TIME_TOLERANCE_S;
use crate::anim::{Animation, SampleOptions};
use crate::geom::Point;
use crate::pipeline::Scene;
use crate::rig::Pose;
use crate::skin::Blend;
use eframe::egui::{self, Color32, Shape, Stroke};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Most neighbouring frames an onion skin shows on each side.
pub const MAX_ONION_FRAMES: usize = 8;

/// Posed frames the onion skin keeps; more and the cache starts again.
const ONION_CACHE_FRAMES: usize = 64;

/// Onion skinning: the posed outlines of `frames` frames before (red) and after (green) the
/// playhead, the nearest at `opacity`, fading with distance.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OnionOptions {
    /// Default off.
    pub enabled: bool,
    /// Default 2, at most [`MAX_ONION_FRAMES`].
    pub frames: usize,
    /// Default 0.5.
    pub opacity: f32,
}

impl Default for OnionOptions {
    fn default() -> Self {
        OnionOptions {
            enabled: false,
            frames: 2,
            opacity: 0.5,
        }
    }
}

/// Posed outlines of neighbouring frames, for one rig and one version of the animation.
#[derive(Default)]
struct OnionCache {
    scene: Option<Identity<Scene>>,
    /// The animation's name and JSON, and how its frames are sampled and skinned.
    animation: Option<(String, Animation, SampleOptions, Blend)>,
    /// Boundary edges (vertex pairs) of each part's mesh.
    outlines: Vec<Vec<[u32; 2]>>,
    /// Posed vertex positions by frame time (µs).
    frames: BTreeMap<i64, Vec<Vec<Point>>>,
}

/// Animate mode's own state: the animation edited, the playhead, playback and the onion
/// skins' cache (the dopesheet and curve editor keep theirs in [`super::timeline`]).
pub struct AnimateMode {
    /// The animation edited.
    pub animation: String,
    /// The playhead, s.
    pub time_s: f64,
    pub playing: bool,
    /// The pose edited since the playhead last moved (not yet keyed).
    pub(super) shown: Option<Pose>,
    onion_cache: OnionCache,
    /// Real time played since the last frame step, s.
    play_clock_s: f64,
    /// Whether playback ran last frame (starting again from the end rewinds first).
    was_playing: bool,
}

impl AnimateMode {
    pub fn new(animation: String) -> Self {
        AnimateMode {
            animation,
            time_s: 0.0,
            playing: false,
            shown: None,
            onion_cache: OnionCache::default(),
            play_clock_s: 0.0,
            was_playing: false,
        }
    }
}

/// Edges used by one triangle only: the outline of a mesh (holes included).
fn boundary_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut count: BTreeMap<[u32; 2], u32> = BTreeMap::new();
    for t in triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *count.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    count
        .into_iter()
        .filter(|(_, n)| *n == 1)
        .map(|(e, _)| e)
        .collect()
}

impl EditorApp {
    /// The current animation at the current time (clamped to its keys), sampled as File →
    /// Render's settings sample it.
    pub fn sampled_pose(&self) -> Pose {
        crate::document::animation_named(self.doc.state(), &self.animate.animation).sample_with(
            self.animate.time_s,
            false,
            &self.render_settings.sampling,
        )
    }

    /// Play or pause (the Play button, Space).
    pub(super) fn toggle_playback(&mut self) {
        self.animate.playing = !self.animate.playing;
    }

    /// Keys the edited pose at the playhead (*Set key*): the channels the edit changed and every
    /// channel of the selected handle, as the library's [`crate::document::Command::SetKey`]
    /// decides; says what it did, or why not. A key inside a segment splits its curve, so the
    /// motion around it stays (the library's [`crate::anim::edit::put_key`]).
    pub fn set_key(&mut self) {
        let pose = self.edited_pose();
        let (animation, time_s) = (self.animate.animation.clone(), self.animate.time_s);
        if self.apply(crate::document::Command::SetKey {
            animation: animation.clone(),
            time_s,
            pose,
            keep: self.selected.iter().cloned().collect(),
            sampling: self.render_settings.sampling,
        }) {
            self.animate.shown = None;
            self.message = Some(format!("keyed '{animation}' at {time_s:.3} s"));
        }
    }

    /// Moves the playhead; an edited but unkeyed pose is dropped, as in other animation tools.
    pub fn set_time(&mut self, time_s: f64) {
        self.animate.time_s = time_s.max(0.0);
        self.animate.shown = None;
    }

    /// The current animation's length: its last key, at least [`super::MIN_TIMELINE_S`].
    pub fn timeline_length_s(&self) -> f64 {
        crate::document::animation_named(self.doc.state(), &self.animate.animation)
            .duration_s()
            .max(super::MIN_TIMELINE_S)
    }

    /// Seconds per frame at the frame rate: File → Render's, so playback shows the frames a
    /// render writes (the rig document keeps no frame rate of its own).
    pub(super) fn frame_s(&self) -> f64 {
        1.0 / self
            .render_settings
            .fps
            .clamp(1.0, crate::playback::MAX_FPS)
    }

    /// `time_s` on the nearest frame.
    pub fn snap_to_frame(&self, time_s: f64) -> f64 {
        (time_s / self.frame_s()).round() * self.frame_s()
    }

    /// Where playback ends (and loops): the last key, or the timeline's length when every key
    /// is at 0.
    pub(super) fn play_end_s(&self) -> f64 {
        let end = crate::document::animation_named(self.doc.state(), &self.animate.animation)
            .duration_s();
        if end > KEY_TIME_TOLERANCE_S {
            end
        } else {
            self.timeline_length_s()
        }
    }

    /// Plays frame by frame at the frame rate: the playhead only ever shows frames (as a render
    /// does), stepping as many as the real time elapsed covers. Looping wraps at the last key,
    /// which a cycle's first key repeats, so it is not shown twice; otherwise playback stops on
    /// the last key.
    pub(super) fn advance_playback(&mut self, ctx: &egui::Context) {
        if !self.animate.playing || self.mode != Mode::Animate {
            self.animate.play_clock_s = 0.0;
            self.animate.was_playing = false;
            return;
        }
        ctx.request_repaint();
        let frame_s = self.frame_s();
        let end = self.play_end_s();
        if !self.animate.was_playing {
            self.animate.was_playing = true;
            // Play pressed on the last frame starts over.
            if self.animate.time_s >= end - KEY_TIME_TOLERANCE_S {
                self.set_time(0.0);
                return;
            }
        }
        self.animate.play_clock_s += f64::from(ctx.input(|i| i.stable_dt));
        let steps = (self.animate.play_clock_s / frame_s + 1e-9).floor();
        if steps < 1.0 {
            return;
        }
        self.animate.play_clock_s = (self.animate.play_clock_s - steps * frame_s).max(0.0);
        let mut t = ((self.animate.time_s / frame_s).round() + steps) * frame_s;
        if t >= end - KEY_TIME_TOLERANCE_S {
            if self.timeline.looping {
                t = self.snap_to_frame(t.rem_euclid(end));
                if t >= end - KEY_TIME_TOLERANCE_S {
                    t = 0.0;
                }
            } else {
                t = end;
                self.animate.playing = false;
                self.animate.was_playing = false;
            }
        }
        self.set_time(t);
    }

    /// Onion skins for the canvas: the posed outlines of the frames around the playhead,
    /// earlier ones red, later ones green, fading with distance (empty when off).
    pub(super) fn onion_shapes(
        &mut self,
        scene: &Arc<Scene>,
        placed: &canvas::Placed,
    ) -> Vec<Shape> {
        let options = self.timeline.onion;
        let opacity = options.opacity;
        if !options.enabled || self.mode != Mode::Animate {
            return Vec::new();
        }
        let animation = crate::document::animation_named(self.doc.state(), &self.animate.animation);
        let frame_s = self.frame_s();
        let (sampling, blend) = (self.render_settings.sampling, self.render_settings.blend);
        let cache = &mut self.animate.onion_cache;
        if cache.scene.as_ref().is_none_or(|k| !k.is(scene)) {
            cache.scene = Some(Identity::of(scene));
            cache.outlines = scene
                .doc
                .parts
                .iter()
                .map(|p| boundary_edges(&p.mesh.triangles))
                .collect();
            cache.frames.clear();
        }
        let version = (
            self.animate.animation.clone(),
            animation.clone(),
            sampling,
            blend,
        );
        if cache.animation.as_ref() != Some(&version) {
            cache.animation = Some(version);
            cache.frames.clear();
        }
        if cache.frames.len() > ONION_CACHE_FRAMES {
            cache.frames.clear();
        }
        let now = (self.animate.time_s / frame_s).round() * frame_s;
        let end = animation.duration_s();
        let frames = options.frames.min(MAX_ONION_FRAMES);
        if frames == 0 {
            return Vec::new();
        }
        // The frames around the playhead, as the library plays them (momentum included).
        let times: Vec<(usize, f64, [u8; 3])> = (1..=frames)
            .rev()
            .flat_map(|k| {
                [(-1.0, [255, 90, 90]), (1.0, [90, 230, 120])]
                    .map(|(sign, rgb)| (k, now + sign * k as f64 * frame_s, rgb))
            })
            .filter(|(_, t, _)| *t >= -KEY_TIME_TOLERANCE_S && *t <= end + KEY_TIME_TOLERANCE_S)
            .collect();
        let micros = |t: f64| (t * 1e6).round() as i64;
        let missing: Vec<f64> = times
            .iter()
            .map(|(_, t, _)| t.max(0.0))
            .filter(|&t| !cache.frames.contains_key(&micros(t)))
            .collect();
        let options = crate::scene::PlayOptions {
            sampling,
            looping: false,
        };
        // Frames that cannot be posed are left out; the canvas reports the error.
        if let Ok(played) = crate::scene::frames(scene, &animation, &missing, options) {
            for frame in played {
                if let Ok(positions) =
                    scene.positions_from_transforms(&frame.transforms, &frame.pose, blend)
                {
                    cache.frames.insert(micros(frame.time_s), positions);
                }
            }
        }
        let mut shapes = Vec::new();
        for (k, t, rgb) in times {
            let fade = opacity * (frames + 1 - k) as f32 / frames as f32;
            let Some(positions) = cache.frames.get(&micros(t.max(0.0))) else {
                continue;
            };
            let color =
                Color32::from_rgba_unmultiplied(rgb[0], rgb[1], rgb[2], (fade * 255.0) as u8);
            let stroke = Stroke::new(1.2, color);
            for (edges, part) in cache.outlines.iter().zip(positions) {
                for [a, b] in edges {
                    let (Some(p), Some(q)) = (part.get(*a as usize), part.get(*b as usize)) else {
                        continue;
                    };
                    shapes.push(Shape::line_segment(
                        [placed.screen_from_canvas(*p), placed.screen_from_canvas(*q)],
                        stroke,
                    ));
                }
            }
        }
        shapes
    }
}
