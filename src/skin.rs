//! Skinning: rest vertices + sparse weights + one affine map per handle → posed vertices.
//!
//! In: rest positions (canvas px), [`SkinWeights`] (each vertex's non-zero weights, rows summing
//! to one), and one [`Affine`] per handle (rest canvas → posed canvas). Out: posed positions.
//! Linear blend skinning: v' = Σ_j w_ij (A_j v + t_j), evaluated as v + Σ_j w_ij (A_j v + t_j − v)
//! so that identity transforms give back the rest positions bit for bit, whatever rounding the
//! weights' sum carries. Large meshes split across threads.

use crate::geom::Point;
use crate::rig::pose::Affine;
use rayon::prelude::*;

/// Sparse weights in compressed rows: vertex i's influences are
/// `handles[offsets[i]..offsets[i+1]]` with `weights[..]` alongside.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SkinWeights {
    pub offsets: Vec<u32>,
    pub handles: Vec<u32>,
    pub weights: Vec<f64>,
}

impl SkinWeights {
    /// From per-vertex lists of (handle, weight).
    pub fn from_rows(rows: &[Vec<(u32, f64)>]) -> Self {
        let mut s = SkinWeights {
            offsets: Vec::with_capacity(rows.len() + 1),
            ..Default::default()
        };
        s.offsets.push(0);
        for row in rows {
            for &(h, w) in row {
                s.handles.push(h);
                s.weights.push(w);
            }
            s.offsets.push(s.handles.len() as u32);
        }
        s
    }

    pub fn vertex_count(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Vertex i's influences.
    pub fn row(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let range = self.offsets[i] as usize..self.offsets[i + 1] as usize;
        self.handles[range.clone()]
            .iter()
            .map(|&h| h as usize)
            .zip(self.weights[range].iter().copied())
    }
}

/// Below this many vertices, threads cost more than they save.
const PARALLEL_MIN_VERTICES: usize = 8192;

/// Linear blend skinning of `rest` into `out` (same length).
pub fn linear_blend(
    rest: &[Point],
    weights: &SkinWeights,
    transforms: &[Affine],
    out: &mut [Point],
) {
    let blend = |(i, (p, o)): (usize, (&Point, &mut Point))| {
        let (mut dx, mut dy) = (0.0, 0.0);
        for (h, w) in weights.row(i) {
            let t = &transforms[h];
            dx += w * ((t.linear[(0, 0)] - 1.0) * p.x + t.linear[(0, 1)] * p.y + t.translation.x);
            dy += w * (t.linear[(1, 0)] * p.x + (t.linear[(1, 1)] - 1.0) * p.y + t.translation.y);
        }
        *o = Point::new(p.x + dx, p.y + dy);
    };
    if rest.len() >= PARALLEL_MIN_VERTICES {
        rest.par_iter()
            .zip(out.par_iter_mut())
            .enumerate()
            .for_each(blend);
    } else {
        rest.iter().zip(out.iter_mut()).enumerate().for_each(blend);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Vec2;
    use crate::rig::pose::rotation;

    #[test]
    fn identity_and_rigid_transforms_are_reproduced() {
        let rest: Vec<Point> = (0..50)
            .map(|i| Point::new(i as f64, (i * 7 % 13) as f64))
            .collect();
        let rows: Vec<Vec<(u32, f64)>> = (0..50)
            .map(|i| vec![(0, i as f64 / 49.0), (1, 1.0 - i as f64 / 49.0)])
            .collect();
        let weights = SkinWeights::from_rows(&rows);
        let mut out = vec![Point::origin(); 50];
        linear_blend(
            &rest,
            &weights,
            &[Affine::identity(), Affine::identity()],
            &mut out,
        );
        assert_eq!(out, rest);
        // The same rigid motion on every handle moves every vertex rigidly.
        let rigid = Affine {
            linear: rotation(30.0),
            translation: Vec2::new(4.0, -2.0),
        };
        linear_blend(&rest, &weights, &[rigid, rigid], &mut out);
        for (p, q) in rest.iter().zip(&out) {
            assert!((rigid.apply(*p) - q).norm() < 1e-12);
        }
    }
}
