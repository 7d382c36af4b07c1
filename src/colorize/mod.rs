//! Scribble colorization: line art + a few colored scribbles → a colored drawing.
//!
//! In: the line art (RGBA8: lines on white or on transparency), [`Scribbles`] of the same size
//! (a label per pixel, a palette) and [`ColorizeOptions`]. Out: [`Colorized`]: the colored
//! image (line art on top), the fill alone, and optionally one mask layer per color.
//!
//! The fill respects the ink:
//!
//! 1. [`lineart`]: the drawing composited over white paper, and its ink per pixel.
//! 2. [`scribbles`]: scribble pixels per color (layer or lyon-tessellated polylines); those
//!    lying on a line are dropped (a line belongs to no region).
//! 3. [`gap_closing`]: every line casts a fading ridge of ink, so small gaps close.
//! 4. [`ink_regions`]: the regions the closed lines enclose. A region holding scribbles of one
//!    color takes it, exactly. A region holding several is split by [`RegionSplit`]: scaled
//!    geodesic reach ([`reach_split`], the default: colors meet at necks, each scribble
//!    reaching in proportion to its size), a depth flood (boundaries where the region is
//!    narrowest), an ink-density flood ([`density_split`],
//!    G'MIC Smart Coloring's order: where ink crowds), or the content-aware weights
//!    (Jacobson, Baran, Popović & Sorkine 2011; Jacobson's thesis 2013 § 3.4 shows this very
//!    application): [`image_mesh`] (an adaptive mesh, one vertex per pixel along lines and
//!    scribble rims) lifted to (x, y, s·r, s·g, s·b) by [`crate::weights::lift`], one
//!    harmonic (or bounded biharmonic) weight function per color ([`weights`]), each pixel
//!    taking the largest among its region's colors. Lines, ridges and unscribbled regions
//!    are reached by a watershed over the ink: colors meet on crests.
//! 5. [`fill`]: flat (each pixel its color) or soft (antialiased region edges); the line
//!    art on top.
//!
//! [`PreparedLineArt`] keeps steps 1, 3 and the regions of 4 (the line art alone) for repeated
//! colorizations of one drawing; [`session`] is the interactive editing of scribble strokes over it, with undo.
//!
//! [`flood`] is the paint-bucket baseline and [`score`] the measure the tests use;
//! [`synthetic`] draws test line art with known true colorings.

pub mod chamfer;
pub mod components;
pub mod density_split;
pub mod end_point_join;
pub mod fill;
pub mod flood;
pub mod gap_closing;
pub mod image_mesh;
pub mod ink_regions;
pub mod lineart;
pub mod reach_split;
pub mod score;
pub mod scribbles;
pub mod session;
pub mod synthetic;
pub mod weights;

pub use end_point_join::EndPointJoinOptions;
pub use fill::FillMode;
pub use image_mesh::{ImageMesh, MeshOptions};
pub use ink_regions::{InkRegions, RegionSplit};
pub use lineart::LineArt;
pub use scribbles::{ScribbleError, ScribbleOptions, Scribbles};
pub use weights::{ColorWeights, LiftedStiffness};

use crate::weights::BbwOptions;
use image::RgbaImage;
use reach_split::ReachSites;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;

/// How to colorize. Every field has a documented default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ColorizeOptions {
    /// Lift scale s: a full change of one color channel counts as s px. Large enough that
    /// crossing a line costs more than going around inside a region, small enough to keep
    /// the stiffness matrix well conditioned. Default [`DEFAULT_LIFT_SCALE`].
    pub scale: f64,
    /// A pixel whose ink (1 − luminance over white) reaches this is a line pixel: scribbles
    /// there are ignored. Default 0.5.
    pub line_threshold: f32,
    /// Lines cast a ridge of ink fading to nothing over this many px before the lift
    /// ([`gap_closing`]): a gap of g px keeps 1 − g / (2·fade) of the line's ink, so it
    /// separates colors instead of letting one flood through. 0 = off. Default 4.
    pub gap_closing_px: f64,
    /// Gaps closed first by joining line end points with curves ([`end_point_join`]), before
    /// the ridge. Default: on, with its defaults.
    pub end_point_join: EndPointJoinOptions,
    /// How the lifted mesh is measured. Default: edge stretch.
    pub stiffness: LiftedStiffness,
    /// Default: harmonic.
    pub weights: ColorWeights,
    /// Default: flat.
    pub fill: FillMode,
    /// How a region holding several scribble colors is split. Default: reach.
    pub split: RegionSplit,
    /// `split: density`: σ of the coarse Gaussian the paper mask is blurred with, px (the
    /// ink within about 2σ of a pixel orders the flood). Default 12 (G'MIC uses 1 % of the
    /// image's side, 5 px at 512²; chosen among 3–32 on the evaluation's set 26, see
    /// docs/colorize-eval.md).
    pub split_blur_px: f64,
    /// `split: density`: σ of the fine Gaussian, px: the level is the lower of the two
    /// blurs' paper, so a pixel right beside a line stays shallow however open the paper
    /// beyond it. Default 1.
    pub split_fine_blur_px: f64,
    /// `split: depth`: distances to the lines beyond this many px count as this deep (deeper,
    /// the flood is a plain geodesic one). Default 16.
    pub split_depth_px: f64,
    /// `split: reach`: α, crossing a pixel costs (its distance to the nearest line)^−α: the
    /// larger, the more the narrowest opening on a path decides. Default 6 (chosen among
    /// 0–8 on the evaluation's set 26, see docs/colorize-eval.md).
    pub split_depth_exponent: f64,

    /// `soft` fill: each color's share of the (2·r + 1)² px box around a pixel, so region
    /// edges are antialiased over about that width and nothing spreads further. Default 1.
    pub soft_radius_px: u32,
    pub mesh: MeshOptions,
    pub scribbles: ScribbleOptions,
    /// Used with `weights: bbw`.
    pub bbw: BbwOptions,
}

/// The default lift scale, px per unit of color.
pub const DEFAULT_LIFT_SCALE: f64 = 1000.0;

impl Default for ColorizeOptions {
    fn default() -> Self {
        ColorizeOptions {
            scale: DEFAULT_LIFT_SCALE,
            line_threshold: 0.5,
            gap_closing_px: 4.0,
            end_point_join: EndPointJoinOptions::default(),
            stiffness: LiftedStiffness::EdgeStretch,
            weights: ColorWeights::Harmonic,
            fill: FillMode::Flat,
            split: RegionSplit::Reach,
            split_depth_px: 16.0,
            split_depth_exponent: 6.0,
            split_blur_px: 12.0,
            split_fine_blur_px: 1.0,

            soft_radius_px: 1,
            mesh: MeshOptions::default(),
            scribbles: ScribbleOptions::default(),
            bbw: BbwOptions::default(),
        }
    }
}

/// What was wrong with a colorization request.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ColorizeError {
    #[error("the scribbles are {scribbles_w}×{scribbles_h} px but the line art is {art_w}×{art_h} px; they must match")]
    SizeMismatch {
        art_w: u32,
        art_h: u32,
        scribbles_w: u32,
        scribbles_h: u32,
    },
    #[error("no scribbles: draw at least one colored stroke")]
    NoScribbles,
    #[error("scribble color #{0} has no pixel on the canvas")]
    OffCanvas(String),
    #[error("scribble color #{0} lies entirely on line pixels; draw it inside a region")]
    OnLines(String),
    /// An option out of its range: `field` as it is named in files (the batch manifest's
    /// colorize options, `end_point_join.spline_max_px`), `rule` what it must be and what it is.
    /// The command line names its flag instead ([`ColorizeError::InvalidOption::field`] →
    /// `--join-curve`).
    #[error("invalid colorize option: {field} {rule}")]
    InvalidOption { field: &'static str, rule: String },
    #[error("{0}")]
    Mesh(#[from] image_mesh::ImageMeshError),
    #[error("{0}")]
    Weights(#[from] weights::ColorWeightError),
    #[error("the colorization was cancelled")]
    Cancelled,
}

/// The result of a colorization.
#[derive(Clone, Debug, PartialEq)]
pub struct Colorized {
    /// The colored drawing, line art on top.
    pub image: RgbaImage,
    /// The fill alone (opaque).
    pub fill_only: RgbaImage,
    /// One mask layer per palette color when asked for; empty otherwise.
    pub layers: Vec<RgbaImage>,
    /// The scribble colors, in handle order.
    pub palette: Vec<[u8; 3]>,
    pub stats: ColorizeStats,
}

/// Sizes, for reports and benchmarks.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ColorizeStats {
    pub pixels: usize,
    pub vertices: usize,
    pub triangles: usize,
    /// Scribble pixels dropped because they lie on a line.
    pub scribble_pixels_on_lines: usize,
}

/// The scribble labels with those on line pixels removed; fails when a color is left with
/// no pixel.
pub fn effective_labels(
    art: &LineArt,
    scribbles: &Scribbles,
    line_threshold: f32,
) -> Result<(Vec<u16>, usize), ColorizeError> {
    if scribbles.colors.is_empty() {
        return Err(ColorizeError::NoScribbles);
    }
    let before = scribbles.pixel_counts();
    let mut dropped = 0;
    let labels: Vec<u16> = scribbles
        .labels
        .iter()
        .zip(&art.ink)
        .map(|(&l, &ink)| {
            if l > 0 && ink >= line_threshold {
                dropped += 1;
                0
            } else {
                l
            }
        })
        .collect();
    let mut after = vec![0usize; scribbles.colors.len()];
    for &l in &labels {
        if l > 0 {
            after[l as usize - 1] += 1;
        }
    }
    for (k, color) in scribbles.colors.iter().enumerate() {
        if before[k] == 0 {
            return Err(ColorizeError::OffCanvas(scribbles::hex(*color)));
        }
        if after[k] == 0 {
            return Err(ColorizeError::OnLines(scribbles::hex(*color)));
        }
    }
    Ok((labels, dropped))
}

/// Colorizes `lineart` from `scribbles`. With `want_layers`, also one mask per color.
pub fn colorize(
    lineart: &RgbaImage,
    scribbles: &Scribbles,
    options: &ColorizeOptions,
    want_layers: bool,
) -> Result<Colorized, ColorizeError> {
    check_size(lineart, scribbles)?;
    PreparedLineArt::new(lineart.clone(), options.clone())?.colorize(
        scribbles,
        want_layers,
        &AtomicBool::new(false),
    )
}

fn check_size(lineart: &RgbaImage, scribbles: &Scribbles) -> Result<(), ColorizeError> {
    if (scribbles.width, scribbles.height) != lineart.dimensions() {
        return Err(ColorizeError::SizeMismatch {
            art_w: lineart.width(),
            art_h: lineart.height(),
            scribbles_w: scribbles.width,
            scribbles_h: scribbles.height,
        });
    }
    Ok(())
}

/// The part of a colorization that depends on the line art alone, computed once per image:
/// the drawing over white, its ink, and its colors with gaps closed (steps 1 and 3). An
/// interactive session keeps one and re-solves only the scribble-dependent rest (the mesh
/// follows the scribbles' rims, so it is rebuilt per solve) on every stroke change.
#[derive(Clone, Debug)]
pub struct PreparedLineArt {
    pub image: RgbaImage,
    pub art: LineArt,
    /// The colors the lift and the mesh see: [`gap_closing::close_gaps`] of `art.over_white`.
    pub closed: Vec<[u8; 3]>,
    /// The regions the closed lines enclose, and the ink levels the watershed follows.
    pub regions: InkRegions,
    /// What the reach split reads of the regions, made by the first solve that splits by
    /// reach and kept for the next ones.
    reach_sites: OnceLock<ReachSites>,
    pub options: ColorizeOptions,
}

/// Largest lift scale, px per full color change: far beyond any image's size (the bad-input
/// sweep saw 1e300 fail as "not positive definite"; where between the two the solve breaks
/// down was not measured).
pub const MAX_LIFT_SCALE_PX: f64 = 1e5;

/// Largest σ of the density split's blurs, px: the kernel spans 8σ, and beyond a few
/// hundred px the blur costs seconds and orders nothing the depth flood would not.
pub const MAX_SPLIT_BLUR_PX: f64 = 256.0;

/// Largest `split_depth_exponent`: at 32 a pixel 1 px from a line already costs 2^32 times
/// one 2 px away, so the narrowest opening on a path decides alone, as with any larger α.
pub const MAX_SPLIT_DEPTH_EXPONENT: f64 = 32.0;

/// Largest soft-fill radius, px: a wider blend is a blur, not an antialiased edge.
pub const MAX_SOFT_RADIUS_PX: u32 = 8;

/// Longest gap-closing fade, px: as far as end points are joined ([`end_point_join::MAX_JOIN_PX`]).
/// Beyond, the ridge covers whole drawings in ink and leaves nothing to color (`--gap-closing
/// 1e9` colorized an image with no mesh and exit 0).
pub const MAX_GAP_CLOSING_PX: f64 = end_point_join::MAX_JOIN_PX;

impl ColorizeOptions {
    /// Refuses options out of their documented ranges ([`ColorizeError::InvalidOptions`]),
    /// as every colorization does before any work.
    pub fn check(&self) -> Result<(), ColorizeError> {
        use std::ops::Bound::{Excluded, Included};
        check_range("scale", self.scale, 0.0..=MAX_LIFT_SCALE_PX, " px")?;
        check_range(
            "line_threshold",
            self.line_threshold,
            (Excluded(0.0), Included(1.0)),
            "",
        )?;
        check_range("split_depth_px", self.split_depth_px, 0.5.., "")?;
        check_range(
            "split_depth_exponent",
            self.split_depth_exponent,
            0.0..=MAX_SPLIT_DEPTH_EXPONENT,
            "",
        )?;
        for (name, sigma_px) in [
            ("split_blur_px", self.split_blur_px),
            ("split_fine_blur_px", self.split_fine_blur_px),
        ] {
            check_range(name, sigma_px, 0.0..=MAX_SPLIT_BLUR_PX, " px")?;
        }
        check_range(
            "soft_radius_px",
            self.soft_radius_px,
            0.0..=f64::from(MAX_SOFT_RADIUS_PX),
            "",
        )?;
        check_range(
            "gap_closing_px",
            self.gap_closing_px,
            0.0..=MAX_GAP_CLOSING_PX,
            " px",
        )?;
        self.end_point_join
            .check()
            .map_err(|(field, rule)| ColorizeError::InvalidOption { field, rule })
    }
}

/// Refuses the option `name` unless its `value` is finite and within `range` (`unit` is
/// written after the range's limits; an open end is `inf`, which is refused as NaN is): the
/// one place [`ColorizeOptions::check`]'s range messages are worded. A magnitude of 10⁶ or
/// more, or below 10⁻³, is written as `1e300`.
fn check_range<T>(
    name: &'static str,
    value: T,
    range: impl std::ops::RangeBounds<f64>,
    unit: &str,
) -> Result<(), ColorizeError>
where
    T: Copy + Into<f64> + std::fmt::Display + std::fmt::LowerExp,
{
    use std::ops::Bound::{Excluded, Included, Unbounded};
    let x: f64 = value.into();
    if x.is_finite() && range.contains(&x) {
        return Ok(());
    }
    let shown = if x.is_finite() && x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
        format!("{value:e}")
    } else {
        value.to_string()
    };
    let low = match range.start_bound() {
        Included(lo) => format!("[{lo}"),
        Excluded(lo) => format!("({lo}"),
        Unbounded => "(-inf".to_string(),
    };
    let high = match range.end_bound() {
        Included(hi) => format!("{hi}]"),
        Excluded(hi) => format!("{hi})"),
        Unbounded => "inf)".to_string(),
    };
    Err(ColorizeError::InvalidOption {
        field: name,
        rule: format!("must lie in {low}, {high}{unit}, not {shown}"),
    })
}

/// What preparing line art reads of [`ColorizeOptions`], and nothing else: the preparation
/// runs on this alone, so two option sets with equal preparations share its work
/// ([`PreparedLineArt::with_options`]).
#[derive(Clone, Debug, PartialEq)]
struct Preparation {
    line_threshold: f32,
    end_point_join: EndPointJoinOptions,
    gap_closing_px: f64,
    split_depth_px: f64,
}

impl Preparation {
    fn of(options: &ColorizeOptions) -> Self {
        Preparation {
            line_threshold: options.line_threshold,
            end_point_join: options.end_point_join.clone(),
            gap_closing_px: options.gap_closing_px,
            split_depth_px: options.split_depth_px,
        }
    }

    /// Steps 1 and 3 on `lineart`: the drawing over white, its colors with gaps closed, and
    /// the regions those enclose.
    fn run(&self, lineart: &RgbaImage) -> (LineArt, Vec<[u8; 3]>, InkRegions) {
        let art = LineArt::new(lineart);
        // The lift and the mesh see the drawing with its gaps closed: end points joined by
        // curves of full ink, then every line's ridge.
        let joins = end_point_join::join_end_points(
            &art.line_mask(self.line_threshold),
            art.width,
            art.height,
            &self.end_point_join,
        );
        let mut joined = art.over_white.clone();
        for (c, &j) in joined.iter_mut().zip(&joins.mask) {
            if j {
                *c = [0; 3];
            }
        }
        let closed = gap_closing::close_gaps(&joined, art.width, art.height, self.gap_closing_px);
        let regions = InkRegions::new(
            &closed,
            art.width,
            art.height,
            self.line_threshold,
            self.split_depth_px,
        );
        (art, closed, regions)
    }
}

impl PreparedLineArt {
    /// Checks `options` and prepares `lineart` for colorizations with them.
    pub fn new(lineart: RgbaImage, options: ColorizeOptions) -> Result<Self, ColorizeError> {
        options.check()?;
        let (art, closed, regions) = Preparation::of(&options).run(&lineart);
        Ok(PreparedLineArt {
            image: lineart,
            art,
            closed,
            regions,
            reach_sites: OnceLock::new(),
            options,
        })
    }

    /// This line art prepared for `options`. When what the preparation reads is unchanged
    /// (`Preparation`: line threshold, end-point joins, gap closing, split depth), its work
    /// is kept and only the options change (a new split or α costs a copy); otherwise it is
    /// prepared anew.
    pub fn with_options(&self, options: ColorizeOptions) -> Result<Self, ColorizeError> {
        let same_preparation = Preparation::of(&self.options) == Preparation::of(&options);
        if !same_preparation {
            return PreparedLineArt::new(self.image.clone(), options);
        }
        options.check()?;
        Ok(PreparedLineArt {
            options,
            ..self.clone()
        })
    }

    /// Colorizes the prepared line art from `scribbles` (steps 2, 4, 5, 6). Setting `cancel`
    /// (from another thread) stops it with [`ColorizeError::Cancelled`] before the next step.
    pub fn colorize(
        &self,
        scribbles: &Scribbles,
        want_layers: bool,
        cancel: &AtomicBool,
    ) -> Result<Colorized, ColorizeError> {
        let (lineart, art, closed, options) = (&self.image, &self.art, &self.closed, &self.options);
        check_size(lineart, scribbles)?;
        let cancelled = || {
            if cancel.load(Ordering::Relaxed) {
                Err(ColorizeError::Cancelled)
            } else {
                Ok(())
            }
        };
        let (labels, dropped) = effective_labels(art, scribbles, options.line_threshold)?;
        cancelled()?;
        let m = scribbles.colors.len();
        let (mut vertices, mut triangles) = (0, 0);
        // Regions closed by lines take their one color; regions holding several are split by
        // the content-aware weights (only then is the mesh built and solved); the watershed
        // reaches the rest (ink_regions).
        let regions = &self.regions;
        let owner = ink_regions::owners(regions, &labels, |per_region, owner| {
            let contested = |i: usize| {
                let r = regions.region[i] as usize;
                r > 0 && per_region[r - 1].len() > 1
            };
            let (w, h) = (art.width, art.height);
            match options.split {
                RegionSplit::Density => {
                    let level = density_split::density_levels(
                        &regions.region,
                        w,
                        h,
                        options.split_fine_blur_px,
                        options.split_blur_px,
                    );
                    ink_regions::watershed_within(&level, owner, w, h, contested);
                    return Ok(());
                }
                RegionSplit::Depth => {
                    ink_regions::watershed_within(&regions.shallowness, owner, w, h, contested);
                    return Ok(());
                }
                RegionSplit::Reach => {
                    let sites = self.reach_sites.get_or_init(|| ReachSites::new(regions));
                    reach_split::reach_split(
                        regions,
                        sites,
                        &labels,
                        owner,
                        options.split_depth_exponent,
                        contested,
                    );
                    return Ok(());
                }
                RegionSplit::Weights => {}
            }
            let mesh = ImageMesh::new(art.width, art.height, closed, &labels, &options.mesh)?;
            cancelled()?;
            let vertex_pixels = mesh.pixel_indices();
            let colors: Vec<[f64; 3]> = vertex_pixels
                .iter()
                .map(|&i| closed[i].map(|c| c as f64 / 255.0))
                .collect();
            let vertex_labels: Vec<u16> = vertex_pixels.iter().map(|&i| labels[i]).collect();
            let w = weights::color_weights(
                &mesh,
                &colors,
                &vertex_labels,
                m,
                &weights::ColorWeightOptions {
                    scale: options.scale,
                    stiffness: options.stiffness,
                    method: options.weights,
                    bbw: options.bbw.clone(),
                },
            )?;
            cancelled()?;
            mesh.interpolate(|i, bary| {
                if labels[i] != 0 || !contested(i) {
                    return;
                }
                let r = regions.region[i] as usize;
                let mut best = (f64::NEG_INFINITY, 0u16);
                for &c in &per_region[r - 1] {
                    let share: f64 = bary
                        .iter()
                        .map(|&(v, b)| b * w.row(v as usize)[c as usize - 1])
                        .sum();
                    if share > best.0 {
                        best = (share, c);
                    }
                }
                owner[i] = best.1;
            });
            vertices = mesh.vertex_count();
            triangles = mesh.triangles.len();
            Ok::<(), ColorizeError>(())
        })?;
        cancelled()?;
        let filled = fill::fill_owners(
            &owner,
            &scribbles.colors,
            art,
            lineart,
            options.fill,
            options.soft_radius_px,
            want_layers,
        );
        Ok(Colorized {
            image: filled.image,
            fill_only: filled.fill_only,
            layers: filled.layers,
            palette: scribbles.colors.clone(),
            stats: ColorizeStats {
                pixels: art.pixel_count(),
                vertices,
                triangles,
                scribble_pixels_on_lines: dropped,
            },
        })
    }
}

#[cfg(test)]
mod check_tests {
    use super::*;

    /// Sets one option of [`ColorizeOptions`] to a value.
    type Set = fn(&mut ColorizeOptions, f64);

    #[test]
    fn each_option_out_of_its_range_is_refused_by_its_own_name() {
        const INF: f64 = f64::INFINITY;
        const NAN: f64 = f64::NAN;
        assert_eq!(ColorizeOptions::default().check(), Ok(()));
        // Each option: its name in the message, values refused, and its limits (accepted).
        let options: [(&str, Set, &[f64], &[f64]); 8] = [
            (
                "scale",
                |o, v| o.scale = v,
                &[-1e-9, MAX_LIFT_SCALE_PX * 1.001, 1e300, NAN, INF, -INF],
                &[0.0, MAX_LIFT_SCALE_PX],
            ),
            (
                "line_threshold",
                |o, v| o.line_threshold = v as f32,
                &[0.0, -0.5, 1.01, NAN, INF],
                &[1e-6, 1.0],
            ),
            (
                "split_depth_px",
                |o, v| o.split_depth_px = v,
                &[0.49, -1.0, NAN, INF],
                &[0.5, 1e9],
            ),
            (
                "split_depth_exponent",
                |o, v| o.split_depth_exponent = v,
                &[-0.1, MAX_SPLIT_DEPTH_EXPONENT + 0.5, NAN, INF],
                &[0.0, MAX_SPLIT_DEPTH_EXPONENT],
            ),
            (
                "split_blur_px",
                |o, v| o.split_blur_px = v,
                &[-0.1, MAX_SPLIT_BLUR_PX + 0.5, NAN, INF],
                &[0.0, MAX_SPLIT_BLUR_PX],
            ),
            (
                "split_fine_blur_px",
                |o, v| o.split_fine_blur_px = v,
                &[-0.1, MAX_SPLIT_BLUR_PX + 0.5, NAN, INF],
                &[0.0, MAX_SPLIT_BLUR_PX],
            ),
            (
                "soft_radius_px",
                |o, v| o.soft_radius_px = v as u32,
                &[f64::from(MAX_SOFT_RADIUS_PX + 1), f64::from(u32::MAX)],
                &[0.0, f64::from(MAX_SOFT_RADIUS_PX)],
            ),
            (
                "gap_closing_px",
                |o, v| o.gap_closing_px = v,
                &[-0.1, NAN, INF, MAX_GAP_CLOSING_PX + 1.0],
                &[0.0, MAX_GAP_CLOSING_PX],
            ),
        ];
        for (name, set, refused, accepted) in options {
            for &value in refused {
                let mut o = ColorizeOptions::default();
                set(&mut o, value);
                let Err(ColorizeError::InvalidOption {
                    field,
                    rule: message,
                }) = o.check()
                else {
                    panic!("{name} = {value} was accepted");
                };
                assert_eq!(field, name, "{name} = {value}: {message}");
                let others: Vec<_> = options.iter().map(|o| o.0).filter(|n| *n != name).collect();
                assert!(
                    others.iter().all(|other| !message.contains(other)),
                    "{name} = {value}: {message}"
                );
            }
            for &value in accepted {
                let mut o = ColorizeOptions::default();
                set(&mut o, value);
                assert_eq!(o.check(), Ok(()), "{name} = {value}");
            }
        }
        // The wording, as `sinew colorize` and `sinew batch` print it.
        let refused = |set: &dyn Fn(&mut ColorizeOptions)| {
            let mut o = ColorizeOptions::default();
            set(&mut o);
            o.check().unwrap_err().to_string()
        };
        assert_eq!(
            refused(&|o| o.scale = 1e300),
            "invalid colorize option: scale must lie in [0, 100000] px, not 1e300"
        );
        assert_eq!(
            refused(&|o| o.split_depth_exponent = 99.0),
            "invalid colorize option: split_depth_exponent must lie in [0, 32], not 99"
        );
        assert_eq!(
            refused(&|o| o.line_threshold = 0.0),
            "invalid colorize option: line_threshold must lie in (0, 1], not 0"
        );
        assert_eq!(
            refused(&|o| o.gap_closing_px = f64::NAN),
            "invalid colorize option: gap_closing_px must lie in [0, 256] px, not NaN"
        );
    }
}
