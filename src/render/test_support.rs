//! Textures and meshes generated in code for the render tests.

use image::{Rgba, RgbaImage};
use tiny_skia::Pixmap;

use crate::geom::Point;

use super::Texture;

/// A straight-alpha image, opaque and colourful where `opaque(x, y)` holds for the pixel
/// center, transparent elsewhere. The colour varies smoothly in red and green and alternates
/// pixel by pixel in blue, so a half-pixel misplacement shows.
pub fn colorful_image(width: u32, height: u32, opaque: impl Fn(f64, f64) -> bool) -> RgbaImage {
    RgbaImage::from_fn(width, height, |x, y| {
        if opaque(f64::from(x) + 0.5, f64::from(y) + 0.5) {
            let blue = if (x + y) % 2 == 0 { 40 } else { 220 };
            Rgba([(x * 5 + y) as u8, (y * 3 + 2 * x) as u8, blue, 255])
        } else {
            Rgba([0, 0, 0, 0])
        }
    })
}

/// [`colorful_image`] as a premultiplied texture.
pub fn colorful_texture(width: u32, height: u32, opaque: impl Fn(f64, f64) -> bool) -> Texture {
    Texture::from_rgba(&colorful_image(width, height, opaque)).expect("non-empty test texture")
}

/// A transparent canvas.
pub fn canvas(width: u32, height: u32) -> Pixmap {
    Pixmap::new(width, height).expect("non-empty test canvas")
}

/// A grid mesh with vertices at every (xs[i], ys[j]), two triangles per cell.
pub fn grid_mesh(xs: &[f64], ys: &[f64]) -> (Vec<Point>, Vec<[u32; 3]>) {
    let points = ys
        .iter()
        .flat_map(|&y| xs.iter().map(move |&x| Point::new(x, y)))
        .collect();
    let row = xs.len() as u32;
    let mut triangles = Vec::new();
    for j in 0..ys.len() as u32 - 1 {
        for i in 0..row - 1 {
            let v = j * row + i;
            // Alternate the diagonal so that edges run in several directions.
            if (i + j) % 2 == 0 {
                triangles.push([v, v + 1, v + row + 1]);
                triangles.push([v, v + row + 1, v + row]);
            } else {
                triangles.push([v, v + 1, v + row]);
                triangles.push([v + 1, v + row + 1, v + row]);
            }
        }
    }
    (points, triangles)
}

/// `count` evenly spaced values from `lo` to `hi` inclusive.
pub fn linspace(lo: f64, hi: f64, count: usize) -> Vec<f64> {
    (0..count)
        .map(|i| lo + (hi - lo) * i as f64 / (count - 1) as f64)
        .collect()
}

/// A fan of `segments` thin triangles around `center`: vertex 0 is the center, the others lie
/// on a circle of `radius`.
pub fn fan_mesh(center: Point, radius: f64, segments: u32) -> (Vec<Point>, Vec<[u32; 3]>) {
    let mut points = vec![center];
    points.extend((0..segments).map(|k| {
        let angle = std::f64::consts::TAU * f64::from(k) / f64::from(segments);
        center + radius * nalgebra::Vector2::new(angle.cos(), angle.sin())
    }));
    let triangles = (0..segments)
        .map(|k| [0, 1 + k, 1 + (k + 1) % segments])
        .collect();
    (points, triangles)
}

/// Distance from `p` to the closed polyline `ring`.
pub fn distance_to_ring(p: Point, ring: &[Point]) -> f64 {
    (0..ring.len())
        .map(|i| crate::geom::point_segment_distance(p, ring[i], ring[(i + 1) % ring.len()]))
        .fold(f64::INFINITY, f64::min)
}
