//! The shape autorig works on: the union of the layers' alpha, traced as `sinew rig` traces it.
//!
//! In: one or more straight-alpha RGBA layers on one canvas and the [`TraceOptions`] the rig
//! will be built with. Out: a [`Shape`]: the traced outlines (canvas px; outer rings and holes)
//! and a raster of the pixels whose centers lie inside them (even-odd), plus exact queries:
//! whether a point or a whole segment lies inside the outlines. Handles proposed inside these
//! outlines lie inside the meshes `sinew rig` builds from the same layers, since it traces them
//! the same way (a layer's outline lies inside the union's).

use crate::geom::{point_in_ring, Point};
use crate::trace::{self, Outline, TraceError, TraceOptions};
use image::RgbaImage;

/// Side of the cells that bucket outline edges for segment queries, px.
const EDGE_CELL_PX: f64 = 8.0;

/// Default [`Shape::clearance_px`].
pub const SEGMENT_CLEARANCE_PX: f64 = 0.75;

/// A traced silhouette with fast inside queries.
#[derive(Clone, Debug)]
pub struct Shape {
    pub width: u32,
    pub height: u32,
    pub outlines: Vec<Outline>,
    /// Per pixel (row-major), whether its center lies inside the outlines.
    pub inside: Vec<bool>,
    /// Number of pixels inside, px².
    pub area_px2: f64,
    /// How far [`Shape::segment_inside`] keeps segments from the outline, px: a bone grazing
    /// the outline would leave sliver triangles where the mesher embeds it. Default
    /// [`SEGMENT_CLEARANCE_PX`].
    pub clearance_px: f64,
    edges: EdgeGrid,
}

/// The union of the layers' alpha on the first layer's canvas (the largest alpha per pixel;
/// color is not used; pixels off the canvas dropped).
pub fn union_alpha(layers: &[super::LayerRef]) -> RgbaImage {
    let [w, h] = layers.first().map_or([0, 0], |l| l.canvas_px);
    let mut out = RgbaImage::new(w, h);
    for layer in layers {
        let [ox, oy] = layer.offset_px.map(i64::from);
        let (lw, lh) = (
            i64::from(layer.image.width()),
            i64::from(layer.image.height()),
        );
        // The layer's columns and rows that lie on the canvas.
        let (x0, x1) = ((-ox).max(0), (i64::from(w) - ox).min(lw));
        let (y0, y1) = ((-oy).max(0), (i64::from(h) - oy).min(lh));
        if x0 >= x1 || y0 >= y1 {
            continue;
        }
        let (source, target) = (layer.image.as_raw(), &mut *out);
        for y in y0..y1 {
            // In range: 0 ≤ y < lh, 0 ≤ oy + y < h, and likewise for the columns.
            let from = ((y * lw + x0) * 4) as usize;
            let to = (((oy + y) * i64::from(w) + ox + x0) * 4) as usize;
            let n = ((x1 - x0) * 4) as usize;
            for (o, p) in target[to..to + n]
                .chunks_exact_mut(4)
                .zip(source[from..from + n].chunks_exact(4))
            {
                o[3] = o[3].max(p[3]);
            }
        }
    }
    out
}

impl Shape {
    /// Traces `image` with `options`. Returns `Ok(None)` when no region is large enough.
    pub fn trace(image: &RgbaImage, options: &TraceOptions) -> Result<Option<Shape>, TraceError> {
        Shape::trace_placed(&super::LayerRef::whole("", image), options)
    }

    /// Traces one layer's image and places the shape where the layer lies on its canvas.
    /// Returns `Ok(None)` when no region is large enough.
    pub fn trace_placed(
        layer: &super::LayerRef,
        options: &TraceOptions,
    ) -> Result<Option<Shape>, TraceError> {
        let outlines = trace::translated(trace::trace(layer.image, options)?, layer.offset_px);
        if outlines.is_empty() {
            return Ok(None);
        }
        let [w, h] = layer.canvas_px;
        Ok(Some(Shape::from_outlines(outlines, w, h)))
    }

    /// A shape from outlines already traced on a `width` × `height` canvas.
    pub fn from_outlines(outlines: Vec<Outline>, width: u32, height: u32) -> Shape {
        let inside = fill_even_odd(rings(&outlines), width, height);
        let area_px2 = inside.iter().filter(|&&b| b).count() as f64;
        let edges = EdgeGrid::new(rings(&outlines));
        Shape {
            width,
            height,
            outlines,
            inside,
            area_px2,
            clearance_px: SEGMENT_CLEARANCE_PX,
            edges,
        }
    }

    /// Whether the pixel containing `p` has its center inside (false off the canvas).
    pub fn pixel_inside(&self, p: Point) -> bool {
        if !(p.x >= 0.0 && p.y >= 0.0) {
            return false;
        }
        let (x, y) = (p.x as u32, p.y as u32);
        x < self.width && y < self.height && self.inside[(y * self.width + x) as usize]
    }

    /// The cells that may be inside, as `[x0, y0, x1, y1)` (columns x0..x1, rows y0..y1 of
    /// [`Shape::inside`]): the outlines' bounding box on the grid. Loops over a layer's inside
    /// cells stay within it, so a small layer on a large canvas costs its own size.
    pub fn cell_box(&self) -> [usize; 4] {
        let (mut lo, mut hi) = (
            Point::new(f64::MAX, f64::MAX),
            Point::new(f64::MIN, f64::MIN),
        );
        for p in rings(&self.outlines).flatten() {
            lo = Point::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Point::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        if lo.x > hi.x {
            return [0; 4];
        }
        let clamp = |v: f64, n: u32| (v.max(0.0) as usize).min(n as usize);
        [
            clamp(lo.x.floor(), self.width),
            clamp(lo.y.floor(), self.height),
            clamp(hi.x.ceil() + 1.0, self.width),
            clamp(hi.y.ceil() + 1.0, self.height),
        ]
    }

    /// The inside cells' centres, px, row by row.
    pub fn inside_centers(&self) -> impl Iterator<Item = Point> + '_ {
        let [x0, y0, x1, y1] = self.cell_box();
        let w = self.width as usize;
        (y0..y1).flat_map(move |y| {
            (x0..x1)
                .filter(move |&x| self.inside[y * w + x])
                .map(move |x| Point::new(x as f64 + 0.5, y as f64 + 0.5))
        })
    }

    /// Whether `p` lies inside the outlines (even-odd over every ring), exactly.
    pub fn contains(&self, p: Point) -> bool {
        rings(&self.outlines)
            .filter(|r| point_in_ring(p, r))
            .count()
            % 2
            == 1
    }

    /// Whether the whole segment `a`–`b` lies inside the outlines, at least
    /// [`Shape::clearance_px`] from them: `a` inside and no outline edge that near.
    pub fn segment_inside(&self, a: Point, b: Point) -> bool {
        self.contains(a) && !self.edges.near_segment(a, b, self.clearance_px)
    }

    /// Every ring (outer rings and holes).
    pub fn rings(&self) -> impl Iterator<Item = &[Point]> {
        rings(&self.outlines)
    }
}

fn rings(outlines: &[Outline]) -> impl Iterator<Item = &[Point]> {
    outlines
        .iter()
        .flat_map(|o| std::iter::once(o.outer.as_slice()).chain(o.holes.iter().map(Vec::as_slice)))
}

/// Pixels whose centers lie inside the rings by the even-odd rule (a scanline fill).
fn fill_even_odd<'a>(
    rings: impl Iterator<Item = &'a [Point]>,
    width: u32,
    height: u32,
) -> Vec<bool> {
    let mut crossings: Vec<Vec<f64>> = vec![Vec::new(); height as usize];
    for ring in rings {
        let n = ring.len();
        for i in 0..n {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            if a.y == b.y {
                continue;
            }
            let (lo, hi) = if a.y < b.y { (a, b) } else { (b, a) };
            // Rows whose center y + 0.5 lies in [lo.y, hi.y).
            let first = (lo.y - 0.5).ceil().max(0.0) as i64;
            let last = ((hi.y - 0.5).ceil() as i64 - 1).min(height as i64 - 1);
            for row in first..=last {
                let y = row as f64 + 0.5;
                let x = lo.x + (y - lo.y) / (hi.y - lo.y) * (hi.x - lo.x);
                crossings[row as usize].push(x);
            }
        }
    }
    let mut inside = vec![false; width as usize * height as usize];
    for (row, xs) in crossings.iter_mut().enumerate() {
        xs.sort_by(f64::total_cmp);
        for pair in xs.chunks_exact(2) {
            // Pixel centers x + 0.5 in [pair[0], pair[1]).
            let from = (pair[0] - 0.5).ceil().max(0.0) as i64;
            let to = ((pair[1] - 0.5).ceil() as i64).min(width as i64);
            for x in from..to {
                inside[row * width as usize + x as usize] = true;
            }
        }
    }
    inside
}

/// Outline edges bucketed on a grid, for segment–outline tests.
#[derive(Clone, Debug, Default)]
struct EdgeGrid {
    origin: Point,
    columns: usize,
    rows: usize,
    cells: Vec<Vec<u32>>,
    edges: Vec<[Point; 2]>,
}

impl EdgeGrid {
    fn new<'a>(rings: impl Iterator<Item = &'a [Point]>) -> EdgeGrid {
        let mut edges = Vec::new();
        for ring in rings {
            let n = ring.len();
            edges.extend((0..n).map(|i| [ring[i], ring[(i + 1) % n]]));
        }
        if edges.is_empty() {
            return EdgeGrid::default();
        }
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for p in edges.iter().flatten() {
            lo = [lo[0].min(p.x), lo[1].min(p.y)];
            hi = [hi[0].max(p.x), hi[1].max(p.y)];
        }
        let columns = ((hi[0] - lo[0]) / EDGE_CELL_PX) as usize + 1;
        let rows = ((hi[1] - lo[1]) / EDGE_CELL_PX) as usize + 1;
        let mut grid = EdgeGrid {
            origin: lo.into(),
            columns,
            rows,
            cells: vec![Vec::new(); columns * rows],
            edges: Vec::new(),
        };
        for (k, e) in edges.iter().enumerate() {
            let [c0, r0, c1, r1] = grid.cell_box(e[0], e[1], 0.0);
            for r in r0..=r1 {
                for c in c0..=c1 {
                    grid.cells[r * columns + c].push(k as u32);
                }
            }
        }
        grid.edges = edges;
        grid
    }

    /// The cells (clamped to the grid) covering the box of `a`–`b` grown by `grow`:
    /// [c0, r0, c1, r1].
    fn cell_box(&self, a: Point, b: Point, grow: f64) -> [usize; 4] {
        let cell = |v: f64, o: f64, n: usize| {
            (((v - o) / EDGE_CELL_PX).floor().max(0.0) as usize).min(n - 1)
        };
        [
            cell(a.x.min(b.x) - grow, self.origin.x, self.columns),
            cell(a.y.min(b.y) - grow, self.origin.y, self.rows),
            cell(a.x.max(b.x) + grow, self.origin.x, self.columns),
            cell(a.y.max(b.y) + grow, self.origin.y, self.rows),
        ]
    }

    /// Whether an edge comes within `clearance` of segment `a`–`b` (or touches it).
    fn near_segment(&self, a: Point, b: Point, clearance: f64) -> bool {
        if self.edges.is_empty() {
            return false;
        }
        // Walk the segment in steps shorter than a cell, testing the cells of each step's box.
        let steps = ((b - a).norm() / (0.5 * EDGE_CELL_PX)).ceil().max(1.0) as usize;
        let mut tested: Vec<u32> = Vec::new();
        for s in 0..steps {
            let p = a + (b - a) * (s as f64 / steps as f64);
            let q = a + (b - a) * ((s + 1) as f64 / steps as f64);
            let [c0, r0, c1, r1] = self.cell_box(p, q, clearance);
            for r in r0..=r1 {
                for c in c0..=c1 {
                    for &k in &self.cells[r * self.columns + c] {
                        if tested.contains(&k) {
                            continue;
                        }
                        let e = self.edges[k as usize];
                        if crate::geom::segments_touch(a, b, e[0], e[1])
                            || segment_gap(a, b, e[0], e[1]) < clearance
                        {
                            return true;
                        }
                        tested.push(k);
                    }
                }
            }
            if tested.len() > 256 {
                tested.clear();
            }
        }
        false
    }
}

/// The distance between segments `a`–`b` and `c`–`d` when they do not cross (the smallest
/// distance from an endpoint of one to the other).
fn segment_gap(a: Point, b: Point, c: Point, d: Point) -> f64 {
    let to = crate::geom::point_segment_distance;
    to(a, c, d)
        .min(to(b, c, d))
        .min(to(c, a, b))
        .min(to(d, a, b))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn the_union_places_each_layer_at_its_offset_and_drops_what_is_off_the_canvas() {
        let whole = RgbaImage::from_fn(8, 6, |x, _| image::Rgba([0, 0, 0, x as u8 * 10]));
        let small = RgbaImage::from_pixel(3, 3, image::Rgba([9, 9, 9, 200]));
        let layers = [
            super::super::LayerRef::whole("whole", &whole),
            super::super::LayerRef {
                name: "small",
                image: &small,
                offset_px: [6, -1],
                canvas_px: [8, 6],
            },
        ];
        let union = union_alpha(&layers);
        assert_eq!(union.dimensions(), (8, 6));
        for (x, y, p) in union.enumerate_pixels() {
            let covered = x >= 6 && y <= 1;
            let expected = if covered { 200 } else { x as u8 * 10 };
            assert_eq!(p[3], expected, "({x}, {y})");
            assert_eq!(p.0[..3], [0, 0, 0], "colour is not used");
        }
    }

    /// The axis-aligned rectangle (x0, y0)–(x1, y1): its four corners from (x0, y0) along x first.
    pub(crate) fn square(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<Point> {
        vec![
            Point::new(x0, y0),
            Point::new(x1, y0),
            Point::new(x1, y1),
            Point::new(x0, y1),
        ]
    }

    #[test]
    fn a_ring_with_a_hole_fills_and_answers_segments() {
        let outline = Outline {
            outer: square(2.0, 2.0, 30.0, 30.0),
            holes: vec![square(10.0, 10.0, 20.0, 20.0)],
        };
        let shape = Shape::from_outlines(vec![outline], 40, 40);
        // 28² pixels minus the 10² hole.
        assert_eq!(shape.area_px2, 28.0 * 28.0 - 100.0);
        assert!(shape.pixel_inside(Point::new(5.5, 5.5)));
        assert!(!shape.pixel_inside(Point::new(15.5, 15.5)));
        assert!(shape.segment_inside(Point::new(4.0, 4.0), Point::new(28.0, 4.0)));
        // Through the hole.
        assert!(!shape.segment_inside(Point::new(4.0, 15.0), Point::new(28.0, 15.0)));
        // Out of the shape.
        assert!(!shape.segment_inside(Point::new(4.0, 4.0), Point::new(35.0, 4.0)));
    }
}
