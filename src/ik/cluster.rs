//! Rotation clusters: vertices grouped by their skinning weights (k-means in weight space).
//!
//! In: one dense weight vector per vertex (length = handle columns) and a cluster count. Out: a
//! cluster index per vertex. Fast automatic skinning transformations (Jacobson et al. 2012, §4)
//! let every vertex of a cluster share one rotation in the local step: vertices with similar
//! weights move alike, so a few clusters per handle capture the deformation the skinning
//! subspace can express, and the local step costs one 2×2 fit per cluster instead of per vertex.
//!
//! Seeding is farthest-point (deterministic, no random numbers); Lloyd iterations follow until
//! no vertex changes cluster or the iteration limit is reached.

use rayon::prelude::*;

/// Clusters `points` (each of length `dim`, stored back to back) into at most `count` groups.
/// Every returned index is below the returned cluster count, and every cluster is non-empty.
pub fn weight_space_clusters(
    points: &[f64],
    dim: usize,
    count: usize,
    iterations: usize,
) -> (Vec<u32>, usize) {
    let n = points.len().checked_div(dim).unwrap_or(0);
    if n == 0 {
        return (Vec::new(), 0);
    }
    let count = count.clamp(1, n);
    let point = |i: usize| &points[i * dim..(i + 1) * dim];
    let distance2 =
        |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>();

    // Farthest-point seeds, starting from vertex 0.
    let mut centers: Vec<f64> = point(0).to_vec();
    let mut nearest: Vec<f64> = (0..n)
        .into_par_iter()
        .map(|i| distance2(point(i), point(0)))
        .collect();
    while centers.len() / dim < count {
        let (far, d) =
            nearest.iter().enumerate().fold(
                (0, -1.0),
                |best, (i, &d)| if d > best.1 { (i, d) } else { best },
            );
        if d <= 0.0 {
            break; // Fewer distinct weight vectors than clusters asked for.
        }
        let seed = point(far).to_vec();
        nearest
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, d)| *d = d.min(distance2(point(i), &seed)));
        centers.extend_from_slice(&seed);
    }
    let k = centers.len() / dim;

    // Nearest center by ‖x − c‖² = ‖x‖² − 2 x·c + ‖c‖², the dot products as one matrix product
    // (n × dim times dim × k): the clustering's cost is all here.
    let x = nalgebra::DMatrix::from_row_slice(n, dim, points);
    let assign = |centers: &[f64]| -> Vec<u32> {
        let c = nalgebra::DMatrix::from_row_slice(k, dim, centers);
        let dots = &x * c.transpose();
        let norms: Vec<f64> = (0..k).map(|j| c.row(j).norm_squared()).collect();
        (0..n)
            .map(|i| {
                let mut best = (0u32, f64::INFINITY);
                for (j, norm) in norms.iter().enumerate() {
                    let d = norm - 2.0 * dots[(i, j)];
                    if d < best.1 {
                        best = (j as u32, d);
                    }
                }
                best.0
            })
            .collect()
    };
    let mut labels = assign(&centers);
    for _ in 0..iterations {
        let mut sums = vec![0.0; k * dim];
        let mut sizes = vec![0usize; k];
        for (i, &c) in labels.iter().enumerate() {
            let c = c as usize;
            sizes[c] += 1;
            for (s, x) in sums[c * dim..(c + 1) * dim].iter_mut().zip(point(i)) {
                *s += x;
            }
        }
        for c in 0..k {
            if sizes[c] > 0 {
                for (center, s) in centers[c * dim..(c + 1) * dim]
                    .iter_mut()
                    .zip(&sums[c * dim..(c + 1) * dim])
                {
                    *center = s / sizes[c] as f64;
                }
            }
        }
        let next = assign(&centers);
        let changed = next != labels;
        labels = next;
        if !changed {
            break;
        }
    }
    compact(labels)
}

/// Renumbers labels so that the clusters in use are 0..count, in order of first appearance.
fn compact(labels: Vec<u32>) -> (Vec<u32>, usize) {
    let mut map: Vec<Option<u32>> =
        vec![None; labels.iter().map(|&l| l as usize + 1).max().unwrap_or(0)];
    let mut next = 0u32;
    let labels = labels
        .into_iter()
        .map(|l| {
            *map[l as usize].get_or_insert_with(|| {
                next += 1;
                next - 1
            })
        })
        .collect();
    (labels, next as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separates_two_groups_and_is_deterministic() {
        // Vertices near handle 0 and vertices near handle 1.
        let mut points = Vec::new();
        for i in 0..20 {
            let w = if i < 10 {
                0.9 + 0.001 * i as f64
            } else {
                0.1 - 0.001 * i as f64
            };
            points.extend_from_slice(&[w, 1.0 - w]);
        }
        let (labels, count) = weight_space_clusters(&points, 2, 2, 10);
        assert_eq!(count, 2);
        assert!(labels[..10].iter().all(|&l| l == labels[0]));
        assert!(labels[10..].iter().all(|&l| l == labels[10]));
        assert_ne!(labels[0], labels[10]);
        assert_eq!(weight_space_clusters(&points, 2, 2, 10).0, labels);
    }

    #[test]
    fn never_more_clusters_than_distinct_points() {
        let points = vec![1.0, 0.0, 1.0, 0.0, 1.0, 0.0];
        let (labels, count) = weight_space_clusters(&points, 2, 5, 3);
        assert_eq!(count, 1);
        assert_eq!(labels, vec![0, 0, 0]);
    }
}
