//! Outlines → triangle mesh.
