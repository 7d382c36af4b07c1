//! Deformed textured meshes → pixels, with tiny-skia.
//!
//! In: a canvas `Pixmap` (premultiplied RGBA), and per part a texture (premultiplied), the
//! mesh's rest positions in texture pixels, its deformed positions in canvas pixels and its
//! triangles. Out: the parts composited source-over in order, with bilinear sampling,
//! antialiased outer edges and no seams between adjacent triangles.

use crate::geom::Point;

/// The per-mesh state rendering needs that does not change between frames.
pub struct MeshRenderer {
    _private: (),
}

impl MeshRenderer {
    /// Precomputes what drawing needs from the mesh's connectivity and rest positions
    /// (`uv_px`: texture pixels).
    pub fn new(uv_px: &[Point], triangles: &[[u32; 3]]) -> Self {
        let _ = (uv_px, triangles);
        todo!("render: being written")
    }
}
