//! Files: the native rig document, images, animation sequences, and atomic writes.

pub mod atomic;
pub mod confine;
pub mod document;
pub mod image;
pub mod layered;
pub mod outputs;
pub mod sequence;
pub mod set;
pub mod slots;

pub use atomic::write_atomic;
pub use confine::{confined, PathError};
pub use document::{
    AutorigRecord, BuildOptions, DocumentError, JsonLayout, MeshDoc, PartDoc, PartImages,
    RecordedTemplate, RigDocument, RuntimeTarget, SavedRig, WeightsDoc,
};
pub use image::{load_png, save_png, ImageError};
pub use slots::{Skin, Skins, SlotError};
