//! An adaptive triangle mesh over an image: one vertex per pixel along lines and strokes, big
//! triangles over flat areas.
//!
//! In: the image size and a per-pixel "content key" (color and scribble label), plus
//! [`MeshOptions`]. Out: [`ImageMesh`]: vertices at pixel centers (pixel (i, j) → canvas point
//! (i + 0.5, j + 0.5)), triangles (spade's Delaunay triangulation of the vertices), and
//! [`ImageMesh::interpolate`], which walks every pixel with its barycentric weights.
//!
//! Vertices come from a quadtree over the lattice of pixel centers (the classic adaptive
//! image mesh, e.g. Sarkis & Diepold's content-adaptive meshes): a cell that is flat — every
//! pixel in it (edges included) within [`MeshOptions::flat_tolerance`] of the others in each
//! channel, and one scribble label — and no larger than [`MeshOptions::max_cell_px`] is a leaf
//! and contributes its four corners; other cells split down to single pixels. So every pixel
//! of a line, of its antialiased rim and of a scribble's rim is a vertex, and a Delaunay
//! triangle cannot jump over a line: its circumcircle is empty, and the line's pixels are
//! vertices. The discretization has O(lines + strokes + area / max_cell²) unknowns instead of
//! one per pixel.

use crate::geom::Point;
use serde::{Deserialize, Serialize};
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

/// Mesh resolution.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MeshOptions {
    /// A cell is flat when each color channel varies by at most this (of 255) within it.
    /// Default 4.
    pub flat_tolerance: u8,
    /// Largest cell side, px (a power of two). Default 32.
    pub max_cell_px: u32,
}

impl Default for MeshOptions {
    fn default() -> Self {
        MeshOptions {
            flat_tolerance: 4,
            max_cell_px: 32,
        }
    }
}

/// The mesh over the image.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageMesh {
    pub width: u32,
    pub height: u32,
    /// Pixel (column, row) of each vertex; its canvas position is the pixel's center.
    pub pixels: Vec<[u32; 2]>,
    pub triangles: Vec<[u32; 3]>,
}

/// A vertex for spade, remembering nothing but its position (bulk_load_stable keeps order).
#[derive(Clone, Copy, Debug)]
struct Vertex(Point2<f64>);

impl HasPosition for Vertex {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.0
    }
}

/// What prevents meshing.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ImageMeshError {
    #[error("the image is {0}×{1} px; at least 2×2 is needed")]
    TooSmall(u32, u32),
    #[error("max_cell_px must be a power of two, not {0}")]
    CellSize(u32),
    #[error("triangulation failed: {0}")]
    Triangulation(String),
}

impl ImageMesh {
    /// Builds the mesh. `color[i]` and `label[i]` describe pixel i (row-major).
    pub fn new(
        width: u32,
        height: u32,
        color: &[[u8; 3]],
        label: &[u16],
        options: &MeshOptions,
    ) -> Result<Self, ImageMeshError> {
        if width < 2 || height < 2 {
            return Err(ImageMeshError::TooSmall(width, height));
        }
        if !options.max_cell_px.is_power_of_two() {
            return Err(ImageMeshError::CellSize(options.max_cell_px));
        }
        let (w, h) = (width as usize, height as usize);
        let mut is_vertex = vec![false; w * h];
        let root = ((w.max(h) - 1) as u32).next_power_of_two() as usize;
        let flat = |x0: usize, y0: usize, x1: usize, y1: usize| {
            let first = y0 * w + x0;
            let (mut lo, mut hi, l) = (color[first], color[first], label[first]);
            for y in y0..=y1 {
                for i in y * w + x0..=y * w + x1 {
                    if label[i] != l {
                        return false;
                    }
                    for k in 0..3 {
                        lo[k] = lo[k].min(color[i][k]);
                        hi[k] = hi[k].max(color[i][k]);
                        if hi[k] - lo[k] > options.flat_tolerance {
                            return false;
                        }
                    }
                }
            }
            true
        };
        // Depth-first over cells (x, y, side) of the lattice of pixel indices.
        let mut stack = vec![(0usize, 0usize, root)];
        while let Some((x, y, s)) = stack.pop() {
            if x >= w || y >= h {
                continue;
            }
            let (x1, y1) = ((x + s).min(w - 1), (y + s).min(h - 1));
            if s == 1 || (s <= options.max_cell_px as usize && flat(x, y, x1, y1)) {
                for (cx, cy) in [(x, y), (x1, y), (x, y1), (x1, y1)] {
                    is_vertex[cy * w + cx] = true;
                }
            } else {
                let half = s / 2;
                stack.extend([
                    (x, y, half),
                    (x + half, y, half),
                    (x, y + half, half),
                    (x + half, y + half, half),
                ]);
            }
        }
        let pixels: Vec<[u32; 2]> = (0..w * h)
            .filter(|&i| is_vertex[i])
            .map(|i| [(i % w) as u32, (i / w) as u32])
            .collect();
        let vertices: Vec<Vertex> = pixels
            .iter()
            .map(|p| Vertex(Point2::new(p[0] as f64 + 0.5, p[1] as f64 + 0.5)))
            .collect();
        let dt: DelaunayTriangulation<Vertex> =
            DelaunayTriangulation::bulk_load_stable(vertices)
                .map_err(|e| ImageMeshError::Triangulation(format!("{e:?}")))?;
        let mut triangles: Vec<[u32; 3]> = dt
            .inner_faces()
            .map(|f| f.vertices().map(|v| v.fix().index() as u32))
            .collect();
        let darkness: Vec<u32> = pixels
            .iter()
            .map(|p| {
                let c = color[p[1] as usize * w + p[0] as usize];
                765 - (c[0] as u32 + c[1] as u32 + c[2] as u32)
            })
            .collect();
        orient_square_diagonals(&pixels, &darkness, &mut triangles);
        Ok(ImageMesh {
            width,
            height,
            pixels,
            triangles,
        })
    }

    pub fn vertex_count(&self) -> usize {
        self.pixels.len()
    }

    /// Vertex positions, canvas px (pixel centers).
    pub fn positions(&self) -> Vec<Point> {
        self.pixels
            .iter()
            .map(|p| Point::new(p[0] as f64 + 0.5, p[1] as f64 + 0.5))
            .collect()
    }

    /// Row-major pixel index of each vertex.
    pub fn pixel_indices(&self) -> Vec<usize> {
        self.pixels
            .iter()
            .map(|p| p[1] as usize * self.width as usize + p[0] as usize)
            .collect()
    }

    /// Calls `visit(pixel, [(vertex, barycentric weight); 3])` once for every pixel of the
    /// image, row by row. Vertices sit on the integer lattice of pixel indices, so the
    /// inside test is exact integer arithmetic; a pixel on an edge shared by two triangles goes
    /// to the first triangle listed (an ownership bitmap), which keeps the walk deterministic.
    pub fn interpolate(&self, mut visit: impl FnMut(usize, [(u32, f64); 3])) {
        let w = self.width as usize;
        let mut done = vec![false; w * self.height as usize];
        // Triangles of each row band: visit triangles in order, pixels inside each.
        for t in &self.triangles {
            let p = t.map(|v| {
                let q = self.pixels[v as usize];
                [q[0] as i64, q[1] as i64]
            });
            let area2 = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1])
                - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
            if area2 == 0 {
                continue;
            }
            let sign = area2.signum();
            let edge = |a: [i64; 2], b: [i64; 2], x: i64, y: i64| {
                ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) * sign
            };
            let x0 = p.iter().map(|q| q[0]).min().unwrap_or(0);
            let x1 = p.iter().map(|q| q[0]).max().unwrap_or(0);
            let y0 = p.iter().map(|q| q[1]).min().unwrap_or(0);
            let y1 = p.iter().map(|q| q[1]).max().unwrap_or(0);
            let inverse = 1.0 / (area2 * sign) as f64;
            for y in y0..=y1 {
                for x in x0..=x1 {
                    // Barycentric coordinate of vertex k ∝ the edge function opposite it.
                    let b0 = edge(p[1], p[2], x, y);
                    let b1 = edge(p[2], p[0], x, y);
                    let b2 = edge(p[0], p[1], x, y);
                    if b0 < 0 || b1 < 0 || b2 < 0 {
                        continue;
                    }
                    let i = y as usize * w + x as usize;
                    if std::mem::replace(&mut done[i], true) {
                        continue;
                    }
                    visit(
                        i,
                        [
                            (t[0], b0 as f64 * inverse),
                            (t[1], b1 as f64 * inverse),
                            (t[2], b2 as f64 * inverse),
                        ],
                    );
                }
            }
        }
    }
}

/// Where four vertices form a unit square of pixels, both of its diagonals are Delaunay (the
/// corners are cocircular) and spade picks one arbitrarily. A one-pixel diagonal line is only
/// 8-connected: the diagonal joining the two paper pixels across it would let weights leak
/// through the line. So each unit square takes the diagonal whose endpoints are
/// darker (the larger of the two pairs' smaller darkness), keeping the line a wall in the mesh.
fn orient_square_diagonals(pixels: &[[u32; 2]], darkness: &[u32], triangles: &mut [[u32; 3]]) {
    use std::collections::HashMap;
    // Unit squares (by their top-left pixel) → the two triangles splitting them.
    let mut squares: HashMap<[u32; 2], Vec<usize>> = HashMap::new();
    for (k, t) in triangles.iter().enumerate() {
        let p = t.map(|v| pixels[v as usize]);
        let (x0, x1) = (p.iter().map(|q| q[0]).min(), p.iter().map(|q| q[0]).max());
        let (y0, y1) = (p.iter().map(|q| q[1]).min(), p.iter().map(|q| q[1]).max());
        if let (Some(x0), Some(x1), Some(y0), Some(y1)) = (x0, x1, y0, y1) {
            if x1 == x0 + 1 && y1 == y0 + 1 {
                squares.entry([x0, y0]).or_default().push(k);
            }
        }
    }
    let mut keys: Vec<[u32; 2]> = squares.keys().copied().collect();
    keys.sort_unstable(); // HashMap order is random; flips must not depend on it.
    for key in keys {
        let pair = &squares[&key];
        let [a, b] = match pair.as_slice() {
            [a, b] => [*a, *b],
            _ => continue,
        };
        let (ta, tb) = (triangles[a], triangles[b]);
        // The shared edge (the current diagonal) and the two opposite corners.
        let shared: Vec<u32> = ta.iter().copied().filter(|v| tb.contains(v)).collect();
        let [p, q] = match shared.as_slice() {
            [p, q] => [*p, *q],
            _ => continue,
        };
        let (Some(&u), Some(&v)) = (
            ta.iter().find(|x| !tb.contains(x)),
            tb.iter().find(|x| !ta.contains(x)),
        ) else {
            continue;
        };
        let strength = |i: u32, j: u32| darkness[i as usize].min(darkness[j as usize]);
        if strength(u, v) > strength(p, q) {
            triangles[a] = [u, v, p];
            triangles[b] = [v, u, q];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn disc_image(w: u32, h: u32) -> (Vec<[u8; 3]>, Vec<u16>) {
        let color = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64 - 40.0, (i / w) as f64 - 30.0);
                let r = (x * x + y * y).sqrt();
                if (r - 20.0).abs() < 1.5 {
                    [0; 3]
                } else {
                    [255; 3]
                }
            })
            .collect();
        (color, vec![0; (w * h) as usize])
    }

    #[test]
    fn lines_are_fine_and_flat_areas_coarse() {
        let (w, h) = (97, 70);
        let (color, label) = disc_image(w, h);
        let mesh = ImageMesh::new(w, h, &color, &label, &MeshOptions::default()).unwrap();
        let is_vertex: std::collections::HashSet<[u32; 2]> = mesh.pixels.iter().copied().collect();
        // Every line pixel is a vertex.
        for (i, c) in color.iter().enumerate() {
            if *c == [0; 3] {
                assert!(is_vertex.contains(&[i as u32 % w, i as u32 / w]));
            }
        }
        // Far fewer vertices than pixels.
        assert!(
            mesh.vertex_count() < (w * h) as usize / 3,
            "{}",
            mesh.vertex_count()
        );
        // The four image corners are vertices, so the triangles cover the image.
        for c in [[0, 0], [w - 1, 0], [0, h - 1], [w - 1, h - 1]] {
            assert!(is_vertex.contains(&c));
        }
    }

    #[test]
    fn interpolation_visits_every_pixel_once_and_reproduces_linear_functions() {
        let (w, h) = (97, 70);
        let (color, label) = disc_image(w, h);
        let mesh = ImageMesh::new(w, h, &color, &label, &MeshOptions::default()).unwrap();
        let f = |p: [u32; 2]| 3.0 * p[0] as f64 - 2.0 * p[1] as f64 + 7.0;
        let values: Vec<f64> = mesh.pixels.iter().map(|&p| f(p)).collect();
        let mut visits = vec![0u32; (w * h) as usize];
        mesh.interpolate(|i, bary| {
            visits[i] += 1;
            let v: f64 = bary.iter().map(|&(k, b)| b * values[k as usize]).sum();
            let expected = f([i as u32 % w, i as u32 / w]);
            assert!((v - expected).abs() < 1e-9, "pixel {i}: {v} vs {expected}");
        });
        assert!(visits.iter().all(|&n| n == 1));
    }

    #[test]
    fn a_one_pixel_diagonal_line_stays_a_wall() {
        // A diagonal of black pixels on white, only 8-connected: no mesh edge may join two
        // white pixels on opposite sides of it.
        let n = 12u32;
        let color: Vec<[u8; 3]> = (0..n * n)
            .map(|i| if i % n == i / n { [0; 3] } else { [255; 3] })
            .collect();
        let mesh = ImageMesh::new(
            n,
            n,
            &color,
            &vec![0; (n * n) as usize],
            &MeshOptions::default(),
        )
        .unwrap();
        let side = |p: [u32; 2]| (p[0] as i64 - p[1] as i64).signum();
        for t in &mesh.triangles {
            for k in 0..3 {
                let (a, b) = (
                    mesh.pixels[t[k] as usize],
                    mesh.pixels[t[(k + 1) % 3] as usize],
                );
                assert!(side(a) * side(b) >= 0, "edge {a:?}–{b:?} crosses the line");
            }
        }
    }

    #[test]
    fn tiny_images_are_errors() {
        assert_eq!(
            ImageMesh::new(1, 5, &[[0; 3]; 5], &[0; 5], &MeshOptions::default()),
            Err(ImageMeshError::TooSmall(1, 5))
        );
    }
}
