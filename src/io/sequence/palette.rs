//! One colour palette for a whole animation: Wu's variance-minimising quantizer, refined by
//! k-means, and the exact nearest-entry map from every colour used to its palette index.
//!
//! In: the visible (alpha ≥ threshold) pixels of every frame, as 24-bit RGB, and the largest
//! palette size. Out: at most that many RGB colours and, for each colour that occurs, the index
//! of its nearest palette entry (squared RGB distance; ties go to the lower index).
//!
//! Why this method: one global palette must serve every frame, so it is built from the pooled
//! histogram of all of them. Wu's quantizer (Graphics Gems II, 1991) splits colour space into
//! boxes along the cut that most reduces the summed squared error, using cumulative moments over
//! a 32³ grid; it is exact, deterministic and fast, and its error is below median cut's (which
//! splits on population, not error) and NeuQuant's (a sampled neural net, tuned for photographs).
//! Wu's cuts fall on the 32-level grid, so where it runs out of cuttable boxes (smooth gradients
//! pack many colours into few grid cells) the remaining entries come from the same greedy cut
//! applied to the exact colours of the worst clusters; then a few Lloyd (k-means) passes move
//! every entry to the mean of the colours nearest to it — each pass can only lower the error. An animation with no more colours than the palette holds keeps them all, exactly.
//! No dithering: on flat cutout art it adds noise, and in an animation that noise crawls from
//! frame to frame; it also defeats the GIF's LZW compression.

use rayon::prelude::*;

/// Bits per channel of Wu's moment grid (32 levels per channel).
const GRID_BITS: u32 = 5;
/// Cells per axis of the cumulative moment arrays: the grid plus a zero border.
const SIDE: usize = (1 << GRID_BITS) + 1;
/// Lloyd passes at most after Wu's split; they stop early once no entry moves.
pub const KMEANS_PASSES: usize = 6;

/// A 24-bit colour packed as `0xRRGGBB`.
pub type Rgb24 = u32;

/// Packs red, green and blue into `0xRRGGBB`.
pub fn pack_rgb(r: u8, g: u8, b: u8) -> Rgb24 {
    (u32::from(r) << 16) | (u32::from(g) << 8) | u32::from(b)
}

fn unpack(c: Rgb24) -> [i64; 3] {
    [
        i64::from((c >> 16) as u8),
        i64::from((c >> 8) as u8),
        i64::from(c as u8),
    ]
}

/// Every distinct colour with its pixel count, sorted by colour.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Histogram {
    pub colours: Vec<Rgb24>,
    pub counts: Vec<u64>,
}

impl Histogram {
    /// Counts colours given as a list per frame (any order).
    pub fn from_frames(per_frame: Vec<Vec<Rgb24>>) -> Self {
        let runs: Vec<(Vec<Rgb24>, Vec<u64>)> = per_frame
            .into_par_iter()
            .map(|mut colours| {
                colours.sort_unstable();
                run_lengths(colours.iter().map(|&c| (c, 1)))
            })
            .collect();
        let mut pooled: Vec<(Rgb24, u64)> = runs
            .into_iter()
            .flat_map(|(colours, counts)| colours.into_iter().zip(counts))
            .collect();
        pooled.sort_unstable_by_key(|&(colour, _)| colour);
        let (colours, counts) = run_lengths(pooled.into_iter());
        Histogram { colours, counts }
    }

    pub fn is_empty(&self) -> bool {
        self.colours.is_empty()
    }

    /// The histogram of both histograms' pixels (counts of a colour in both add up): what
    /// [`Histogram::from_frames`] gives for their frames together.
    pub fn merge(&self, other: &Histogram) -> Histogram {
        let mut a = self
            .colours
            .iter()
            .copied()
            .zip(self.counts.iter().copied())
            .peekable();
        let mut b = other
            .colours
            .iter()
            .copied()
            .zip(other.counts.iter().copied())
            .peekable();
        let merged = std::iter::from_fn(|| match (a.peek(), b.peek()) {
            (Some(x), Some(y)) if x.0 <= y.0 => a.next(),
            (Some(_), Some(_)) => b.next(),
            (Some(_), None) => a.next(),
            (None, _) => b.next(),
        });
        let (colours, counts) = run_lengths(merged);
        Histogram { colours, counts }
    }
}

/// Merges equal neighbours of a colour-sorted list, adding their counts.
fn run_lengths(sorted: impl Iterator<Item = (Rgb24, u64)>) -> (Vec<Rgb24>, Vec<u64>) {
    let mut colours: Vec<Rgb24> = Vec::new();
    let mut counts: Vec<u64> = Vec::new();
    for (colour, count) in sorted {
        match (colours.last(), counts.last_mut()) {
            (Some(&last), Some(total)) if last == colour => *total += count,
            _ => {
                colours.push(colour);
                counts.push(count);
            }
        }
    }
    (colours, counts)
}

/// A palette and the nearest-entry index of every colour of the histogram it was built from.
#[derive(Debug, Clone, PartialEq)]
pub struct Quantized {
    /// Palette entries, RGB.
    pub palette: Vec<[u8; 3]>,
    /// Index into `palette` for each colour of the histogram, in the histogram's order.
    pub index_of_colour: Vec<u8>,
}

/// Builds a palette of at most `max_colours` (1..=256) entries for `histogram`.
pub fn quantize(histogram: &Histogram, max_colours: usize) -> Quantized {
    let max_colours = max_colours.clamp(1, 256);
    if histogram.colours.len() <= max_colours {
        return Quantized {
            palette: histogram.colours.iter().map(|&c| rgb_bytes(c)).collect(),
            index_of_colour: (0..histogram.colours.len()).map(|i| i as u8).collect(),
        };
    }
    let mut centres = wu_palette(histogram, max_colours);
    let mut nearest = nearest_indices(&histogram.colours, &centres);
    if centres.len() < max_colours {
        split_exactly(histogram, &nearest, &mut centres, max_colours);
        nearest = nearest_indices(&histogram.colours, &centres);
    }
    for _ in 0..KMEANS_PASSES {
        let moved = recentre(histogram, &nearest, &mut centres);
        if !moved {
            break;
        }
        nearest = nearest_indices(&histogram.colours, &centres);
    }
    Quantized {
        palette: centres
            .iter()
            .map(|c| c.map(|v| v.clamp(0, 255) as u8))
            .collect(),
        index_of_colour: nearest,
    }
}

fn rgb_bytes(c: Rgb24) -> [u8; 3] {
    unpack(c).map(|v| v as u8)
}

/// Index of the nearest centre to each colour (ties: lowest index). Parallel, order-preserving.
fn nearest_indices(colours: &[Rgb24], centres: &[[i64; 3]]) -> Vec<u8> {
    colours
        .par_iter()
        .map(|&c| {
            let rgb = unpack(c);
            let mut best = (i64::MAX, 0usize);
            for (i, centre) in centres.iter().enumerate() {
                let d: i64 = (0..3).map(|k| (rgb[k] - centre[k]).pow(2)).sum();
                if d < best.0 {
                    best = (d, i);
                }
            }
            best.1 as u8
        })
        .collect()
}

/// One Lloyd step: moves each centre to the rounded mean of its colours. Returns whether any
/// centre moved. Centres that lost all their colours stay where they are.
fn recentre(histogram: &Histogram, nearest: &[u8], centres: &mut [[i64; 3]]) -> bool {
    let mut sums = vec![[0u64; 4]; centres.len()];
    for ((&c, &count), &i) in histogram.colours.iter().zip(&histogram.counts).zip(nearest) {
        let rgb = unpack(c);
        let s = &mut sums[usize::from(i)];
        for k in 0..3 {
            s[k] += rgb[k] as u64 * count;
        }
        s[3] += count;
    }
    let mut moved = false;
    for (centre, s) in centres.iter_mut().zip(&sums) {
        if s[3] == 0 {
            continue;
        }
        let mean = [0, 1, 2].map(|k| ((s[k] + s[3] / 2) / s[3]) as i64);
        moved |= mean != *centre;
        *centre = mean;
    }
    moved
}

/// Fills the palette up to `max_colours` by splitting clusters of exact colours, worst first.
///
/// Wu's boxes cannot cut inside a grid cell (8 levels per channel), so a palette for smooth
/// gradients, whose many colours share few cells, comes out short. Here each cluster (the colours
/// nearest to one centre) is cut with Wu's criterion again, but between exact colour values: the
/// cluster with the largest squared error is split along the axis and at the value that lowers
/// it most, until the palette is full or every cluster is a single colour.
fn split_exactly(
    histogram: &Histogram,
    nearest: &[u8],
    centres: &mut Vec<[i64; 3]>,
    max_colours: usize,
) {
    let mut clusters: Vec<Vec<usize>> = vec![Vec::new(); centres.len()];
    for (colour, &i) in nearest.iter().enumerate() {
        clusters[usize::from(i)].push(colour);
    }
    let mut error: Vec<f64> = clusters
        .iter()
        .map(|m| cluster_error(histogram, m))
        .collect();
    while centres.len() < max_colours {
        let Some((worst, _)) = error
            .iter()
            .enumerate()
            .filter(|(_, &e)| e > 0.0)
            .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
        else {
            break;
        };
        let Some((lower, upper)) = best_exact_cut(histogram, &clusters[worst]) else {
            error[worst] = 0.0;
            continue;
        };
        centres[worst] = cluster_mean(histogram, &lower);
        centres.push(cluster_mean(histogram, &upper));
        error[worst] = cluster_error(histogram, &lower);
        error.push(cluster_error(histogram, &upper));
        clusters[worst] = lower;
        clusters.push(upper);
    }
}

/// (count, Σr, Σg, Σb) of a cluster's pixels.
fn cluster_sums(histogram: &Histogram, members: &[usize]) -> [i64; 4] {
    let mut s = [0i64; 4];
    for &m in members {
        let rgb = unpack(histogram.colours[m]);
        let n = histogram.counts[m] as i64;
        s[0] += n;
        for k in 0..3 {
            s[k + 1] += rgb[k] * n;
        }
    }
    s
}

fn cluster_mean(histogram: &Histogram, members: &[usize]) -> [i64; 3] {
    let [w, r, g, b] = cluster_sums(histogram, members);
    [r, g, b].map(|v| (v + w / 2) / w.max(1))
}

/// Summed squared distance of a cluster's pixels to their mean.
fn cluster_error(histogram: &Histogram, members: &[usize]) -> f64 {
    let square: i64 = members
        .iter()
        .map(|&m| {
            let rgb = unpack(histogram.colours[m]);
            (rgb[0] * rgb[0] + rgb[1] * rgb[1] + rgb[2] * rgb[2]) * histogram.counts[m] as i64
        })
        .sum();
    let sums = cluster_sums(histogram, members);
    if sums[0] == 0 {
        return 0.0;
    }
    square as f64 - spread_score(sums)
}

/// The cut of a cluster, along one channel between two of its distinct values, that most
/// lowers its squared error; None for a single colour.
fn best_exact_cut(histogram: &Histogram, members: &[usize]) -> Option<(Vec<usize>, Vec<usize>)> {
    let whole = cluster_sums(histogram, members);
    let mut best: Option<(f64, usize, i64)> = None;
    for axis in 0..3 {
        let mut sorted: Vec<(i64, usize)> = members
            .iter()
            .map(|&m| (unpack(histogram.colours[m])[axis], m))
            .collect();
        sorted.sort_unstable();
        let mut lower = [0i64; 4];
        for pair in sorted.windows(2) {
            let (value, m) = pair[0];
            let rgb = unpack(histogram.colours[m]);
            let n = histogram.counts[m] as i64;
            lower[0] += n;
            for k in 0..3 {
                lower[k + 1] += rgb[k] * n;
            }
            if pair[1].0 == value {
                continue;
            }
            let upper = [0, 1, 2, 3].map(|k| whole[k] - lower[k]);
            let score = spread_score(lower) + spread_score(upper);
            if best.is_none_or(|(s, _, _)| score > s) {
                best = Some((score, axis, value));
            }
        }
    }
    let (_, axis, value) = best?;
    let (lower, upper) = members
        .iter()
        .partition(|&&m| unpack(histogram.colours[m])[axis] <= value);
    Some((lower, upper))
}

/// Cumulative moments over the 33³ grid: pixel count, per-channel sums, sum of squared norms.
struct Moments {
    weight: Vec<i64>,
    red: Vec<i64>,
    green: Vec<i64>,
    blue: Vec<i64>,
    square: Vec<i64>,
}

fn cell(r: usize, g: usize, b: usize) -> usize {
    (r * SIDE + g) * SIDE + b
}

impl Moments {
    fn new(histogram: &Histogram) -> Self {
        let n = SIDE * SIDE * SIDE;
        let mut m = Moments {
            weight: vec![0; n],
            red: vec![0; n],
            green: vec![0; n],
            blue: vec![0; n],
            square: vec![0; n],
        };
        let shift = 8 - GRID_BITS;
        for (&c, &count) in histogram.colours.iter().zip(&histogram.counts) {
            let rgb = unpack(c);
            let count = count as i64;
            let at = cell(
                (rgb[0] >> shift) as usize + 1,
                (rgb[1] >> shift) as usize + 1,
                (rgb[2] >> shift) as usize + 1,
            );
            m.weight[at] += count;
            m.red[at] += rgb[0] * count;
            m.green[at] += rgb[1] * count;
            m.blue[at] += rgb[2] * count;
            m.square[at] += (rgb[0] * rgb[0] + rgb[1] * rgb[1] + rgb[2] * rgb[2]) * count;
        }
        for table in [
            &mut m.weight,
            &mut m.red,
            &mut m.green,
            &mut m.blue,
            &mut m.square,
        ] {
            prefix_sum_3d(table);
        }
        m
    }

    fn tables(&self) -> [&[i64]; 4] {
        [&self.weight, &self.red, &self.green, &self.blue]
    }
}

/// In place: each cell becomes the sum over the box from the origin to it (inclusive).
fn prefix_sum_3d(t: &mut [i64]) {
    for r in 1..SIDE {
        for g in 1..SIDE {
            for b in 1..SIDE {
                t[cell(r, g, b)] += t[cell(r, g, b - 1)];
            }
        }
    }
    for r in 1..SIDE {
        for g in 1..SIDE {
            for b in 1..SIDE {
                t[cell(r, g, b)] += t[cell(r, g - 1, b)];
            }
        }
    }
    for r in 1..SIDE {
        for g in 1..SIDE {
            for b in 1..SIDE {
                t[cell(r, g, b)] += t[cell(r - 1, g, b)];
            }
        }
    }
}

/// A box of grid cells: lower bounds exclusive, upper inclusive, per channel.
#[derive(Debug, Clone, Copy)]
struct ColourBox {
    lo: [usize; 3],
    hi: [usize; 3],
}

impl ColourBox {
    /// Sum of a cumulative table over the box (inclusion–exclusion over its 8 corners).
    fn sum(&self, t: &[i64]) -> i64 {
        let (l, h) = (self.lo, self.hi);
        t[cell(h[0], h[1], h[2])] - t[cell(h[0], h[1], l[2])] - t[cell(h[0], l[1], h[2])]
            + t[cell(h[0], l[1], l[2])]
            - t[cell(l[0], h[1], h[2])]
            + t[cell(l[0], h[1], l[2])]
            + t[cell(l[0], l[1], h[2])]
            - t[cell(l[0], l[1], l[2])]
    }

    /// The box cut at `at` along `axis`: the part with upper bound `at`.
    fn below(&self, axis: usize, at: usize) -> ColourBox {
        let mut b = *self;
        b.hi[axis] = at;
        b
    }

    fn cells(&self) -> usize {
        (0..3).map(|k| self.hi[k] - self.lo[k]).product()
    }

    /// Summed squared distance of the box's pixels to their mean.
    fn variance(&self, m: &Moments) -> f64 {
        let w = self.sum(&m.weight);
        if w == 0 {
            return 0.0;
        }
        let s: f64 = [&m.red, &m.green, &m.blue]
            .iter()
            .map(|t| (self.sum(t) as f64).powi(2))
            .sum();
        self.sum(&m.square) as f64 - s / w as f64
    }
}

/// `Σ²/w` of the pixels in a part: the larger, the smaller the part's squared error.
fn spread_score(sums: [i64; 4]) -> f64 {
    let [w, r, g, b] = sums;
    ((r as f64).powi(2) + (g as f64).powi(2) + (b as f64).powi(2)) / w as f64
}

/// The best cut of `bx`: (axis, position), or None when no cut leaves pixels on both sides.
fn best_cut(bx: &ColourBox, m: &Moments) -> Option<(usize, usize)> {
    let whole = m.tables().map(|t| bx.sum(t));
    let mut best: Option<(f64, usize, usize)> = None;
    for axis in 0..3 {
        for at in bx.lo[axis] + 1..bx.hi[axis] {
            let part = bx.below(axis, at);
            let lower = m.tables().map(|t| part.sum(t));
            let upper = [0, 1, 2, 3].map(|k| whole[k] - lower[k]);
            if lower[0] == 0 || upper[0] == 0 {
                continue;
            }
            let score = spread_score(lower) + spread_score(upper);
            if best.is_none_or(|(s, _, _)| score > s) {
                best = Some((score, axis, at));
            }
        }
    }
    best.map(|(_, axis, at)| (axis, at))
}

/// Wu's split into at most `max_colours` boxes; returns each box's mean colour.
fn wu_palette(histogram: &Histogram, max_colours: usize) -> Vec<[i64; 3]> {
    let m = Moments::new(histogram);
    let mut boxes = vec![ColourBox {
        lo: [0; 3],
        hi: [SIDE - 1; 3],
    }];
    // Error each box would still give up by splitting; 0 once it cannot be split.
    let mut splittable = vec![boxes[0].variance(&m)];
    while boxes.len() < max_colours {
        let Some((next, _)) = splittable
            .iter()
            .enumerate()
            .filter(|(_, &v)| v > 0.0)
            .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
        else {
            break;
        };
        let bx = boxes[next];
        let Some((axis, at)) = best_cut(&bx, &m) else {
            splittable[next] = 0.0;
            continue;
        };
        let lower = bx.below(axis, at);
        let mut upper = bx;
        upper.lo[axis] = at;
        boxes[next] = lower;
        boxes.push(upper);
        let score = |b: &ColourBox| if b.cells() > 1 { b.variance(&m) } else { 0.0 };
        splittable[next] = score(&lower);
        splittable.push(score(&upper));
    }
    boxes
        .iter()
        .filter_map(|bx| {
            let [w, r, g, b] = m.tables().map(|t| bx.sum(t));
            (w > 0).then(|| [r, g, b].map(|s| (s + w / 2) / w))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn squared_error(h: &Histogram, q: &Quantized) -> u64 {
        h.colours
            .iter()
            .zip(&h.counts)
            .zip(&q.index_of_colour)
            .map(|((&c, &n), &i)| {
                let p = q.palette[usize::from(i)];
                let rgb = unpack(c);
                (0..3)
                    .map(|k| (rgb[k] - i64::from(p[k])).pow(2) as u64)
                    .sum::<u64>()
                    * n
            })
            .sum()
    }

    #[test]
    fn histogram_pools_frames() {
        let h = Histogram::from_frames(vec![vec![5, 3, 5], vec![3, 9], vec![]]);
        assert_eq!(h.colours, vec![3, 5, 9]);
        assert_eq!(h.counts, vec![2, 2, 1]);
    }

    #[test]
    fn merged_histograms_are_the_pooled_one() {
        let frames = vec![vec![5, 3, 5], vec![3, 9], vec![], vec![1, 9, 9, 12]];
        let whole = Histogram::from_frames(frames.clone());
        let merged = Histogram::from_frames(frames[..2].to_vec())
            .merge(&Histogram::from_frames(frames[2..].to_vec()));
        assert_eq!(merged, whole);
        assert_eq!(Histogram::default().merge(&whole), whole);
        assert_eq!(whole.merge(&Histogram::default()), whole);
    }

    #[test]
    fn few_colours_are_kept_exactly() {
        let h = Histogram::from_frames(vec![vec![0xff0000, 0x00ff00, 0x0000ff, 0x00ff00]]);
        let q = quantize(&h, 4);
        assert_eq!(q.palette, vec![[0, 0, 255], [0, 255, 0], [255, 0, 0]]);
        assert_eq!(q.index_of_colour, vec![0, 1, 2]);
    }

    #[test]
    fn clusters_are_found_and_refinement_lowers_the_error() {
        // Four tight clusters of 27 colours each, one of them far more frequent.
        let centres = [[30u8, 40, 50], [200, 60, 60], [60, 200, 90], [240, 240, 20]];
        let mut pixels = Vec::new();
        for (n, c) in centres.iter().enumerate() {
            for d in 0..27u8 {
                let [dr, dg, db] = [d % 3, d / 3 % 3, d / 9].map(|v| v * 2);
                let colour = pack_rgb(c[0] + dr, c[1] + dg, c[2] + db);
                pixels.extend(std::iter::repeat_n(colour, if n == 0 { 50 } else { 3 }));
            }
        }
        let h = Histogram::from_frames(vec![pixels]);
        let q = quantize(&h, 4);
        assert_eq!(q.palette.len(), 4);
        // Each cluster maps to one entry, at its centre (offsets 0..4 average to +2).
        for c in centres {
            let expect = c.map(|v| v + 2);
            assert!(
                q.palette.contains(&expect),
                "{:?} not in {:?}",
                expect,
                q.palette
            );
        }
        let wu_only = {
            let centres = wu_palette(&h, 4);
            Quantized {
                index_of_colour: nearest_indices(&h.colours, &centres),
                palette: centres.iter().map(|c| c.map(|v| v as u8)).collect(),
            }
        };
        assert!(squared_error(&h, &q) <= squared_error(&h, &wu_only));
    }

    #[test]
    fn a_smooth_ramp_gets_an_even_palette_and_bounded_error() {
        // A grey ramp of 256 levels into 16 entries: each entry should cover about 16 levels,
        // so no colour is farther than ~8 levels (per channel) from its entry.
        let pixels: Vec<Rgb24> = (0..=255u8).map(|v| pack_rgb(v, v, v)).collect();
        let h = Histogram::from_frames(vec![pixels]);
        let q = quantize(&h, 16);
        assert_eq!(q.palette.len(), 16);
        for (&c, &i) in h.colours.iter().zip(&q.index_of_colour) {
            let v = unpack(c)[0];
            let p = q.palette[usize::from(i)];
            assert!((v - i64::from(p[0])).abs() <= 9, "level {v} → {p:?}");
        }
    }

    #[test]
    fn nearest_is_exact() {
        let pixels: Vec<Rgb24> = (0..4096u32).map(|i| i * 4099 % 0x1000000).collect();
        let h = Histogram::from_frames(vec![pixels]);
        let q = quantize(&h, 32);
        for (&c, &i) in h.colours.iter().zip(&q.index_of_colour) {
            let rgb = unpack(c);
            let d = |p: &[u8; 3]| {
                (0..3)
                    .map(|k| (rgb[k] - i64::from(p[k])).pow(2))
                    .sum::<i64>()
            };
            let best = q.palette.iter().map(d).min().unwrap();
            assert_eq!(d(&q.palette[usize::from(i)]), best);
        }
    }
}
