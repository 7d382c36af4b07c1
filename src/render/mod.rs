//! Deformed textured meshes → pixels, with a scanline rasterizer of our own.
//!
//! In: a canvas `Pixmap` (premultiplied RGBA8) and, per part, a [`Texture`] (premultiplied),
//! the mesh's rest vertex positions in texture pixels (`uv_px`), its triangles, and per frame
//! its deformed vertex positions in world pixels (the rig's canvas pixels), a [`Tint`] and a
//! visibility flag, plus a `canvas_from_world` transform for the view ([`draw_parts`] takes a
//! list of [`PartDraw`]s in the caller's order). Out: each part composited source-over onto the
//! canvas with bilinear sampling, antialiased outer edges, no seams between adjacent triangles
//! and no snapping of sub-pixel positions. Pixel (i, j) covers [i, i+1) × [j, j+1) in every
//! space, as in tiny-skia. The output is a pure function of the inputs: integer arithmetic
//! decides ownership and blending, and nothing depends on the thread count.
//!
//! How a part is drawn ([`MeshRenderer::draw`]):
//!
//! 1. Coverage ([`coverage`]): the part's boundary loops (non-zero winding, so holes stay holes
//!    and a mirrored or folded part still counts as inside) give each pixel of the part's
//!    bounding box the exact fraction of its area inside the part, by signed-area accumulation.
//! 2. Triangles ([`raster`]): each triangle owns the pixels whose centers lie inside it, decided
//!    in fixed point (1/256 px) with a tie rule that gives every center on a shared edge or
//!    vertex to exactly one triangle, so adjacent triangles neither overlap nor leave a seam.
//!    Each owned pixel samples the texture bilinearly ([`texture`]) at its center mapped through
//!    the triangle's affine map (texture coordinates stay in `f64` until the per-row fixed-point
//!    stepping, so placement is exact to 1/256 texel), is scaled by its coverage and the tint and
//!    blended source-over ([`blend`]), and its coverage is then cleared, so that nothing draws
//!    it twice.
//! 3. Skirts ([`skirt`]): pixels partly covered by the part but whose centers lie just outside
//!    it get their colour from a band 1 px wide outside each boundary edge, drawn the same way
//!    with the map of the edge's triangle extended past the edge.
//!
//! Why not tiny-skia per triangle, as before: its per-fill set-up (path, edge list, pipeline
//! compilation) costs about a microsecond per triangle and its `f32` bilinear pipeline tens of
//! nanoseconds per pixel, where the bundled character has 16k triangles; and an antialiased
//! mask per part layer plus a compositing pass cost a pass over the whole bounding box each.
//! tiny-skia still draws the wireframe overlays and holds the canvas.
//!
//! Limits: at convex corners sharper than ~29° the skirt's mitre is capped, so the extreme tip
//! can lose a little antialiased coverage; triangles of (near) zero area in texture or output
//! space are skipped; where triangles of one part overlap (a fold) the one listed last shows;
//! canvas coordinates must stay within ±2²⁰ px.

mod blend;
mod compare;
mod convert;
mod coverage;
mod frame;
mod mesh_renderer;
mod pixel_math;
mod raster;
mod skirt;
mod texture;
mod topology;
mod wireframe;

#[cfg(test)]
mod test_support;

pub use blend::Tint;
pub use compare::{
    max_channel_diff, max_channel_diff_where, premultiplied, psnr_premultiplied, psnr_rgba,
};
pub use convert::{pixmap_from_rgba, rgba_from_pixmap};
pub use frame::{draw_parts, PartDraw, RenderPart};
pub use mesh_renderer::MeshRenderer;
pub use skirt::SKIRT_PX;
pub use texture::Texture;
pub use wireframe::draw_wireframe;

/// Why a mesh, an image or a frame cannot be rendered.
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
    /// An image with no pixels.
    #[error("the image is empty ({width}×{height} px)")]
    EmptyImage { width: u32, height: u32 },
    /// A draw names a part the frame was not given.
    #[error("part {part} does not exist (there are {parts} parts)")]
    UnknownPart { part: usize, parts: usize },
    /// A draw brings a different number of positions than its part's mesh has vertices.
    #[error("part {part}: {got} vertex positions for a mesh of {expected} vertices")]
    PositionCount {
        part: usize,
        got: usize,
        expected: usize,
    },
}
