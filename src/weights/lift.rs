//! The content-aware lift: a mesh measured in (x, y, s·r, s·g, s·b) instead of (x, y).
//!
//! In: vertex positions (canvas px), one color per vertex (RGB in [0, 1]) and the scale `s`
//! (px per unit of color). Out: the lifted 5D points, or directly the [`Domain`] (cotangent
//! stiffness and mass) measured on them.
//!
//! Jacobson, Baran, Popović & Sorkine 2011 (§ "content-aware weights") and Jacobson's thesis
//! (2013, § 3.4, colorization): an edge across a color change is long in 5D, so weights diffuse
//! along flat areas and barely across edges of the image. A full change of one channel counts as
//! `s` px. Skinning (`weights::part`, `sinew rig --content-aware S`) and scribble colorization
//! (`colorize`) both build their domain here, so the two cannot drift apart.

use super::solve::Domain;
use crate::geom::Point;

/// What is wrong with a lift request.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum LiftError {
    #[error("the content-aware scale must be finite and non-negative, not {0}")]
    InvalidScale(f64),
    #[error("{0} colors for {1} mesh vertices")]
    ColorCount(usize, usize),
}

/// The points (x, y, s·r, s·g, s·b), one per vertex.
pub fn lift_points(
    positions: &[Point],
    colors: &[[f64; 3]],
    scale: f64,
) -> Result<Vec<[f64; 5]>, LiftError> {
    if !(scale.is_finite() && scale >= 0.0) {
        return Err(LiftError::InvalidScale(scale));
    }
    if colors.len() != positions.len() {
        return Err(LiftError::ColorCount(colors.len(), positions.len()));
    }
    Ok(positions
        .iter()
        .zip(colors)
        .map(|(p, c)| [p.x, p.y, scale * c[0], scale * c[1], scale * c[2]])
        .collect())
}

/// The weight domain of the mesh measured on its lifted points.
pub fn content_aware_domain(
    positions: &[Point],
    colors: &[[f64; 3]],
    scale: f64,
    triangles: &[[u32; 3]],
) -> Result<Domain, LiftError> {
    Ok(Domain::new(
        &lift_points(positions, colors, scale)?,
        triangles,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_color_edge_weakens_the_stiffness_across_it() {
        // Two triangles sharing the edge 1–2; vertex 3 has another color.
        let positions = [
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(0.0, 1.0),
            Point::new(1.0, 1.0),
        ];
        let triangles = [[0, 1, 2], [1, 3, 2]];
        let flat = Domain::planar(&positions, &triangles);
        let same = content_aware_domain(&positions, &[[0.5; 3]; 4], 100.0, &triangles).unwrap();
        // One color everywhere: the lift changes nothing.
        assert_eq!(flat.stiffness.to_dense(), same.stiffness.to_dense());
        let colors = [[1.0; 3], [1.0; 3], [1.0; 3], [0.0; 3]];
        let lifted = content_aware_domain(&positions, &colors, 100.0, &triangles).unwrap();
        // The coupling between vertex 3 and the others (−K off the diagonal) shrinks.
        let coupling = |d: &Domain| -d.stiffness.get(3, 1).copied().unwrap_or(0.0);
        assert!(coupling(&lifted) < 0.1 * coupling(&flat));
    }

    #[test]
    fn bad_requests_are_errors() {
        assert!(matches!(
            lift_points(&[Point::new(0.0, 0.0)], &[[0.0; 3]], f64::NAN),
            Err(LiftError::InvalidScale(_))
        ));
        assert!(matches!(
            lift_points(&[Point::new(0.0, 0.0)], &[[0.0; 3]], -1.0),
            Err(LiftError::InvalidScale(_))
        ));
        assert_eq!(
            lift_points(&[Point::new(0.0, 0.0)], &[], 1.0),
            Err(LiftError::ColorCount(0, 1))
        );
    }
}
