//! An interactive colorization: line art, scribble strokes edited with undo, and the colored
//! result of the current strokes.
//!
//! In: a line-art image, [`ColorizeOptions`], and [`SessionCommand`]s (add a stroke, erase the
//! strokes near a point, clear, recolor, replace them all from a scribble file). Out: the
//! current strokes and, once solved, the [`Colorized`] result for exactly those strokes, saved
//! atomically as a PNG on request; the strokes themselves save and load as the JSON scribble
//! file of `sinew colorize --scribbles`.
//!
//! The line-art-dependent part is prepared once ([`PreparedLineArt`]); a solve rasterizes the
//! strokes and runs the rest of [`super`]'s pipeline. Solving takes longer than a frame on
//! real images, so it is split off like the document's rig builds: [`ColorizeSession::job`]
//! copies out what a solve needs (shared, cheap), [`SolveJob::run`] runs on any thread and can
//! be cancelled, and [`ColorizeSession::set_result`] installs the result only if the strokes
//! are still the ones it was solved for — the newest strokes win.
//!
//! Undo is by snapshot, as in [`crate::document`]: every successful command pushes the state
//! before it (the strokes, shared through an `Arc`, and the result computed for them, so
//! undoing shows the earlier result again without solving).

use super::scribbles::{hex, ScribbleError, Stroke, StrokeFile, MAX_COORDINATE_PX};
use super::{ColorizeError, ColorizeOptions, Colorized, PreparedLineArt, Scribbles};
use crate::geom::segment_distance;
use crate::geom::Point;
use image::RgbaImage;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Undo steps kept, as for the document.
pub const UNDO_LIMIT: usize = crate::document::UNDO_LIMIT;

/// One scribble: a polyline in image px painted with a round brush.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScribbleStroke {
    /// RGB8.
    pub color: [u8; 3],
    /// Brush diameter, image px.
    pub width_px: f64,
    /// The brush's path, image px (pixel (i, j) covers [i, i+1) × [j, j+1)); one point is a
    /// dot.
    pub points_px: Vec<Point>,
}

impl ScribbleStroke {
    /// The stroke in the JSON scribble file's form (`sinew colorize --scribbles`).
    pub fn to_stroke(&self) -> Stroke {
        Stroke {
            color: format!("#{}", hex(self.color)),
            width: self.width_px,
            points: self.points_px.clone(),
        }
    }

    /// A stroke of the JSON scribble file (`#rrggbb` color), as the session keeps it.
    pub fn from_stroke(stroke: &Stroke) -> Result<Self, SessionError> {
        let color = super::scribbles::parse_hex_color(&stroke.color).ok_or_else(|| {
            SessionError::BadStroke(format!(
                "color '{}' is not of the form #rrggbb",
                stroke.color
            ))
        })?;
        Ok(ScribbleStroke {
            color,
            width_px: stroke.width,
            points_px: stroke.points.clone(),
        })
    }

    /// Distance (px) from `at_px` to the painted area: to the path, less the brush radius;
    /// 0 or less on the paint.
    pub fn distance_px(&self, p: Point) -> f64 {
        let to_path = match self.points_px.as_slice() {
            [] => f64::INFINITY,
            [only] => (p - only).norm(),
            points => points
                .windows(2)
                .map(|w| segment_distance(p, w[0], w[1]).0)
                .fold(f64::INFINITY, f64::min),
        };
        to_path - self.width_px / 2.0
    }
}

/// One edit of the strokes.
#[derive(Clone, Debug, PartialEq)]
pub enum SessionCommand {
    /// Adds a stroke on top of the others (later strokes paint over earlier ones).
    AddStroke(ScribbleStroke),
    /// Removes every stroke whose paint passes within `radius_px` of `at_px`.
    EraseNear { at_px: Point, radius_px: f64 },
    /// Removes every stroke.
    Clear,
    /// Gives every stroke of color `from` the color `to` (`to` may be a color already used:
    /// the two regions then become one color).
    Recolor { from: [u8; 3], to: [u8; 3] },
    /// Replaces every stroke with these (a scribble file loaded).
    Replace(Vec<ScribbleStroke>),
}

/// What a session command, solve or save got wrong. The session is unchanged.
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    #[error("the stroke {0}")]
    BadStroke(String),
    #[error("the stroke lies outside the {0}×{1} px image")]
    OffImage(u32, u32),
    #[error("the strokes would use {0} colors, more than the {1} allowed")]
    TooManyColors(usize, usize),
    #[error("no stroke passes within {radius_px} px of ({x:.1}, {y:.1})")]
    NothingToErase { x: f64, y: f64, radius_px: f64 },
    #[error("the erase radius must be a finite number ≥ 0, not {0}")]
    EraseRadius(f64),
    #[error("there are no strokes")]
    NoStrokes,
    #[error("no stroke has the color #{0}")]
    UnknownColor(String),
    #[error("the result was computed for strokes that have changed since")]
    Outdated,
    #[error("there is no colorized result yet: draw scribbles and wait for it")]
    NoResult,
    #[error(transparent)]
    Scribbles(#[from] ScribbleError),
    #[error(transparent)]
    Colorize(#[from] ColorizeError),
    #[error(transparent)]
    Image(#[from] crate::io::ImageError),
    #[error("cannot read {path}: {source}")]
    Read {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    #[error("cannot write {path}: {source}")]
    Write {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
}

/// What one undo step restores.
#[derive(Clone, Debug)]
pub struct SessionState {
    pub strokes: Arc<Vec<ScribbleStroke>>,
    /// The colorization of exactly `strokes`, once solved (`None` also while there are none).
    pub result: Option<Arc<Colorized>>,
}

/// Everything a solve needs, shared with the session (cheap to make, `Send`).
#[derive(Clone, Debug)]
pub struct SolveJob {
    pub lineart: Arc<PreparedLineArt>,
    pub strokes: Arc<Vec<ScribbleStroke>>,
}

impl SolveJob {
    /// Rasterizes the strokes and colorizes. `None` for no strokes (nothing to color).
    pub fn run(&self, cancel: &AtomicBool) -> Result<Option<Colorized>, SessionError> {
        if self.strokes.is_empty() {
            return Ok(None);
        }
        let strokes: Vec<Stroke> = self.strokes.iter().map(|s| s.to_stroke()).collect();
        let (w, h) = self.lineart.image.dimensions();
        let scribbles = Scribbles::from_strokes(&strokes, w, h, &self.lineart.options.scribbles)?;
        Ok(Some(self.lineart.colorize(&scribbles, false, cancel)?))
    }
}

/// The session: prepared line art, current state, undo history.
pub struct ColorizeSession {
    lineart: Arc<PreparedLineArt>,
    state: SessionState,
    undo: Vec<SessionState>,
    redo: Vec<SessionState>,
}

impl ColorizeSession {
    /// A session over `lineart` with no strokes. Fails on bad options or an image too small
    /// to mesh (under 2×2 px).
    pub fn new(lineart: RgbaImage, options: ColorizeOptions) -> Result<Self, SessionError> {
        let (w, h) = lineart.dimensions();
        if w < 2 || h < 2 {
            return Err(
                ColorizeError::Mesh(super::image_mesh::ImageMeshError::TooSmall(w, h)).into(),
            );
        }
        Ok(ColorizeSession {
            lineart: Arc::new(PreparedLineArt::new(lineart, options)?),
            state: SessionState {
                strokes: Arc::new(Vec::new()),
                result: None,
            },
            undo: Vec::new(),
            redo: Vec::new(),
        })
    }

    pub fn lineart(&self) -> &RgbaImage {
        &self.lineart.image
    }

    /// The options the session colorizes with.
    pub fn options(&self) -> &ColorizeOptions {
        &self.lineart.options
    }

    /// Colorizes with `options` from now on (the line art prepared again only when its
    /// preparation changes, [`PreparedLineArt::with_options`]). The strokes and their undo
    /// history stay; every result kept, current or in the history, is dropped (it was solved
    /// with the old options), so the next [`ColorizeSession::job`] solves again. On error (bad
    /// options) nothing changes.
    pub fn set_options(&mut self, options: ColorizeOptions) -> Result<(), SessionError> {
        if options == self.lineart.options {
            return Ok(());
        }
        self.lineart = Arc::new(self.lineart.with_options(options)?);
        for state in std::iter::once(&mut self.state)
            .chain(&mut self.undo)
            .chain(&mut self.redo)
        {
            state.result = None;
        }
        Ok(())
    }

    /// Image size, px.
    pub fn size_px(&self) -> [u32; 2] {
        [self.lineart.image.width(), self.lineart.image.height()]
    }

    pub fn state(&self) -> &SessionState {
        &self.state
    }

    pub fn strokes(&self) -> &[ScribbleStroke] {
        &self.state.strokes
    }

    /// The colorization of the current strokes, if it has been solved.
    pub fn result(&self) -> Option<&Arc<Colorized>> {
        self.state.result.as_ref()
    }

    /// The colors in use, in order of first use.
    pub fn palette(&self) -> Vec<[u8; 3]> {
        palette_of(&self.state.strokes)
    }

    /// The strokes as a JSON scribble file (`sinew colorize --scribbles`).
    pub fn stroke_file(&self) -> StrokeFile {
        StrokeFile {
            strokes: self.state.strokes.iter().map(|s| s.to_stroke()).collect(),
        }
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Applies `command`; on error nothing changes.
    pub fn apply(&mut self, command: SessionCommand) -> Result<(), SessionError> {
        let strokes = self.apply_to(command)?;
        let previous = std::mem::replace(
            &mut self.state,
            SessionState {
                strokes: Arc::new(strokes),
                result: None,
            },
        );
        self.undo.push(previous);
        if self.undo.len() > UNDO_LIMIT {
            self.undo.remove(0);
        }
        self.redo.clear();
        Ok(())
    }

    /// Steps back one command; false when there is nothing to undo.
    pub fn undo(&mut self) -> bool {
        swap_in(&mut self.state, &mut self.undo, &mut self.redo)
    }

    /// Re-applies the last undone command; false when there is nothing to redo.
    pub fn redo(&mut self) -> bool {
        swap_in(&mut self.state, &mut self.redo, &mut self.undo)
    }

    /// What a solve of the current strokes needs, for [`SolveJob::run`] on another thread.
    pub fn job(&self) -> SolveJob {
        SolveJob {
            lineart: self.lineart.clone(),
            strokes: self.state.strokes.clone(),
        }
    }

    /// Installs the result of a solve of `strokes`; refused ([`SessionError::Outdated`]) when
    /// the current strokes are others.
    pub fn set_result(
        &mut self,
        strokes: &[ScribbleStroke],
        result: Option<Arc<Colorized>>,
    ) -> Result<(), SessionError> {
        if strokes != self.state.strokes.as_slice() {
            return Err(SessionError::Outdated);
        }
        self.state.result = result;
        Ok(())
    }

    /// Solves the current strokes here and now (tests, scripts; the editor solves on a thread).
    pub fn solve(&mut self) -> Result<(), SessionError> {
        let job = self.job();
        let result = job.run(&AtomicBool::new(false))?;
        self.set_result(&job.strokes, result.map(Arc::new))
    }

    /// Writes the colorized image (line art on top) to `path` as a PNG, atomically.
    pub fn save_result(&self, path: &Path) -> Result<(), SessionError> {
        let result = self.state.result.as_ref().ok_or(SessionError::NoResult)?;
        crate::io::save_png(path, &result.image)?;
        Ok(())
    }

    /// Writes the strokes to `path` as a JSON scribble file (`sinew colorize --scribbles`),
    /// atomically. Refused ([`SessionError::NoStrokes`]) when there are none.
    pub fn save_strokes(&self, path: &Path) -> Result<(), SessionError> {
        if self.state.strokes.is_empty() {
            return Err(SessionError::NoStrokes);
        }
        self.write_strokes(path)
    }

    /// [`ColorizeSession::save_strokes`], an empty file too (an autosave mirrors the strokes
    /// as they are, none included).
    pub fn write_strokes(&self, path: &Path) -> Result<(), SessionError> {
        let write = |source| SessionError::Write {
            path: path.to_path_buf(),
            source,
        };
        let text = serde_json::to_string_pretty(&self.stroke_file())
            .map_err(|e| write(std::io::Error::other(e)))?;
        crate::io::write_atomic(path, text.as_bytes()).map_err(write)
    }

    /// Replaces the strokes with those of the JSON scribble file at `path`, as one undo step;
    /// returns how many there are. On error nothing changes.
    pub fn load_strokes(&mut self, path: &Path) -> Result<usize, SessionError> {
        let text = std::fs::read_to_string(path).map_err(|source| SessionError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let strokes = strokes_from_json(&text)?;
        let count = strokes.len();
        self.apply(SessionCommand::Replace(strokes))?;
        Ok(count)
    }

    /// The strokes after `command`, or why it cannot apply.
    fn apply_to(&self, command: SessionCommand) -> Result<Vec<ScribbleStroke>, SessionError> {
        let mut strokes = self.state.strokes.as_ref().clone();
        match command {
            SessionCommand::AddStroke(stroke) => {
                self.check_stroke(&stroke)?;
                strokes.push(stroke);
            }
            SessionCommand::EraseNear { at_px, radius_px } => {
                if !(radius_px.is_finite() && radius_px >= 0.0) {
                    return Err(SessionError::EraseRadius(radius_px));
                }
                let before = strokes.len();
                strokes.retain(|s| s.distance_px(at_px) > radius_px);
                if strokes.len() == before {
                    return Err(SessionError::NothingToErase {
                        x: at_px[0],
                        y: at_px[1],
                        radius_px,
                    });
                }
            }
            SessionCommand::Clear => {
                if strokes.is_empty() {
                    return Err(SessionError::NoStrokes);
                }
                strokes.clear();
            }
            SessionCommand::Recolor { from, to } => {
                let mut found = false;
                for s in strokes.iter_mut().filter(|s| s.color == from) {
                    s.color = to;
                    found = true;
                }
                if !found {
                    return Err(SessionError::UnknownColor(hex(from)));
                }
            }
            SessionCommand::Replace(new) => {
                for stroke in &new {
                    self.check_stroke(stroke)?;
                }
                strokes = new;
            }
        }
        let colors = palette_of(&strokes).len();
        let allowed = self.lineart.options.scribbles.max_colors;
        if colors > allowed {
            return Err(SessionError::TooManyColors(colors, allowed));
        }
        Ok(strokes)
    }

    /// A stroke the rasterizer takes and that touches the image.
    fn check_stroke(&self, stroke: &ScribbleStroke) -> Result<(), SessionError> {
        let bad = |what: &str| Err(SessionError::BadStroke(what.into()));
        if !(stroke.width_px.is_finite() && stroke.width_px > 0.0) {
            return bad("width must be a positive number of px");
        }
        if stroke.points_px.is_empty() {
            return bad("has no points");
        }
        let limit = MAX_COORDINATE_PX;
        if stroke.width_px > limit
            || stroke
                .points_px
                .iter()
                .flat_map(|p| p.iter())
                .any(|c| !c.is_finite() || c.abs() > limit)
        {
            return bad("has a coordinate or width that is not a number within ±1e6 px");
        }
        // Its bounding box, grown by the brush radius, must overlap the image.
        let r = stroke.width_px / 2.0;
        let [w, h] = self.size_px().map(f64::from);
        let lo = |k: usize| {
            stroke
                .points_px
                .iter()
                .map(|p| p[k])
                .fold(f64::INFINITY, f64::min)
        };
        let hi = |k: usize| {
            stroke
                .points_px
                .iter()
                .map(|p| p[k])
                .fold(f64::NEG_INFINITY, f64::max)
        };
        if hi(0) + r < 0.0 || hi(1) + r < 0.0 || lo(0) - r > w || lo(1) - r > h {
            let [w, h] = self.size_px();
            return Err(SessionError::OffImage(w, h));
        }
        Ok(())
    }
}

/// The strokes of a JSON scribble file's text, as a session keeps them.
pub fn strokes_from_json(text: &str) -> Result<Vec<ScribbleStroke>, SessionError> {
    let file: StrokeFile =
        serde_json::from_str(text).map_err(|e| ScribbleError::Json(e.to_string()))?;
    file.strokes
        .iter()
        .map(ScribbleStroke::from_stroke)
        .collect()
}

/// Distinct stroke colors in order of first use.
fn palette_of(strokes: &[ScribbleStroke]) -> Vec<[u8; 3]> {
    let mut colors: Vec<[u8; 3]> = Vec::new();
    for s in strokes {
        if !colors.contains(&s.color) {
            colors.push(s.color);
        }
    }
    colors
}

/// Makes the last state of `from` current, pushing the current one onto `to`.
fn swap_in(
    state: &mut SessionState,
    from: &mut Vec<SessionState>,
    to: &mut Vec<SessionState>,
) -> bool {
    match from.pop() {
        Some(other) => {
            to.push(std::mem::replace(state, other));
            true
        }
        None => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colorize::synthetic::{scene, SceneSpec, PALETTE};

    /// One circle on white paper (128 px): the background's and the circle's true colors, and
    /// strokes in the top margin (background) and across the circle's center.
    fn circle() -> (
        crate::colorize::synthetic::Scene,
        ScribbleStroke,
        ScribbleStroke,
    ) {
        let s = scene(&SceneSpec {
            size: 128,
            shapes: 1,
            ..Default::default()
        });
        let stroke = |k: usize, color: [u8; 3]| ScribbleStroke {
            color,
            width_px: s.strokes[k].width,
            points_px: s.strokes[k].points.clone(),
        };
        let background = stroke(0, PALETTE[10]);
        let inside = stroke(1, PALETTE[0]);
        (s, background, inside)
    }

    fn session(s: &crate::colorize::synthetic::Scene) -> ColorizeSession {
        ColorizeSession::new(s.lineart.clone(), ColorizeOptions::default()).unwrap()
    }

    /// Fraction of non-line pixels where `pick(truth color)` says the result should be
    /// `want` and it is.
    fn share(
        s: &crate::colorize::synthetic::Scene,
        image: &RgbaImage,
        region: [u8; 3],
        want: [u8; 3],
    ) -> f64 {
        let (mut n, mut good) = (0, 0);
        for (i, (t, p)) in s.truth.pixels().zip(image.pixels()).enumerate() {
            if s.is_line[i] || [t[0], t[1], t[2]] != region {
                continue;
            }
            n += 1;
            good += ([p[0], p[1], p[2]] == want) as usize;
        }
        good as f64 / n.max(1) as f64
    }

    #[test]
    fn new_options_drop_every_result_and_solve_as_the_one_shot_colorize() {
        // Two background colors and no line between them: the split decides where they meet.
        let s = scene(&SceneSpec {
            size: 96,
            split_background: true,
            ..Default::default()
        });
        let mut session = session(&s);
        for (k, stroke) in s.strokes.iter().enumerate() {
            session
                .apply(SessionCommand::AddStroke(ScribbleStroke {
                    color: PALETTE[k],
                    width_px: stroke.width,
                    points_px: stroke.points.clone(),
                }))
                .unwrap();
            session.solve().unwrap();
        }
        let reach = session.result().unwrap().image.clone();
        let strokes: Vec<Stroke> = session.strokes().iter().map(|s| s.to_stroke()).collect();
        let one_shot = |options: &ColorizeOptions| {
            let scribbles = Scribbles::from_strokes(&strokes, 96, 96, &options.scribbles).unwrap();
            super::super::colorize(&s.lineart, &scribbles, options, false)
                .unwrap()
                .image
        };
        assert_eq!(reach, one_shot(&ColorizeOptions::default()));
        // A new split (the preparation kept) and a new split depth (prepared anew).
        for options in [
            ColorizeOptions {
                split: super::super::RegionSplit::Depth,
                ..Default::default()
            },
            ColorizeOptions {
                split: super::super::RegionSplit::Depth,
                split_depth_px: 3.0,
                ..Default::default()
            },
        ] {
            session.set_options(options.clone()).unwrap();
            assert_eq!(session.options(), &options);
            assert!(session.result().is_none());
            assert!(session.undo());
            assert!(session.result().is_none(), "an undo step kept its result");
            assert!(session.redo());
            session.solve().unwrap();
            let image = &session.result().unwrap().image;
            assert_eq!(image, &one_shot(&options));
            assert_ne!(image, &reach);
        }
        // Bad options: refused, nothing changes.
        let kept = session.result().cloned();
        let bad = ColorizeOptions {
            split_depth_exponent: -1.0,
            ..Default::default()
        };
        assert!(session.set_options(bad).is_err());
        assert_eq!(session.options().split_depth_px, 3.0);
        assert_eq!(session.result().cloned(), kept);
    }

    #[test]
    fn add_erase_clear_recolor_undo_redo() {
        let (s, background, inside) = circle();
        let mut session = session(&s);
        assert!(!session.can_undo());
        session
            .apply(SessionCommand::AddStroke(background.clone()))
            .unwrap();
        session
            .apply(SessionCommand::AddStroke(inside.clone()))
            .unwrap();
        assert_eq!(session.strokes(), &[background.clone(), inside.clone()]);
        assert_eq!(session.palette(), vec![PALETTE[10], PALETTE[0]]);
        // Erasing at the circle's stroke removes it, and only it.
        let c = inside.points_px[0];
        session
            .apply(SessionCommand::EraseNear {
                at_px: Point::new(c[0] + 1.0, c[1] + 0.5),
                radius_px: 1.0,
            })
            .unwrap();
        assert_eq!(session.strokes(), std::slice::from_ref(&background));
        // Nowhere near a stroke: refused, nothing changes.
        assert!(matches!(
            session.apply(SessionCommand::EraseNear {
                at_px: Point::new(64.0, 100.0),
                radius_px: 2.0
            }),
            Err(SessionError::NothingToErase { .. })
        ));
        assert!(session.undo());
        assert_eq!(session.strokes().len(), 2);
        assert!(session.redo());
        assert_eq!(session.strokes().len(), 1);
        assert!(session.undo());
        session
            .apply(SessionCommand::Recolor {
                from: PALETTE[0],
                to: PALETTE[3],
            })
            .unwrap();
        assert_eq!(session.strokes()[1].color, PALETTE[3]);
        assert!(!session.can_redo(), "a new command drops the redo steps");
        assert!(matches!(
            session.apply(SessionCommand::Recolor {
                from: PALETTE[0],
                to: PALETTE[3]
            }),
            Err(SessionError::UnknownColor(_))
        ));
        session.apply(SessionCommand::Clear).unwrap();
        assert!(session.strokes().is_empty());
        assert!(matches!(
            session.apply(SessionCommand::Clear),
            Err(SessionError::NoStrokes)
        ));
        assert!(session.undo());
        assert_eq!(session.strokes().len(), 2);
    }

    #[test]
    fn bad_strokes_are_refused() {
        let (s, background, _) = circle();
        let mut session = session(&s);
        let with = |f: &dyn Fn(&mut ScribbleStroke)| {
            let mut b = background.clone();
            f(&mut b);
            SessionCommand::AddStroke(b)
        };
        for command in [
            with(&|b| b.width_px = 0.0),
            with(&|b| b.width_px = f64::NAN),
            with(&|b| b.points_px.clear()),
            with(&|b| b.points_px[0][1] = f64::INFINITY),
            with(&|b| b.points_px = vec![Point::new(-50.0, 10.0), Point::new(-20.0, 10.0)]),
            with(&|b| b.points_px = vec![Point::new(10.0, 500.0)]),
        ] {
            let e = session.apply(command.clone()).unwrap_err();
            assert!(
                matches!(e, SessionError::BadStroke(_) | SessionError::OffImage(..)),
                "{command:?}: {e}"
            );
        }
        assert!(session.strokes().is_empty() && !session.can_undo());
        // A stroke overhanging the border is fine.
        session
            .apply(with(&|b| {
                b.points_px = vec![Point::new(-1.0, 5.0), Point::new(20.0, 5.0)]
            }))
            .unwrap();
        // Too many colors.
        let mut few = ColorizeOptions::default();
        few.scribbles.max_colors = 1;
        let mut session = ColorizeSession::new(s.lineart.clone(), few).unwrap();
        session.apply(with(&|_| ())).unwrap();
        assert!(matches!(
            session.apply(with(&|b| b.color = [1, 2, 3])),
            Err(SessionError::TooManyColors(2, 1))
        ));
        assert!(ColorizeSession::new(RgbaImage::new(1, 8), ColorizeOptions::default()).is_err());
    }

    #[test]
    fn a_stroke_colors_its_region_and_undo_brings_the_result_back() {
        let (s, background, inside) = circle();
        let mut session = session(&s);
        session.solve().unwrap();
        assert!(session.result().is_none(), "no strokes, nothing to color");
        session
            .apply(SessionCommand::AddStroke(background.clone()))
            .unwrap();
        session.solve().unwrap();
        let one = session.result().unwrap().clone();
        // One color takes everything, the circle too.
        assert_eq!(share(&s, &one.image, PALETTE[0], PALETTE[10]), 1.0);
        session
            .apply(SessionCommand::AddStroke(inside.clone()))
            .unwrap();
        assert!(session.result().is_none(), "a new stroke needs a new solve");
        session.solve().unwrap();
        let two = session.result().unwrap().clone();
        assert!(share(&s, &two.image, PALETTE[0], PALETTE[0]) > 0.99);
        assert!(share(&s, &two.image, PALETTE[10], PALETTE[10]) > 0.99);
        // What changed lies inside the circle (or on its outline), hardly anywhere else.
        let (mut changed, mut outside) = (0, 0);
        for (i, (a, b)) in one.image.pixels().zip(two.image.pixels()).enumerate() {
            if a != b && !s.is_line[i] {
                changed += 1;
                outside += (s.truth.as_raw()[4 * i..4 * i + 3] != PALETTE[0]) as usize;
            }
        }
        assert!(changed > 1000, "{changed}");
        assert!(
            outside * 100 <= changed,
            "{outside} of {changed} outside the circle"
        );
        // Undo shows the earlier result without solving.
        assert!(session.undo());
        assert!(Arc::ptr_eq(session.result().unwrap(), &one));
        assert!(session.redo());
        assert!(Arc::ptr_eq(session.result().unwrap(), &two));
        // The same as the one-shot pipeline on the same strokes, and deterministic.
        let file = session.stroke_file();
        let scribbles =
            Scribbles::from_strokes(&file.strokes, 128, 128, &Default::default()).unwrap();
        let direct =
            crate::colorize::colorize(&s.lineart, &scribbles, &Default::default(), false).unwrap();
        assert_eq!(direct.image, two.image);
        let mut again = self::session(&s);
        again.apply(SessionCommand::AddStroke(background)).unwrap();
        again.apply(SessionCommand::AddStroke(inside)).unwrap();
        again.solve().unwrap();
        assert_eq!(again.result().unwrap().image, two.image);
    }

    #[test]
    fn stale_results_are_refused_and_cancel_stops_a_solve() {
        let (s, background, inside) = circle();
        let mut session = session(&s);
        session
            .apply(SessionCommand::AddStroke(background))
            .unwrap();
        let job = session.job();
        session.apply(SessionCommand::AddStroke(inside)).unwrap();
        let result = job.run(&AtomicBool::new(false)).unwrap();
        assert!(matches!(
            session.set_result(&job.strokes, result.map(Arc::new)),
            Err(SessionError::Outdated)
        ));
        assert!(session.result().is_none());
        assert!(matches!(
            session.job().run(&AtomicBool::new(true)),
            Err(SessionError::Colorize(ColorizeError::Cancelled))
        ));
    }

    #[test]
    fn strokes_save_and_load_as_a_scribble_file_with_one_undo_step() {
        let (s, background, inside) = circle();
        let mut session = session(&s);
        let tmp = crate::test_scratch::scratch("strokes");
        let dir = tmp.path();
        let path = dir.join("lineart.scribbles.json");
        assert!(matches!(
            session.save_strokes(&path),
            Err(SessionError::NoStrokes)
        ));
        assert!(!path.exists());
        session
            .apply(SessionCommand::Replace(vec![
                background.clone(),
                inside.clone(),
            ]))
            .unwrap();
        session.save_strokes(&path).unwrap();
        // The file is what `sinew colorize --scribbles` reads.
        let text = std::fs::read_to_string(&path).unwrap();
        let rasterized = Scribbles::from_json(&text, 128, 128, &Default::default()).unwrap();
        assert_eq!(rasterized.colors, vec![PALETTE[10], PALETTE[0]]);

        let mut other = super::tests::session(&s);
        other
            .apply(SessionCommand::AddStroke(inside.clone()))
            .unwrap();
        assert_eq!(other.load_strokes(&path).unwrap(), 2);
        assert_eq!(other.strokes(), &[background, inside.clone()]);
        assert!(other.undo());
        assert_eq!(other.strokes(), std::slice::from_ref(&inside));

        // A file that is not a scribble file, or is missing, changes nothing.
        let bad = dir.join("bad.json");
        std::fs::write(&bad, "{\"strokes\": [{\"color\": \"red\"}]}").unwrap();
        assert!(matches!(
            other.load_strokes(&bad),
            Err(SessionError::Scribbles(ScribbleError::Json(_)))
        ));
        assert!(matches!(
            other.load_strokes(&dir.join("missing.json")),
            Err(SessionError::Read { .. })
        ));
        let off_image = dir.join("off.json");
        std::fs::write(
            &off_image,
            r##"{"strokes": [{"color": "#ff0000", "width": 3, "points": [[900, 900]]}]}"##,
        )
        .unwrap();
        assert!(other.load_strokes(&off_image).is_err());
        assert_eq!(other.strokes(), &[inside]);
    }

    #[test]
    fn saves_the_result_atomically_and_only_once_solved() {
        let (s, background, _) = circle();
        let mut session = session(&s);
        let tmp = crate::test_scratch::scratch("session");
        let dir = tmp.path();
        let path = dir.join("colored.png");
        session
            .apply(SessionCommand::AddStroke(background))
            .unwrap();
        assert!(matches!(
            session.save_result(&path),
            Err(SessionError::NoResult)
        ));
        assert!(!path.exists());
        session.solve().unwrap();
        session.save_result(&path).unwrap();
        assert_eq!(
            crate::io::load_png(&path).unwrap(),
            session.result().unwrap().image
        );
    }
}
