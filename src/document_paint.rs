//! Painting weights in a [`super::Document`]: the part's rest mesh and weights a brush works on,
//! and one stroke applied as a command.

use super::*;

/// The weight columns of `part` in the current rig with their locked flags, and the rig.
pub fn part_weights_for_painting<'a>(
    state: &'a State,
    part: &str,
) -> Result<(&'a Arc<Scene>, usize, Vec<bool>), DocumentError> {
    let scene = state
        .rig
        .as_ref()
        .filter(|_| state.rig_current && !state.handles.is_empty())
        .ok_or(DocumentError::NoWeights)?;
    let index = scene
        .doc
        .parts
        .iter()
        .position(|p| p.name == part)
        .ok_or_else(|| DocumentError::UnknownLayer(part.to_string()))?;
    let weights = scene.doc.parts[index]
        .weights
        .as_ref()
        .ok_or(DocumentError::NoWeights)?;
    let locked = pipeline::locked_columns(&state.handles, &state.locked, &weights.handles);
    Ok((scene, index, locked))
}

/// The rig after one stroke of [`Command::PaintWeights`].
pub(super) fn paint_weights(
    state: &State,
    part: &str,
    handle: &str,
    mode: BrushMode,
    samples_px: &[Point],
    options: &BrushOptions,
) -> Result<Scene, DocumentError> {
    let (scene, index, locked) = part_weights_for_painting(state, part)?;
    let part_doc = &scene.doc.parts[index];
    let Some(weights) = &part_doc.weights else {
        return Err(DocumentError::NoWeights);
    };
    let column = weights
        .handles
        .iter()
        .position(|h| h == handle)
        .ok_or_else(|| DocumentError::UnknownHandle(handle.to_string()))?;
    if locked[column] {
        return Err(DocumentError::LockedHandle(handle.to_string()));
    }
    let mesh = PaintMesh::new(&part_doc.mesh.vertices, &part_doc.mesh.triangles)?;
    let mut rows = weights.rows.clone();
    let limit = scene.doc.options.weights.max_influences;
    let report = crate::weights::paint_stroke(
        &mesh,
        &mut rows,
        &PaintTarget {
            column,
            locked: &locked,
            max_influences: limit,
        },
        mode,
        samples_px,
        options,
    )?;
    // A stroke that changed nothing is no undo step.
    if report.vertex_changes == 0 {
        return Err(DocumentError::NothingPainted {
            at_limit: report.at_limit,
            limit,
        });
    }
    let painted = crate::io::WeightsDoc {
        handles: weights.handles.clone(),
        rows,
    };
    Ok(scene.with_part_weights(index, painted)?)
}
