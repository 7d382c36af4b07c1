//! Deformed textured meshes → pixels, with tiny-skia.
//!
//! In: a canvas `Pixmap` (premultiplied RGBA) and, per part, a texture (premultiplied
//! `Pixmap`), the mesh's rest vertex positions in texture pixels (`uv_px`), its triangles, and
//! per frame its deformed vertex positions in world pixels (the rig's canvas pixels) plus a
//! `canvas_from_world` transform for the view. Out: the part composited source-over onto the
//! canvas with bilinear sampling, antialiased outer edges and no seams between adjacent
//! triangles. Pixel (i, j) covers [i, i+1) × [j, j+1) in every space, as in tiny-skia.
//!
//! How a part is drawn ([`MeshRenderer::draw`]):
//!
//! 1. Each part is painted into its own scratch layer the size of the part's bounding box
//!    (clipped to the canvas), not straight onto the canvas. Every triangle is filled without
//!    antialiasing, with a `Pattern` shader carrying the triangle's affine texture → output map
//!    and `BlendMode::Source`. Non-antialiased fills sample pixel centers, and adjacent
//!    triangles share their edge's exact coordinates, so the triangles partition the pixel
//!    centers and no seam can appear (antialiased triangles would each cover a shared edge
//!    pixel partially, and 1 - (1 - a)(1 - b) < 1 leaves a hairline).
//! 2. Before the triangles, a "skirt" quad is filled outward from every boundary edge
//!    ([`SKIRT_PX`] wide, mitred at the vertices so the skirts of adjacent edges meet) with
//!    the affine map of the edge's triangle extended past the edge. Pixels whose center lies
//!    just outside the mesh but whose area is partly inside it thereby get texture colour.
//! 3. An antialiased `Mask` of the deformed boundary loops (non-zero winding, so holes stay
//!    holes and a mirrored or folded part still counts as inside) gives each pixel's coverage.
//! 4. The layer, times coverage and opacity, is composited source-over onto the canvas once.
//!
//! Why a layer rather than drawing triangles straight onto the canvas: tiny-skia needs a mask
//! the size of the target pixmap, so a layer keeps the mask as small as the part; `Source`
//! fills make skirts that overlap triangles (at concave corners) and triangles that overlap
//! each other (folds) replace rather than accumulate, so no pixel is blended twice; and
//! opacity applies to the part as a whole, as a paint program applies layer opacity.
//!
//! Limits: at convex corners sharper than ~29° the skirt's mitre is capped, so the extreme tip
//! can lose a little antialiased coverage; triangles of (near) zero area in texture or output
//! space are skipped. Cost is dominated by tiny-skia's per-pixel bilinear sampling (its `f32`
//! pipeline): a few tens of ns per covered pixel, plus on the order of a microsecond of set-up per
//! triangle; the layer and mask cost one allocation each per part and frame.

mod compare;
mod composite;
mod convert;
mod mesh_renderer;
mod pixel_math;
mod topology;
mod wireframe;

#[cfg(test)]
mod test_support;

pub use compare::{max_channel_diff, max_channel_diff_where, psnr_premultiplied, psnr_rgba};
pub use convert::{pixmap_from_rgba, rgba_from_pixmap};
pub use mesh_renderer::{MeshRenderer, SKIRT_PX};
pub use wireframe::draw_wireframe;

/// Why a mesh or image cannot be rendered.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RenderError {
    /// The mesh has no vertices or no triangles.
    #[error("the mesh is empty ({vertices} vertices, {triangles} triangles)")]
    EmptyMesh { vertices: usize, triangles: usize },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "triangle {triangle} refers to vertex {index}, but the mesh has {vertex_count} vertices"
    )]
    TriangleIndexOutOfRange {
        triangle: usize,
        index: u32,
        vertex_count: usize,
    },
    /// A rest vertex position is NaN or infinite.
    #[error("vertex {vertex} has a non-finite texture position")]
    NonFiniteCoordinate { vertex: usize },
    /// An image with no pixels, which a tiny-skia `Pixmap` cannot hold.
    #[error("the image is empty ({width}×{height} px)")]
    EmptyImage { width: u32, height: u32 },
}
