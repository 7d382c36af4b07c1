//! Documents for the document and painting tests: a bar sprite, bones along it, a rig build.

use image::{Rgba, RgbaImage};
use sinew::document::{compute_rig, Command, Document};
use sinew::pipeline::Layer;
use sinew::rig::Bone;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// An opaque 300 × 40 px bar on a 320 × 80 canvas, named `name`, its path `dir/NAME.png`
/// (written there when `save` is set).
pub fn bar_layer(name: &str, dir: &Path, save: bool) -> Layer {
    let image = RgbaImage::from_fn(320, 80, |x, y| {
        if (10..310).contains(&x) && (20..60).contains(&y) {
            Rgba([90, 140, 200, 255])
        } else {
            Rgba([0, 0, 0, 0])
        }
    });
    let path = dir.join(format!("{name}.png"));
    if save {
        image.save(&path).expect("the bar's PNG written");
    }
    Layer::whole(name, path, image)
}

pub fn bone(name: &str, parent: Option<&str>, head: [f64; 2], tail: [f64; 2]) -> Bone {
    Bone {
        name: name.into(),
        parent: parent.map(Into::into),
        head: head.into(),
        tail: tail.into(),
    }
}

/// Computes the weights of the document's current inputs and installs them.
pub fn compute(doc: &mut Document) {
    let inputs = doc.rig_inputs();
    let scene = compute_rig(
        &inputs,
        &std::env::temp_dir(),
        &AtomicBool::new(false),
        &mut |_, _| {},
    )
    .unwrap();
    doc.apply(Command::SetRig(
        std::sync::Arc::new(scene),
        Box::new(inputs.key()),
    ))
    .unwrap();
}
