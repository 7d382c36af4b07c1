//! The art a rig is made from: PNG layers (each covering the whole canvas) and layered files
//! (PSD/PSB, OpenRaster, a Spine script's JSON + trimmed PNGs, see [`crate::io::layered`]),
//! in any mix, as the pipeline's [`Layer`]s.
//!
//! In: paths in draw order (back to front) and the folder where a layered file's parts will be
//! written ([`ArtOptions::parts_dir`]). Out: [`Art`]: one [`Layer`] per PNG and per visible pixel
//! layer of a layered file (named by its group path, `arm_l/hand`; its image the layer's pixels
//! on the canvas with its opacity, trimmed to the opaque ones and placed at their offset, so a
//! small layer on a big canvas stays small), the notes a person should read (skipped layers),
//! and which layers still have to be written ([`Art::write_parts`]) before a document may refer
//! to them. Hidden layers do not become parts (a note says so).

use crate::io::layered::{self, LayeredFormat, LayeredLimits};
use crate::io::{self, ImageError};
use crate::pipeline::{checked_layers, Layer, PipelineError};
use std::path::{Path, PathBuf};

/// Where layered files' parts go, and the limits their reading obeys.
#[derive(Clone, Debug, Default)]
pub struct ArtOptions {
    /// Folder for the part images of layered files: `PARTS_DIR/arm_l/hand.png`. The command
    /// line uses `RIG.parts` beside the rig document it writes.
    pub parts_dir: PathBuf,
    pub limits: LayeredLimits,
}

/// Layers ready for the pipeline.
#[derive(Clone, Debug)]
pub struct Art {
    pub layers: Vec<Layer>,
    /// One line each: what was skipped or drawn differently, naming the layer and file.
    pub notes: Vec<String>,
    /// Indices into `layers` of the images to write (those from layered files).
    pub unwritten: Vec<usize>,
    /// Bone origins marked in the layered files (pivot layers), canvas px.
    pub pivots: Vec<layered::Pivot>,
}

impl Art {
    /// The files [`Art::write_parts`] will write.
    pub fn part_paths(&self) -> impl Iterator<Item = &Path> {
        self.unwritten
            .iter()
            .map(|&i| self.layers[i].path.as_path())
    }

    /// The images of the layers from layered files as PNG files to write (path, bytes): what
    /// [`Art::write_parts`] writes, or what a rig document is written with
    /// ([`crate::io::PartImages::pending`]).
    pub fn part_files(&self) -> Result<Vec<(PathBuf, Vec<u8>)>, ImageError> {
        self.unwritten
            .iter()
            .map(|&i| {
                let layer = &self.layers[i];
                let bytes =
                    io::image::encode_png(&layer.image).map_err(|e| ImageError::Encode {
                        path: layer.path.clone(),
                        reason: e.to_string(),
                    })?;
                Ok((layer.path.clone(), bytes))
            })
            .collect()
    }

    /// Writes the images of the layers from layered files as one set (`io::atomic::write_set`:
    /// all written to temporaries, then renamed; a failure leaves none), creating their
    /// folders. Returns the paths written.
    pub fn write_parts(&self) -> Result<Vec<PathBuf>, ImageError> {
        let files = self.part_files()?;
        for (path, _) in &files {
            if let Some(dir) = path.parent() {
                std::fs::create_dir_all(dir).map_err(|source| ImageError::Write {
                    path: path.clone(),
                    source,
                })?;
            }
        }
        io::atomic::write_set(&files)
            .map_err(|(path, source)| ImageError::Write { path, source })?;
        Ok(files.into_iter().map(|(path, _)| path).collect())
    }
}

/// Whether `path` names a layered file by its extension (`.psd`, `.psb`, `.ora`, `.json`).
pub fn is_layered(path: &Path) -> bool {
    LayeredFormat::of(path).is_some()
}

/// The image file of the part at `layer_path` under `parts_dir` (one definition, beside the
/// rig document's self-contained writing).
pub use crate::io::document::part_image_path;

/// Loads PNG layers and layered files as the layers of one canvas (see the module docs).
pub fn load_art(paths: &[PathBuf], options: &ArtOptions) -> Result<Art, PipelineError> {
    let mut layers = Vec::new();
    let mut notes = Vec::new();
    let mut unwritten = Vec::new();
    let mut pivots = Vec::new();
    for path in paths {
        if !is_layered(path) {
            let name = path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            layers.push(Layer::whole(name, path.clone(), io::load_png(path)?));
            continue;
        }
        let file = layered::load_layered(path, &options.limits)?;
        pivots.extend(file.pivots.iter().cloned());
        let shown = path.display();
        notes.extend(file.warnings.iter().map(|w| format!("{shown}: {w}")));
        let (mut hidden, mut outside) = (0, 0);
        let before = layers.len();
        for l in &file.layers {
            if !l.visible {
                notes.push(format!("{shown}: layer '{}' is hidden; not a part", l.path));
                hidden += 1;
                continue;
            }
            let Some((image, offset_px)) = layered::part_image(l, file.canvas_px) else {
                notes.push(format!(
                    "{shown}: layer '{}' lies outside the canvas or is fully transparent; not a part",
                    l.path
                ));
                outside += 1;
                continue;
            };
            unwritten.push(layers.len());
            layers.push(Layer {
                name: l.path.clone(),
                path: part_image_path(&options.parts_dir, &l.path),
                image,
                offset_px,
                canvas_px: file.canvas_px,
            });
        }
        if layers.len() == before {
            return Err(PipelineError::NoVisibleLayers {
                path: path.clone(),
                hidden,
                outside,
            });
        }
    }
    Ok(Art {
        layers: checked_layers(layers)?,
        notes,
        unwritten,
        pivots,
    })
}
