//! The fill respects the ink: regions closed by lines, and a watershed along the lines.
//!
//! In: the line art with its gaps closed ([`super::gap_closing::close_gaps`], RGB8 per pixel,
//! row-major), its size and the line threshold. Out: [`InkRegions`]: per pixel its ink level
//! (0–255) and its region (a 4-connected component of the pixels whose closed ink stays below
//! the threshold; 0 on lines and their gap-closing ridges).
//!
//! How a colorization uses them ([`owners`]):
//! 1. a region holding scribbles of one color only takes that color, exactly: nothing crosses
//!    a closed line;
//! 2. a region holding several colors (a color boundary the line art does not draw, or a gap
//!    too wide to close) is split among them by a [`RegionSplit`];
//! 3. everything else (lines, the ridges they cast, regions without a scribble) is reached by
//!    a watershed: the colors flood outwards in order of ink level, so two colors meet on a
//!    line's crest, and at a gap on the ridge's crest, which is highest where the opening is
//!    narrowest (a cut, not a distance). An unscribbled region is flooded through its lowest
//!    crest, the widest opening into it.

use super::{chamfer, components};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// How a region holding scribbles of several colors (no line drawn between them, or a gap
/// too wide to close) is split among them.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum RegionSplit {
    /// Scaled geodesic reach ([`super::reach_split`]): each pixel takes the color whose
    /// scribble reaches it cheapest, paths dear near the lines (colors meet at necks) and
    /// each scribble's reach in proportion to its size (a dab claims a small thing, a long
    /// stroke a large area). The default: ahead of the other splits and of G'MIC's Smart
    /// Coloring on the evaluation's undrawn boundaries, held-out set included
    /// (docs/colorize-eval.md).
    #[default]
    Reach,
    /// An ink-density flood ([`super::density_split`]): the colors spread from their
    /// scribbles in order of how little ink lies around a pixel (the paper mask blurred),
    /// so they meet where ink crowds: narrow necks, between line ends that almost close.
    /// The flood order of G'MIC's Smart Coloring.
    Density,
    /// A depth flood: the colors spread from their scribbles in order of distance to the
    /// nearest line, deepest first, so each pixel takes the color whose path to it stays
    /// farthest from the lines: boundaries fall where the region is narrowest, and a scribble
    /// in a region's middle claims it over one in a corner.
    Depth,
    /// The content-aware (5D-lifted) weights: each pixel takes the largest weight among the
    /// colors scribbled in its region.
    Weights,
}

impl RegionSplit {
    /// Every split, the default first.
    pub const ALL: [RegionSplit; 4] = [
        RegionSplit::Reach,
        RegionSplit::Depth,
        RegionSplit::Density,
        RegionSplit::Weights,
    ];

    /// The name files and `sinew colorize --split` give it.
    pub fn name(self) -> &'static str {
        match self {
            RegionSplit::Reach => "reach",
            RegionSplit::Density => "density",
            RegionSplit::Depth => "depth",
            RegionSplit::Weights => "weights",
        }
    }
}

/// Per pixel: the closed ink level and the region.
#[derive(Clone, Debug, PartialEq)]
pub struct InkRegions {
    pub width: u32,
    pub height: u32,
    /// Closed ink, 0 (paper) to 255 (full ink).
    pub level: Vec<u8>,
    /// Region id per pixel, 1-based; 0 on barrier pixels (closed ink ≥ the threshold).
    pub region: Vec<u32>,
    /// The number of regions.
    pub count: usize,
    /// Per pixel: 255 − 255·min(1, its chamfer distance to the nearest barrier pixel /
    /// `depth_px`): low deep inside a region, the order a depth flood follows.
    pub shallowness: Vec<u8>,
    /// Per pixel: its chamfer distance to the nearest barrier pixel in half px (2 per axial,
    /// 3 per diagonal step), unclamped; 0 on barriers, u32::MAX / 2 where there are none.
    pub depth_half_px: Vec<u32>,
}

impl InkRegions {
    /// Labels the regions of `closed` (the gap-closed drawing over white).
    /// `depth_px`: distances beyond it count as it (the depth flood is a plain geodesic
    /// flood deeper than that).
    pub fn new(
        closed: &[[u8; 3]],
        width: u32,
        height: u32,
        line_threshold: f32,
        depth_px: f64,
    ) -> Self {
        let w = width as usize;
        let level: Vec<u8> = closed
            .par_iter()
            .map(|c| {
                let luminance = 0.2126 * c[0] as f32 + 0.7152 * c[1] as f32 + 0.0722 * c[2] as f32;
                (255.0 - luminance).round().clamp(0.0, 255.0) as u8
            })
            .collect();
        let barrier_from = (line_threshold * 255.0).ceil().clamp(1.0, 255.0) as u8;
        let (region, count) = components::label_components(&level, w, barrier_from);
        let depth_half_px = chamfer_half_px(&region, w);
        let far_half_px = (2.0 * depth_px).round().clamp(1.0, 1e6) as u32;
        let shallowness = depth_half_px
            .par_iter()
            .map(|&v| (255 - (v.min(far_half_px) as u64 * 255 / far_half_px as u64)) as u8)
            .collect();
        InkRegions {
            width,
            height,
            level,
            region,
            count,
            shallowness,
            depth_half_px,
        }
    }

    /// Per region (index = id − 1): the colors (1-based labels) scribbled inside, ascending.
    pub fn colors_per_region(&self, labels: &[u16]) -> Vec<Vec<u16>> {
        let mut colors: Vec<Vec<u16>> = vec![Vec::new(); self.count];
        for (&r, &l) in self.region.iter().zip(labels) {
            if r > 0 && l > 0 {
                let c = &mut colors[r as usize - 1];
                if let Err(at) = c.binary_search(&l) {
                    c.insert(at, l);
                }
            }
        }
        colors
    }
}

/// The chamfer distance (2 per axial, 3 per diagonal step: half pixels) to the nearest
/// barrier pixel (`region` 0) in an image `w` wide; 0 on barriers, u32::MAX / 2 everywhere
/// without any.
fn chamfer_half_px(region: &[u32], w: usize) -> Vec<u32> {
    const FAR: u32 = u32::MAX / 2;
    let mut d: Vec<u32> = region
        .par_iter()
        .map(|&r| if r == 0 { 0 } else { FAR })
        .collect();
    chamfer::propagate(&mut d, w, 2, 3, |d, from, step| d.min(from + step));
    d
}

/// The 4-neighbors of pixel `i` in a `w`×`h` image.
fn neighbors4(i: usize, w: usize, h: usize) -> impl Iterator<Item = usize> {
    let (x, y) = (i % w, i / w);
    [
        (x > 0).then(|| i - 1),
        (x + 1 < w).then(|| i + 1),
        (y > 0).then(|| i - w),
        (y + 1 < h).then(|| i + w),
    ]
    .into_iter()
    .flatten()
}

/// Fills every pixel whose `owner` is 0 from the owned ones (1-based color labels) by a
/// watershed over `level`: a bucket queue floods in order of max(level so far, the pixel's
/// level), first in first out within a level, so two fronts meet on crests (and halfway across
/// a flat crest). Pixels no owned pixel can reach keep 0 (none exist when any pixel is owned).
pub fn watershed(level: &[u8], owner: &mut [u16], width: u32, height: u32) {
    watershed_within(level, owner, width, height, |_| true)
}

/// [`watershed`] that floods only the pixels `floodable` accepts, over levels of any unsigned
/// width (one bucket per level up to the highest present).
pub fn watershed_within<L: Copy + Into<usize>>(
    level: &[L],
    owner: &mut [u16],
    width: u32,
    height: u32,
    floodable: impl Fn(usize) -> bool,
) {
    let (w, h) = (width as usize, height as usize);
    let top = level.iter().map(|&l| l.into()).max().unwrap_or(0);
    let mut buckets: Vec<VecDeque<u32>> = (0..=top).map(|_| VecDeque::new()).collect();
    let mut queued = vec![false; w * h];
    for i in 0..w * h {
        if owner[i] != 0 || !floodable(i) {
            queued[i] = true;
        }
    }
    // Seeds: owned pixels next to an unowned one, at their own level.
    for i in 0..w * h {
        if owner[i] != 0 && neighbors4(i, w, h).any(|j| !queued[j]) {
            buckets[level[i].into()].push_back(i as u32);
        }
    }
    let mut current = 0usize;
    while current <= top {
        let Some(i) = buckets[current].pop_front() else {
            current += 1;
            continue;
        };
        let i = i as usize;
        let color = owner[i];
        for j in neighbors4(i, w, h) {
            if !queued[j] {
                queued[j] = true;
                owner[j] = color;
                buckets[current.max(level[j].into())].push_back(j as u32);
            }
        }
    }
}

/// Every pixel's color (1-based label), from the regions, the scribble labels and, for regions
/// holding several colors, `contested`: a function (pixel, the region's colors) → the label
/// the content-aware weights choose (called only when some region holds several colors, with
/// all its pixels at once; it sets the contested regions' pixels and may fail).
pub fn owners<E>(
    regions: &InkRegions,
    labels: &[u16],
    contested: impl FnOnce(&[Vec<u16>], &mut [u16]) -> Result<(), E>,
) -> Result<Vec<u16>, E> {
    let per_region = regions.colors_per_region(labels);
    let mut owner: Vec<u16> = regions
        .region
        .iter()
        .zip(labels)
        .map(|(&r, &l)| {
            if l > 0 {
                l
            } else if r > 0 && per_region[r as usize - 1].len() == 1 {
                per_region[r as usize - 1][0]
            } else {
                0
            }
        })
        .collect();
    if per_region.iter().any(|c| c.len() > 1) {
        contested(&per_region, &mut owner)?;
    }
    watershed(&regions.level, &mut owner, regions.width, regions.height);
    Ok(owner)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_split_is_named_as_files_name_it() {
        for split in RegionSplit::ALL {
            assert_eq!(
                serde_json::to_value(split).unwrap(),
                serde_json::Value::String(split.name().into())
            );
        }
        let mut names: Vec<&str> = RegionSplit::ALL.iter().map(|s| s.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), 4);
        assert_eq!(RegionSplit::ALL[0], RegionSplit::default());
    }

    /// A 9×5 drawing: a vertical line at x = 4, with a gap at row 2 when `gap`.
    fn split(gap: bool) -> (Vec<[u8; 3]>, u32, u32) {
        let (w, h) = (9u32, 5u32);
        let mut c = vec![[255u8; 3]; 45];
        for y in 0..h {
            if !(gap && y == 2) {
                c[(y * w + 4) as usize] = [0; 3];
            }
        }
        (c, w, h)
    }

    #[test]
    fn a_closed_line_separates_regions_and_a_gap_joins_them() {
        let (c, w, h) = split(false);
        let r = InkRegions::new(&c, w, h, 0.5, 64.0);
        assert_eq!(r.count, 2);
        assert_eq!(r.region[4], 0);
        let (c, w, h) = split(true);
        assert_eq!(InkRegions::new(&c, w, h, 0.5, 64.0).count, 1);
    }

    #[test]
    fn one_color_per_region_is_exact_and_the_watershed_meets_on_the_line() {
        let (c, w, h) = split(false);
        let r = InkRegions::new(&c, w, h, 0.5, 64.0);
        let mut labels = vec![0u16; 45];
        labels[0] = 1; // left
        labels[8] = 2; // right
        let owner = owners(&r, &labels, |_, _| -> Result<(), ()> {
            panic!("no region is contested")
        })
        .unwrap();
        for y in 0..5 {
            for x in 0..9 {
                let o = owner[y * 9 + x];
                if x < 4 {
                    assert_eq!(o, 1, "({x}, {y})");
                } else if x > 4 {
                    assert_eq!(o, 2, "({x}, {y})");
                } else {
                    assert!(o == 1 || o == 2);
                }
            }
        }
    }

    #[test]
    fn an_unscribbled_region_is_flooded_through_its_lowest_crest() {
        // Three columns of regions: | A | B | C |, lines at x = 3 (full ink) and x = 7 (half).
        let (w, h) = (11u32, 3u32);
        let mut c = vec![[255u8; 3]; 33];
        for y in 0..3 {
            c[y * 11 + 3] = [0; 3];
            c[y * 11 + 7] = [100; 3]; // ink ≈ 0.61: a line, but a lower crest
        }
        let r = InkRegions::new(&c, w, h, 0.5, 64.0);
        assert_eq!(r.count, 3);
        let mut labels = vec![0u16; 33];
        labels[0] = 1; // A
        labels[10] = 2; // C
        let owner = owners(&r, &labels, |_, _| -> Result<(), ()> { unreachable!() }).unwrap();
        // B (x = 4..=6) takes C's color: its crest toward C is the lower one.
        for y in 0..3 {
            for x in 4..7 {
                assert_eq!(owner[y * 11 + x], 2);
            }
        }
    }
}
