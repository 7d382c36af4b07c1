//! Connected-component labeling by runs: the 4-connected components of the pixels below a
//! level, numbered in raster order of their first pixel.
//!
//! In: one level per pixel (row-major, `width` per row) and the level from which a pixel is a
//! barrier. Out: per pixel its component's id (1-based; 0 on barriers) and the number of
//! components. The rows are cut into runs of open pixels in parallel; runs of neighbouring
//! rows that overlap are merged with a union-find whose root is always a component's first run
//! in raster order (the classic run-based two-pass labeling, Rosenfeld & Pfaltz 1966); the ids
//! are then painted row by row in parallel. The ids equal those of a flood fill started at
//! each unlabeled open pixel in raster order.

use rayon::prelude::*;

/// A run of open pixels on one row: columns `start..end`.
#[derive(Clone, Copy)]
struct Run {
    start: u32,
    end: u32,
}

/// The 4-connected components of the pixels whose `level` is below `barrier_from`, in an
/// image `width` wide: (per pixel the component id, 1-based in raster order of each
/// component's first pixel, 0 on barrier pixels; the number of components).
pub fn label_components(level: &[u8], width: usize, barrier_from: u8) -> (Vec<u32>, usize) {
    if width == 0 || level.is_empty() {
        return (vec![0; level.len()], 0);
    }
    let rows: Vec<Vec<Run>> = level
        .par_chunks(width)
        .map(|row| runs_of(row, barrier_from))
        .collect();
    // The first run of each row in one numbering.
    let mut first = Vec::with_capacity(rows.len() + 1);
    first.push(0usize);
    for row in &rows {
        first.push(first.last().copied().unwrap_or(0) + row.len());
    }
    let mut parent: Vec<usize> = (0..first[rows.len()]).collect();
    for y in 1..rows.len() {
        let (above, below) = (&rows[y - 1], &rows[y]);
        let (mut a, mut b) = (0, 0);
        while a < above.len() && b < below.len() {
            if above[a].start < below[b].end && below[b].start < above[a].end {
                union(&mut parent, first[y - 1] + a, first[y] + b);
            }
            // Step past whichever run ends first (both when they end together).
            let (end_a, end_b) = (above[a].end, below[b].end);
            if end_a <= end_b {
                a += 1;
            }
            if end_b <= end_a {
                b += 1;
            }
        }
    }
    // Roots are each component's first run (unions keep the lower index), so numbering the
    // roots in run order numbers the components in raster order of their first pixel.
    let mut id = vec![0u32; parent.len()];
    let mut count = 0usize;
    for r in 0..parent.len() {
        let root = find(&mut parent, r);
        if root == r {
            count += 1;
            id[r] = count as u32;
        } else {
            id[r] = id[root];
        }
    }
    let mut region = vec![0u32; level.len()];
    region
        .par_chunks_mut(width)
        .zip(rows.par_iter().zip(&first[..rows.len()]))
        .for_each(|(row, (runs, &first))| {
            for (k, run) in runs.iter().enumerate() {
                row[run.start as usize..run.end as usize].fill(id[first + k]);
            }
        });
    (region, count)
}

/// The runs of pixels below `barrier_from` in `row`, left to right.
fn runs_of(row: &[u8], barrier_from: u8) -> Vec<Run> {
    let mut runs = Vec::new();
    let mut x = 0;
    while x < row.len() {
        if row[x] >= barrier_from {
            x += 1;
            continue;
        }
        let start = x;
        while x < row.len() && row[x] < barrier_from {
            x += 1;
        }
        runs.push(Run {
            start: start as u32,
            end: x as u32,
        });
    }
    runs
}

/// The root of `i`, compressing the path to it.
fn find(parent: &mut [usize], mut i: usize) -> usize {
    let mut root = i;
    while parent[root] != root {
        root = parent[root];
    }
    while parent[i] != root {
        let next = parent[i];
        parent[i] = root;
        i = next;
    }
    root
}

/// Joins the sets of `a` and `b` under the lower root.
fn union(parent: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    let (low, high) = (ra.min(rb), ra.max(rb));
    parent[high] = low;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference: a flood fill from each unlabeled open pixel in raster order.
    fn flood_labels(level: &[u8], w: usize, barrier_from: u8) -> (Vec<u32>, usize) {
        let h = level.len() / w;
        let mut region = vec![0u32; level.len()];
        let mut count = 0;
        for seed in 0..level.len() {
            if region[seed] != 0 || level[seed] >= barrier_from {
                continue;
            }
            count += 1;
            region[seed] = count as u32;
            let mut stack = vec![seed];
            while let Some(i) = stack.pop() {
                let (x, y) = (i % w, i / w);
                let near = [
                    (x > 0).then(|| i - 1),
                    (x + 1 < w).then(|| i + 1),
                    (y > 0).then(|| i - w),
                    (y + 1 < h).then(|| i + w),
                ];
                for j in near.into_iter().flatten() {
                    if region[j] == 0 && level[j] < barrier_from {
                        region[j] = count as u32;
                        stack.push(j);
                    }
                }
            }
        }
        (region, count)
    }

    #[test]
    fn runs_label_as_a_raster_order_flood_fill_does() {
        // Random barriers at several densities (many small components, a few large ones,
        // U shapes whose arms meet rows later), on shapes down to one row and one column.
        for (w, h, density) in [
            (41usize, 29usize, 45u32),
            (41, 29, 30),
            (1, 17, 40),
            (17, 1, 40),
        ] {
            let mut state = 0x2545f491u32;
            let level: Vec<u8> = (0..w * h)
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 17;
                    state ^= state << 5;
                    if state % 100 < density {
                        200
                    } else {
                        (state % 100) as u8
                    }
                })
                .collect();
            let runs = label_components(&level, w, 128);
            assert_eq!(runs, flood_labels(&level, w, 128), "{w}×{h} at {density} %");
            assert!(runs.1 > 0);
        }
    }

    #[test]
    fn a_u_shape_is_one_component_numbered_from_its_first_pixel() {
        // Two arms joined at the bottom row: two runs on top that merge rows later, and a
        // separate dot after the left arm's first pixel in raster order.
        let b = 255u8;
        #[rustfmt::skip]
        let level = [
            0, b, 0, b, 0,
            0, b, 0, b, b,
            0, 0, 0, b, 0,
        ];
        let (region, count) = label_components(&level, 5, 128);
        assert_eq!(count, 3);
        assert_eq!(region, vec![1, 0, 1, 0, 2, 1, 0, 1, 0, 0, 1, 1, 1, 0, 3]);
    }
}
