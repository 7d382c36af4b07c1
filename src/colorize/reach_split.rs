//! Splitting a region that holds several scribble colors by scaled geodesic reach: each pixel
//! takes the color whose scribble reaches it at the least cost, a path's cost growing where it
//! runs close to the lines and shrinking with the size of the scribble it starts from.
//!
//! Where the line art draws no boundary between two colors, nothing in it says where the
//! boundary is; this split encodes two priors of how people scribble and draw:
//!
//! - **Necks separate.** A path through a narrow opening costs more than one through open
//!   paper: crossing a pixel costs depth^−α, depth being its distance to the nearest line
//!   (px, at least [`MIN_DEPTH_PX`]), so colors meet where the region pinches (α large: the
//!   narrowest opening on the path dominates, as in a watershed on depth).
//! - **A scribble's size is its region's size.** A short dab marks a small thing (a seed, an
//!   eye, a nostril), a long stroke a large area. A color's cost from one scribble is divided
//!   by that scribble's radius (half its bounding box's diagonal plus [`DOT_RADIUS_PX`]), so a
//!   dab claims a small neighbourhood and a long stroke reaches far: a multiplicatively
//!   weighted geodesic Voronoi diagram.
//!
//! Geodesic distances from scribbles for segmentation: Bai & Sapiro 2007, "A Geodesic
//! Framework for Fast Interactive Image and Video Segmentation and Matting"; here the metric
//! comes from the line art's distance transform and each scribble scales its own distances.
//!
//! In: the regions ([`super::InkRegions`]: region ids and the chamfer depth), the scribble
//! labels (1-based colors, 0 none), `owner` (scribble pixels already own their color), which
//! pixels are contested, and α ([`super::ColorizeOptions::split_depth_exponent`]). Out: every
//! contested pixel a scribble can reach (inside its region, 8-connected) gets the color of
//! least cost. One Dijkstra per color over all its scribbles (a front carries the radius of
//! the scribble it started from), so a color's reach passes through other colors' ground: a
//! long stroke's share wraps around a dab's disk, as in a weighted Voronoi diagram, and need
//! not be connected. Ties go to the lower color: outputs are deterministic.

use super::InkRegions;
use radix_heap::RadixHeapMap;
use rayon::prelude::*;
use std::cmp::Reverse;

/// Depths below this count as this, px: a guard against 0^−α = ∞ (only barrier pixels, which
/// no front crosses, lie at depth 0; a pixel beside one lies at 1 px).
pub const MIN_DEPTH_PX: f64 = 0.5;

/// Added to a scribble's half extent, px: a one-pixel dot counts as a dab of this radius
/// (half the width of a 3-px stroke).
pub const DOT_RADIUS_PX: f64 = 1.5;

/// Assigns the contested pixels (see the module doc). `contested(i)`: pixel `i` lies in a
/// region holding several colors. `depth_exponent` α ≥ 0.
///
/// The colors' Dijkstras run in parallel (rayon), as many at a time as there are threads,
/// largest scribble first. A later batch's front stops where it cannot win: at a pixel that an
/// earlier color reaches at a strictly lower cost from a scribble at least as large, every
/// continuation is dearer too (cost a + L/r against at most b + L/r' with a > b, r ≤ r'), so
/// the split is the one without stopping. The result does not depend on the thread count:
/// what one batch reads was settled by the batches before it, and a pixel goes to the least
/// cost, ties to the lower color.
///
/// `sites`: [`ReachSites::new`] of `regions` (they depend on the line art alone, so a session
/// keeps them across solves).
pub fn reach_split(
    regions: &InkRegions,
    sites: &ReachSites,
    labels: &[u16],
    owner: &mut [u16],
    depth_exponent: f64,
    contested: impl Fn(usize) -> bool,
) {
    let (w, h) = (regions.width as usize, regions.height as usize);
    let (scribble, radius_px, color_of) = scribble_components(labels, w, h, &contested);
    // Each color with its largest scribble's radius, largest first (ties: lower color).
    let mut largest_px: Vec<(u16, f64)> = Vec::new();
    for (&color, &r) in color_of.iter().zip(&radius_px) {
        match largest_px.iter_mut().find(|(c, _)| *c == color) {
            Some((_, largest)) => *largest = largest.max(r),
            None => largest_px.push((color, r)),
        }
    }
    largest_px.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let colors: Vec<u16> = largest_px.iter().map(|&(c, _)| c).collect();
    // Per color (indexed by its label), its scribbles' pixels, ascending.
    let mut seeds: Vec<Vec<u32>> =
        vec![Vec::new(); colors.iter().max().map_or(0, |&c| c as usize + 1)];
    for (i, &s) in scribble.iter().enumerate() {
        if s != u32::MAX {
            seeds[color_of[s as usize] as usize].push(i as u32);
        }
    }
    assert_eq!(sites.site.len(), w * h, "the sites of other regions");
    let cost_of_depth = crossing_costs(sites.top_depth_index, depth_exponent);
    let field = Field {
        site: &sites.site,
        cost_of_depth: &cost_of_depth,
        offsets: STEPS.map(|(dx, dy, _)| dy * w as isize + dx),
        scribble: &scribble,
        seeds: &seeds,
        radius_px: &radius_px,
    };
    let mut won = Won {
        cost: vec![f64::INFINITY; w * h],
        color: vec![0; w * h],
        radius_px: vec![0.0; w * h],
    };
    // One reach buffer per color of a batch, reused: after a batch only the pixels it reached
    // are reset, so a late color stopped after a few pixels costs a few pixels.
    let threads = rayon::current_num_threads().max(1);
    let mut reaches: Vec<Reach> = (0..threads.min(colors.len()))
        .into_par_iter()
        .map(|_| Reach::unreached(w * h))
        .collect();
    let batches = colors.len().div_ceil(threads);
    for (k, batch) in colors.chunks(threads).enumerate() {
        let reaches = &mut reaches[..batch.len()];
        // The first batch has nothing to stop at.
        let stop = (k > 0).then_some(&won);
        (reaches.par_iter_mut().zip(batch)).for_each(|(reach, &c)| field.reach(c, stop, reach));
        // A color's offer of its cost at pixel i, taken when cheaper (ties: the lower color).
        let offer = |won_cost: &mut f64,
                     won_color: &mut u16,
                     won_radius_px: &mut f64,
                     (color, reach): (u16, &Reach),
                     i: usize| {
            let (offered, taken) = (reach.cost[i], *won_cost);
            if offered < taken || (offered == taken && offered.is_finite() && color < *won_color) {
                *won_cost = offered;
                *won_color = color;
                *won_radius_px = radius_px[reach.from[i] as usize];
            }
        };
        let offers = || batch.iter().copied().zip(reaches.iter());
        let reached: usize = reaches.iter().map(|r| r.reached.len()).sum();
        if reached < w * h / SPARSE_MERGE_SHARE {
            // Few pixels reached: only those, in one thread.
            let Won {
                cost,
                color,
                radius_px,
            } = &mut won;
            for by in offers() {
                for &i in &by.1.reached {
                    let i = i as usize;
                    offer(&mut cost[i], &mut color[i], &mut radius_px[i], by, i);
                }
            }
        } else {
            // Every pixel, by rows in parallel.
            let rows = w.max(1);
            (won.cost.par_chunks_mut(rows))
                .zip(won.color.par_chunks_mut(rows))
                .zip(won.radius_px.par_chunks_mut(rows))
                .enumerate()
                .for_each(|(y, ((cost, color), radius_px))| {
                    for by in offers() {
                        for x in 0..cost.len() {
                            offer(
                                &mut cost[x],
                                &mut color[x],
                                &mut radius_px[x],
                                by,
                                y * rows + x,
                            );
                        }
                    }
                });
        }
        if k + 1 < batches {
            reaches.par_iter_mut().for_each(Reach::reset);
        }
    }
    // Scribble pixels keep their own color.
    for i in 0..w * h {
        if labels[i] == 0 && won.color[i] != 0 {
            owner[i] = won.color[i];
        }
    }
}

/// What the reach split reads of the line art alone: per pixel its site ([`sites`]: depth
/// index and the steps that stay in its region), computed once per [`InkRegions`] and kept
/// across solves ([`super::PreparedLineArt`] holds one).
#[derive(Clone, Debug)]
pub struct ReachSites {
    site: Vec<u32>,
    /// The largest depth index below "far" ([`depth_indices`]).
    top_depth_index: u32,
}

impl ReachSites {
    /// The sites of `regions` (4 bytes per pixel).
    pub fn new(regions: &InkRegions) -> Self {
        let (w, h) = (regions.width as usize, regions.height as usize);
        let (top_depth_index, depth) = depth_indices(&regions.depth_half_px);
        ReachSites {
            site: sites(&regions.region, depth, w, h),
            top_depth_index,
        }
    }
}

/// Per pixel its depth index: its chamfer depth in half px, clamped to the deepest depth
/// present `top` (at most [`MAX_DEPTH_INDEX`] − 1) plus one, which stands for "no line
/// anywhere" and for depths beyond [`MAX_DEPTH_INDEX`]. Returns (`top`, indices).
fn depth_indices(depth_half_px: &[u32]) -> (u32, Vec<u32>) {
    let far = u32::MAX / 2;
    let top = depth_half_px
        .par_iter()
        .copied()
        .filter(|&d| d < far)
        .max()
        .unwrap_or(0)
        .min(MAX_DEPTH_INDEX - 1);
    let index = depth_half_px
        .par_iter()
        .map(|&d| if d <= top { d } else { top + 1 })
        .collect();
    (top, index)
}

/// The cost of crossing a pixel, (depth px, at least [`MIN_DEPTH_PX`])^−α, per depth index
/// `0..=top` ([`depth_indices`]), then for "far".
fn crossing_costs(top: u32, depth_exponent: f64) -> Vec<f64> {
    let of = |d: u32| (d as f64 / 2.0).max(MIN_DEPTH_PX).powf(-depth_exponent);
    let mut table: Vec<f64> = (0..=top).map(of).collect();
    table.push(of(u32::MAX / 2));
    table
}

/// A batch whose colors reached fewer than 1/this of the pixels is merged (and its buffers
/// reset) pixel by pixel over the ones reached; otherwise over every pixel in order.
const SPARSE_MERGE_SHARE: usize = 8;

/// The largest depth index a pixel's site holds (24 bits beside its 8 step bits): 2²⁴ half
/// px, 8 million px from the nearest line, far beyond any image.
const MAX_DEPTH_INDEX: u32 = (1 << 24) - 1;

/// Per pixel its site: its depth index (`depth`) above 8 bits of which steps (`STEPS`) stay in
/// the image and in its region, bit k for step k. One 4-byte read per pixel tells a front both.
fn sites(region: &[u32], depth: Vec<u32>, w: usize, h: usize) -> Vec<u32> {
    // In place: the depth indices are not needed after.
    let mut site = depth;
    site.par_iter_mut().for_each(|d| *d <<= 8);
    let row_of = |y: usize| &region[y * w..(y + 1) * w];
    site.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            let here = row_of(y);
            for (k, &(dx, dy, _)) in STEPS.iter().enumerate() {
                let Some(other) = y.checked_add_signed(dy).filter(|&ny| ny < h).map(row_of) else {
                    continue;
                };
                // The pixels whose step stays in the image, beside the ones it lands on.
                let (row, here, other) = match dx {
                    -1 => (&mut row[1..], &here[1..], &other[..w - 1]),
                    1 => (&mut row[..w - 1], &here[..w - 1], &other[1..]),
                    _ => (&mut row[..], here, other),
                };
                for ((s, a), b) in row.iter_mut().zip(here).zip(other) {
                    *s |= u32::from(a == b) << k;
                }
            }
        });
    site
}

/// What one color's Dijkstra reads.
struct Field<'a> {
    /// Per pixel its site ([`sites`]): depth index and the steps that stay in its region.
    site: &'a [u32],
    /// Per depth index, the cost of crossing a pixel ([`crossing_costs`]).
    cost_of_depth: &'a [f64],
    /// Per step of `STEPS`, the index offset it makes.
    offsets: [isize; 8],
    /// Per pixel its scribble component (u32::MAX: none).
    scribble: &'a [u32],
    /// Per color label, its scribbles' pixels.
    seeds: &'a [Vec<u32>],
    radius_px: &'a [f64],
}

/// Per pixel, the least cost over the colors done so far, that color (0: none) and the radius
/// of the scribble it came from, px.
struct Won {
    cost: Vec<f64>,
    color: Vec<u16>,
    radius_px: Vec<f64>,
}

/// One color's reach: per pixel its cost (∞: not reached, or stopped where it cannot win)
/// and the scribble it came from, and the pixels it reached.
struct Reach {
    cost: Vec<f64>,
    from: Vec<u32>,
    /// The pixels whose cost is finite, each once.
    reached: Vec<u32>,
}

impl Reach {
    /// No pixel reached, over `n` pixels.
    fn unreached(n: usize) -> Self {
        Reach {
            cost: vec![f64::INFINITY; n],
            from: vec![u32::MAX; n],
            reached: Vec::new(),
        }
    }

    /// Back to no pixel reached, touching only the pixels that were (or every pixel, in
    /// order, when they were many).
    fn reset(&mut self) {
        if self.reached.len() < self.cost.len() / SPARSE_MERGE_SHARE {
            for &i in &self.reached {
                (self.cost[i as usize], self.from[i as usize]) = (f64::INFINITY, u32::MAX);
            }
        } else {
            self.cost.fill(f64::INFINITY);
            self.from.fill(u32::MAX);
        }
        self.reached.clear();
    }
}

impl Field<'_> {
    /// Per pixel the least cost at which `color`'s scribbles reach it: one Dijkstra from all
    /// of them, a front carrying its scribble's radius, within regions, stopped where `won`
    /// (if any) already holds a strictly cheaper cost from a scribble at least as large.
    /// `into` starts unreached ([`Reach::unreached`] or [`Reach::reset`]).
    fn reach(&self, color: u16, won: Option<&Won>, into: &mut Reach) {
        // Slices and a local list, so the hot loop keeps their addresses in registers.
        let (reach, from) = (&mut into.cost[..], &mut into.from[..]);
        let mut reached = std::mem::take(&mut into.reached);
        // Costs are finite and non-negative, so they order like their bit patterns, and a
        // Dijkstra's popped costs never decrease: a monotone (radix) heap.
        let mut heap = RadixHeapMap::new();
        for &i in &self.seeds[color as usize] {
            let i = i as usize;
            if reach[i] == f64::INFINITY {
                reached.push(i as u32);
            }
            (reach[i], from[i]) = (0.0, self.scribble[i]);
            heap.push(Reverse(0u64), i as u32);
        }
        let cost = |site: u32| self.cost_of_depth[(site >> 8) as usize];
        while let Some((Reverse(bits), i)) = heap.pop() {
            let i = i as usize;
            let at = f64::from_bits(bits);
            if at > reach[i] {
                continue;
            }
            let source = from[i];
            let radius_px = self.radius_px[source as usize];
            let scale = 0.5 / radius_px;
            let site = self.site[i];
            let cost_here = cost(site);
            for (k, &(_, _, step_px)) in STEPS.iter().enumerate() {
                if site & (1 << k) == 0 {
                    continue;
                }
                let j = i.wrapping_add_signed(self.offsets[k]);
                let through = at + step_px * (cost_here + cost(self.site[j])) * scale;
                let lost = |won: &Won| through > won.cost[j] && radius_px <= won.radius_px[j];
                if through < reach[j] && !won.is_some_and(lost) {
                    if reach[j] == f64::INFINITY {
                        reached.push(j as u32);
                    }
                    (reach[j], from[j]) = (through, source);
                    heap.push(Reverse(through.to_bits()), j as u32);
                }
            }
        }
        into.reached = reached;
    }
}

/// The 8 steps (dx, dy, length px).
const STEPS: [(isize, isize, f64); 8] = [
    (1, 0, 1.0),
    (-1, 0, 1.0),
    (0, 1, 1.0),
    (0, -1, 1.0),
    (1, 1, std::f64::consts::SQRT_2),
    (1, -1, std::f64::consts::SQRT_2),
    (-1, 1, std::f64::consts::SQRT_2),
    (-1, -1, std::f64::consts::SQRT_2),
];

/// The scribbles in contested regions: per pixel its scribble (an 8-connected component of one
/// color's scribble pixels; u32::MAX: none), and per scribble its radius, px, and its color.
fn scribble_components(
    labels: &[u16],
    w: usize,
    h: usize,
    contested: &impl Fn(usize) -> bool,
) -> (Vec<u32>, Vec<f64>, Vec<u16>) {
    let mut component = vec![u32::MAX; w * h];
    let (mut radius_px, mut color_of) = (Vec::new(), Vec::new());
    let mut stack = Vec::new();
    for seed in 0..w * h {
        if labels[seed] == 0 || component[seed] != u32::MAX || !contested(seed) {
            continue;
        }
        let id = radius_px.len() as u32;
        let color = labels[seed];
        let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
        component[seed] = id;
        stack.push(seed);
        while let Some(i) = stack.pop() {
            let (x, y) = (i % w, i / w);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
            for (dx, dy, _) in STEPS {
                let (nx, ny) = (x as isize + dx, y as isize + dy);
                if nx < 0 || ny < 0 || nx >= w as isize || ny >= h as isize {
                    continue;
                }
                let j = ny as usize * w + nx as usize;
                if labels[j] == color && component[j] == u32::MAX && contested(j) {
                    component[j] = id;
                    stack.push(j);
                }
            }
        }
        let diagonal_px = ((x1 - x0) as f64).hypot((y1 - y0) as f64);
        radius_px.push(diagonal_px / 2.0 + DOT_RADIUS_PX);
        color_of.push(color);
    }
    (component, radius_px, color_of)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colorize::InkRegions;

    /// A `w`×`h` white page with the given black pixels, as regions (depth unclamped).
    fn page(w: u32, h: u32, ink: impl Fn(u32, u32) -> bool) -> InkRegions {
        let closed: Vec<[u8; 3]> = (0..w * h)
            .map(|i| if ink(i % w, i / w) { [0; 3] } else { [255; 3] })
            .collect();
        InkRegions::new(&closed, w, h, 0.5, 16.0)
    }

    fn split(regions: &InkRegions, labels: &[u16], alpha: f64) -> Vec<u16> {
        let mut owner = labels.to_vec();
        let sites = ReachSites::new(regions);
        reach_split(regions, &sites, labels, &mut owner, alpha, |i| {
            regions.region[i] > 0
        });
        owner
    }

    /// [`split`] on a pool of `threads` threads: one runs the colors one by one, each stopped
    /// where an earlier one wins; as many as there are colors runs them all unstopped.
    fn split_on(threads: usize, regions: &InkRegions, labels: &[u16], alpha: f64) -> Vec<u16> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool");
        pool.install(|| split(regions, labels, alpha))
    }

    #[test]
    fn a_dab_claims_a_small_disk_and_a_long_stroke_the_rest() {
        // Open paper framed by ink; a 1-px dab of color 2 at (20, 20), a 31-px stroke of
        // color 1 along y = 50.
        let (w, h) = (80u32, 70u32);
        let regions = page(w, h, |x, y| x == 0 || y == 0 || x == w - 1 || y == h - 1);
        let mut labels = vec![0u16; (w * h) as usize];
        labels[(20 * w + 20) as usize] = 2;
        for x in 25..56 {
            labels[(50 * w + x) as usize] = 1;
        }
        let owner = split(&regions, &labels, 0.0);
        let at = |x: u32, y: u32| owner[(y * w + x) as usize];
        assert_eq!(at(21, 20), 2, "beside the dab");
        // The dab's radius is 1.5 px, the stroke's 16.5: the dab's cell is an Apollonius
        // disk about 2 px across (distance to the dab / 1.5 = distance to the stroke / 16.5).
        assert_eq!(at(20, 14), 1, "6 px from the dab, 36 from the stroke");
        assert_eq!(at(20, 4), 1);
        let dab_px = owner.iter().filter(|&&o| o == 2).count();
        assert!((2..30).contains(&dab_px), "the dab claims {dab_px} px");
        // Every contested pixel got a color.
        assert!((0..(w * h) as usize).all(|i| regions.region[i] == 0 || owner[i] != 0));
    }

    #[test]
    fn colors_meet_at_the_neck_when_depth_dominates() {
        // Two 30×30 rooms joined by a 2-px-wide corridor (y 20–21, x 31–48); a dab in the
        // left room, a longer stroke in the right one. By distance alone the stroke's color
        // would take the corridor and spill into the left room; with α = 6 the corridor is
        // so dear that the left room stays the dab's.
        let (w, h) = (80u32, 42u32);
        let open = |x: u32, y: u32| {
            let left = (1..31).contains(&x) && (6..36).contains(&y);
            let right = (49..79).contains(&x) && (6..36).contains(&y);
            let corridor = (31..49).contains(&x) && (20..22).contains(&y);
            left || right || corridor
        };
        let regions = page(w, h, |x, y| !open(x, y));
        let mut labels = vec![0u16; (w * h) as usize];
        labels[(20 * w + 16) as usize] = 2;
        for x in 52..76 {
            labels[(20 * w + x) as usize] = 1;
        }
        let at = |owner: &[u16], x: u32, y: u32| owner[(y * w + x) as usize];
        let by_depth = split(&regions, &labels, 6.0);
        assert_eq!(at(&by_depth, 2, 7), 2, "the left room's corner");
        assert_eq!(at(&by_depth, 77, 34), 1, "the right room's corner");
        let by_distance = split(&regions, &labels, 0.0);
        assert_eq!(
            at(&by_distance, 29, 21),
            1,
            "without depth the stroke enters the room"
        );
    }

    #[test]
    fn the_split_does_not_depend_on_the_thread_count() {
        // Six colors (dabs and strokes of several sizes) in one open room with a pillar: one
        // thread runs them one by one, each stopped where an earlier one wins; three threads
        // run them two batches of three.
        let (w, h) = (90u32, 70u32);
        let regions = page(w, h, |x, y| {
            x == 0 || y == 0 || x == w - 1 || y == h - 1 || ((40..46).contains(&x) && y > 20)
        });
        let mut labels = vec![0u16; (w * h) as usize];
        let strokes: [(u16, u32, u32, u32); 6] = [
            (1, 5, 10, 30),
            (2, 60, 60, 1),
            (3, 70, 15, 12),
            (4, 20, 50, 4),
            (5, 50, 35, 1),
            (6, 10, 65, 20),
        ];
        for (color, x0, y, len) in strokes {
            for x in x0..x0 + len {
                labels[(y * w + x) as usize] = color;
            }
        }
        let on = |threads| split_on(threads, &regions, &labels, 6.0);
        let one = on(1);
        assert_eq!(one, on(3));
        assert_eq!(one, on(6));
        for color in 1..=6 {
            assert!(one.contains(&color), "color {color} won no pixel");
        }
    }

    #[test]
    fn a_front_passes_through_a_smaller_scribbles_ground() {
        // Two rooms joined by a 3-px corridor (y 19–21, x 40–49). Color 1: a long stroke at
        // the right room's far end and a dab in the corridor; color 2: a stroke in the left
        // room. Color 1 (the largest scribble) runs first; color 2's front must cross the
        // dab's small disk, where color 1 is cheaper but from a smaller scribble, to claim
        // the right room's near side. One thread (color 2 stopped where it cannot win) and
        // two (no stopping) agree.
        let (w, h) = (160u32, 42u32);
        let open = |x: u32, y: u32| {
            let left = (1..40).contains(&x) && (1..41).contains(&y);
            let right = (50..159).contains(&x) && (1..41).contains(&y);
            left || right || ((40..50).contains(&x) && (19..22).contains(&y))
        };
        let regions = page(w, h, |x, y| !open(x, y));
        let mut labels = vec![0u16; (w * h) as usize];
        for y in 3..39 {
            labels[(y * w + 157) as usize] = 1;
        }
        labels[(20 * w + 45) as usize] = 1;
        for x in 10..30 {
            labels[(20 * w + x) as usize] = 2;
        }
        let on = |threads| split_on(threads, &regions, &labels, 0.0);
        let one = on(1);
        assert_eq!(one[(20 * w + 45) as usize], 1, "the dab");
        assert_eq!(one[(20 * w + 55) as usize], 2, "past the dab: color 2");
        assert_eq!(one, on(2));
    }

    #[test]
    fn same_inputs_same_owners() {
        let (w, h) = (40u32, 30u32);
        let regions = page(w, h, |x, _| x == 0);
        let mut labels = vec![0u16; (w * h) as usize];
        labels[(15 * w + 10) as usize] = 1;
        labels[(15 * w + 30) as usize] = 2;
        let a = split(&regions, &labels, 0.0);
        assert_eq!(a, split(&regions, &labels, 0.0));
        // Equal dabs, α = 0: the split lies at x = 20.
        assert_eq!(a[(15 * w + 19) as usize], 1);
        assert_eq!(a[(15 * w + 21) as usize], 2);
    }
}
