//! An animation rendered as the writers pull it: the frames of `sinew render`, of the
//! editor's File → Render and of a batch's render job, in bounded memory.
//!
//! In: a [`Scene`], an [`Animation`] and its name, [`RenderSettings`]. Out: an
//! [`AnimationFrames`], the [`FrameSource`] of its frames at [`frame_times`]: each chunk posed
//! by the one pose path ([`crate::scene::Playhead`], or the export as Spine's runtime plays it)
//! and drawn by the one draw ([`render_frames`]); and [`write_animation`], which writes them
//! with the animation's events to a frame folder, a GIF or a sprite sheet, as many frames at
//! once as the memory budget allows ([`crate::budget`]; the output does not depend on it).

use super::{
    frame_times, render_events, render_frames, BakedRuntime, FrameView, RenderAnimationError,
    RenderSettings,
};
use crate::anim::{Animation, CurveEvaluation, SampleOptions};
use crate::export::spine::played::{AsPlayed, ExportPlayed};
use crate::io::sequence::{self, FrameSource, SequenceError, SequenceOptions, SequenceReport};
use crate::pipeline::Scene;
use crate::scene::{Frame, PlayOptions, Playhead};
use image::RgbaImage;
use std::borrow::Cow;
use std::ops::Range;
use std::path::Path;
use std::sync::Mutex;

/// The frames of an animation at [`frame_times`], drawn when a writer asks for them.
pub struct AnimationFrames<'a> {
    scene: &'a Scene,
    times_s: Vec<f64>,
    settings: &'a RenderSettings,
    view: FrameView,
    player: Player<'a>,
    on_frame: &'a (dyn Fn() + Sync),
}

/// How frames are posed: exactly (a playhead kept across calls, so momentum is simulated
/// once forward), or as Spine's runtime plays the default export (its curve evaluation, and
/// the baked keys interpolated as it does).
pub(super) enum Player<'a> {
    Exact(Box<Mutex<Playhead<'a>>>),
    Runtime {
        played: Box<AsPlayed>,
        looping: bool,
    },
    /// A runtime that interpolates an export's baked keys (DragonBones, glTF).
    Baked {
        at: BakedAt,
        duration_s: f64,
        looping: bool,
    },
}

/// The pose a baked runtime shows at a time: handle transforms and the pose's slot state.
type BakedAt = Box<dyn Fn(f64) -> (Vec<crate::rig::Affine>, crate::rig::Pose) + Send + Sync>;

impl<'a> Player<'a> {
    /// A player of `animation` (named `name`) on `scene`; `looping`: times past the end wrap.
    pub(super) fn new(
        scene: &'a Scene,
        name: &str,
        animation: &'a Animation,
        sampling: &SampleOptions,
        export: &ExportPlayed,
        baked_runtime: Option<BakedRuntime>,
        looping: bool,
    ) -> Result<Self, RenderAnimationError> {
        let duration_s = animation.duration_s();
        match baked_runtime {
            Some(BakedRuntime::Gltf) => {
                let played = crate::export::gltf::playback(
                    scene,
                    name,
                    animation,
                    &crate::export::gltf::GltfOptions::default(),
                )?;
                return Ok(Player::Baked {
                    at: Box::new(move |t| played.at(t)),
                    duration_s,
                    looping,
                });
            }
            Some(BakedRuntime::Dragonbones) => {
                let played = crate::export::dragonbones::playback(
                    scene,
                    name,
                    animation,
                    &crate::export::dragonbones::DragonBonesOptions::default(),
                )?;
                return Ok(Player::Baked {
                    at: Box::new(move |t| played.at(t)),
                    duration_s,
                    looping,
                });
            }
            None => {}
        }
        Ok(match sampling.curves {
            CurveEvaluation::Exact => {
                let options = PlayOptions {
                    sampling: *sampling,
                    looping,
                };
                Player::Exact(Box::new(Mutex::new(Playhead::new(
                    scene, animation, options,
                ))))
            }
            CurveEvaluation::SpineRuntime => Player::Runtime {
                played: Box::new(crate::export::spine::played::as_played(
                    scene,
                    name,
                    animation,
                    &export.options(),
                )?),
                looping,
            },
        })
    }

    /// The posed frames at `times_s`.
    pub(super) fn frames(&self, times_s: &[f64]) -> Result<Vec<Frame>, RenderAnimationError> {
        match self {
            Player::Exact(head) => {
                // A poisoned lock only means another call's posing panicked; the playhead
                // itself restarts its simulation when asked for an earlier time.
                let mut head = head.lock().unwrap_or_else(|e| e.into_inner());
                Ok(head.frames(times_s)?)
            }
            Player::Runtime { played, looping } => Ok(times_s
                .iter()
                .map(|&t| played.frame(t, *looping))
                .collect::<Result<_, _>>()?),
            Player::Baked {
                at,
                duration_s,
                looping,
            } => Ok(times_s
                .iter()
                .map(|&time_s| {
                    let (transforms, pose) = at(crate::anim::sample::local_time_s(
                        *duration_s,
                        time_s,
                        *looping,
                    ));
                    Frame {
                        time_s,
                        pose,
                        transforms,
                    }
                })
                .collect()),
        }
    }
}

impl<'a> AnimationFrames<'a> {
    /// The frames of `animation` (named `name`) on `scene` as `settings` say; `on_frame` is
    /// called once per frame drawn (progress). Fails on bad settings before drawing anything.
    pub fn new(
        scene: &'a Scene,
        name: &str,
        animation: &'a Animation,
        settings: &'a RenderSettings,
        on_frame: &'a (dyn Fn() + Sync),
    ) -> Result<Self, RenderAnimationError> {
        let view = settings.view(scene.doc.canvas)?;
        let times_s = frame_times(animation.duration_s(), settings.fps)?;
        let player = Player::new(
            scene,
            name,
            animation,
            &settings.sampling,
            &settings.export,
            settings.baked_runtime,
            true,
        )?;
        Ok(AnimationFrames {
            scene,
            times_s,
            settings,
            view,
            player,
            on_frame,
        })
    }

    /// The frame times, s.
    pub fn times_s(&self) -> &[f64] {
        &self.times_s
    }

    /// Frames `range`, drawn.
    pub fn render(&self, range: Range<usize>) -> Result<Vec<RgbaImage>, RenderAnimationError> {
        let frames = self.player.frames(&self.times_s[range])?;
        Ok(render_frames(
            self.scene,
            &frames,
            self.settings.blend,
            &self.view,
            self.on_frame,
        )?)
    }
}

impl FrameSource for AnimationFrames<'_> {
    fn frame_count(&self) -> usize {
        self.times_s.len()
    }

    fn frame_size_px(&self) -> (u32, u32) {
        (self.view.size_px[0], self.view.size_px[1])
    }

    fn draw_bytes_per_thread(&self) -> u64 {
        crate::budget::px_bytes(self.frame_size_px(), crate::budget::DRAW_BYTES_PER_PX)
    }

    fn draw(&self, range: Range<usize>) -> Result<Vec<Cow<'_, RgbaImage>>, SequenceError> {
        self.render(range)
            .map(|images| images.into_iter().map(Cow::Owned).collect())
            .map_err(|e| SequenceError::Draw(e.to_string()))
    }
}

/// Renders `animation` (named `name`) as `settings` say to `output` — a frame folder, a `.gif`
/// or a `.png` sprite sheet with its JSON (events included) — drawing and writing a chunk of
/// frames at a time. Returns what was written and the events of each frame.
pub fn write_animation(
    scene: &Scene,
    name: &str,
    animation: &Animation,
    settings: &RenderSettings,
    output: &Path,
    options: &SequenceOptions,
    on_frame: &(dyn Fn() + Sync),
) -> Result<(SequenceReport, Vec<Vec<crate::anim::FiredEvent>>), RenderAnimationError> {
    let frames = AnimationFrames::new(scene, name, animation, settings, on_frame)?;
    let events = render_events(scene, animation, settings)?;
    let report = sequence::write_sequence(&frames, &events, settings.fps, output, options)?;
    Ok((report, events))
}
