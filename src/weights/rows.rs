//! Checks that the weight editors ([`super::paint`], [`super::locked`]) run on their inputs.
//!
//! In: sparse weight rows (per vertex, `(column, weight)` pairs), a column count, a mesh's
//! triangles and vertex count. Out: `Ok(())`, or the first [`RowsError`] found.

/// Rows or a mesh that do not fit together.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RowsError {
    #[error("{rows} weight rows for {vertices} mesh vertices")]
    RowCount { rows: usize, vertices: usize },
    #[error("vertex {vertex} has a weight in column {column} of {columns}")]
    Column {
        vertex: usize,
        column: u32,
        columns: usize,
    },
    #[error("triangle {triangle} uses vertex {vertex} of {vertices}")]
    Triangle {
        triangle: usize,
        vertex: u32,
        vertices: usize,
    },
}

/// One row per mesh vertex.
pub fn check_row_count(rows: &[Vec<(u32, f64)>], vertices: usize) -> Result<(), RowsError> {
    if rows.len() != vertices {
        return Err(RowsError::RowCount {
            rows: rows.len(),
            vertices,
        });
    }
    Ok(())
}

/// Every weight in a column below `columns`.
pub fn check_columns(rows: &[Vec<(u32, f64)>], columns: usize) -> Result<(), RowsError> {
    for (vertex, row) in rows.iter().enumerate() {
        if let Some(&(column, _)) = row.iter().find(|(c, _)| *c as usize >= columns) {
            return Err(RowsError::Column {
                vertex,
                column,
                columns,
            });
        }
    }
    Ok(())
}

/// Every triangle's corners among the `vertices` mesh vertices.
pub fn check_triangles(triangles: &[[u32; 3]], vertices: usize) -> Result<(), RowsError> {
    for (triangle, t) in triangles.iter().enumerate() {
        if let Some(&vertex) = t.iter().find(|&&v| v as usize >= vertices) {
            return Err(RowsError::Triangle {
                triangle,
                vertex,
                vertices,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reports_the_first_misfit() {
        let rows = vec![vec![(0, 0.5), (1, 0.5)], vec![(3, 1.0)]];
        assert_eq!(check_row_count(&rows, 2), Ok(()));
        assert_eq!(
            check_row_count(&rows, 3),
            Err(RowsError::RowCount {
                rows: 2,
                vertices: 3
            })
        );
        assert_eq!(check_columns(&rows, 4), Ok(()));
        assert_eq!(
            check_columns(&rows, 2),
            Err(RowsError::Column {
                vertex: 1,
                column: 3,
                columns: 2
            })
        );
        assert_eq!(check_triangles(&[[0, 1, 2]], 3), Ok(()));
        assert_eq!(
            check_triangles(&[[0, 1, 2], [2, 1, 5]], 3),
            Err(RowsError::Triangle {
                triangle: 1,
                vertex: 5,
                vertices: 3
            })
        );
    }
}
