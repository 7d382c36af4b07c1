//! Rasterizes the bundled demo character.
//!
//! Reads `assets/character/layers.json` (relative to this crate's manifest directory),
//! renders every `assets/character/src/<layer>.svg` onto the shared canvas into
//! `assets/character/<layer>.png` (RGBA, straight alpha, antialiased), and composites all
//! layers back to front (source-over) into `assets/character/flat.png`. The `attachments` of
//! `layers.json` (other images a layer's slot can show) get their PNGs but stay out of the
//! composite.
//!
//! Output is deterministic: same inputs, same bytes.
//!
//! Run with:
//! `CARGO_TARGET_DIR=/work/assets-target cargo run --release --manifest-path tools/make-assets/Cargo.toml`

use std::error::Error;
use std::fs;
use std::path::{Path, PathBuf};

use resvg::tiny_skia::{Pixmap, PixmapPaint, Transform};
use resvg::usvg;

type Result<T> = std::result::Result<T, Box<dyn Error>>;

fn character_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/character");
    dir.canonicalize().unwrap_or(dir)
}

struct Manifest {
    width: u32,
    height: u32,
    layers: Vec<String>,
    /// Other attachments of the layers' slots (name → slot): rendered, not composited.
    attachments: Vec<String>,
}

fn read_manifest(path: &Path) -> Result<Manifest> {
    let text = fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text)?;
    let canvas = v["canvas"]
        .as_array()
        .filter(|a| a.len() == 2)
        .ok_or("layers.json: \"canvas\" must be [width, height]")?;
    let dim = |i: usize| -> Result<u32> {
        let n = canvas[i].as_u64().ok_or("layers.json: canvas size must be integers")?;
        Ok(u32::try_from(n)?)
    };
    let layers = v["layers"]
        .as_array()
        .ok_or("layers.json: \"layers\" must be an array of names")?
        .iter()
        .map(|l| l.as_str().map(str::to_owned).ok_or("layers.json: layer names must be strings"))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let attachments = match v.get("attachments") {
        None => Vec::new(),
        Some(a) => a
            .as_object()
            .ok_or("layers.json: \"attachments\" must map names to slots")?
            .keys()
            .cloned()
            .collect(),
    };
    Ok(Manifest { width: dim(0)?, height: dim(1)?, layers, attachments })
}

fn render_layer(svg_path: &Path, width: u32, height: u32) -> Result<Pixmap> {
    let data = fs::read(svg_path).map_err(|e| format!("{}: {e}", svg_path.display()))?;
    let opt = usvg::Options::default();
    let tree = usvg::Tree::from_data(&data, &opt).map_err(|e| format!("{}: {e}", svg_path.display()))?;
    let size = tree.size();
    if size.width() != width as f32 || size.height() != height as f32 {
        return Err(format!(
            "{}: canvas is {}x{}, layers.json says {width}x{height}",
            svg_path.display(),
            size.width(),
            size.height()
        )
        .into());
    }
    let mut pixmap = Pixmap::new(width, height).ok_or("bad canvas size")?;
    resvg::render(&tree, Transform::identity(), &mut pixmap.as_mut());
    Ok(pixmap)
}

fn main() -> Result<()> {
    let dir = character_dir();
    let manifest = read_manifest(&dir.join("layers.json"))?;
    let (w, h) = (manifest.width, manifest.height);

    let mut flat = Pixmap::new(w, h).ok_or("bad canvas size")?;
    for name in &manifest.layers {
        let layer = render_layer(&dir.join("src").join(format!("{name}.svg")), w, h)?;
        // encode_png un-premultiplies: the PNG holds straight alpha.
        let out = dir.join(format!("{name}.png"));
        fs::write(&out, layer.encode_png()?)?;
        println!("wrote {}", out.display());
        flat.draw_pixmap(0, 0, layer.as_ref(), &PixmapPaint::default(), Transform::identity(), None);
    }
    // Attachments swap in for a layer: their own PNGs, not part of the composite.
    for name in &manifest.attachments {
        let layer = render_layer(&dir.join("src").join(format!("{name}.svg")), w, h)?;
        let out = dir.join(format!("{name}.png"));
        fs::write(&out, layer.encode_png()?)?;
        println!("wrote {}", out.display());
    }
    let out = dir.join("flat.png");
    fs::write(&out, flat.encode_png()?)?;
    println!("wrote {}", out.display());
    Ok(())
}
