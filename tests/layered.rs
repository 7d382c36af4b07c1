//! Layered art written by real tools (tests/fixtures/layered, made by
//! tools/layered-fixtures/run.sh: psd-tools and Krita): sinew's reading of each file, flattened,
//! against the tool's own flattened image of the same file; and hostile files refused.

use image::RgbaImage;
use sinew::io::layered::{
    self, composite, ora, psd, LayeredError, LayeredImage, LayeredLimits, TreeNode,
};
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/layered")
        .join(name)
}

fn load(name: &str) -> LayeredImage {
    layered::load_layered(&fixture(name), &LayeredLimits::default())
        .unwrap_or_else(|e| panic!("{e}"))
}

fn png(name: &str) -> RgbaImage {
    image::open(fixture(name)).expect(name).into_rgba8()
}

/// Max difference of premultiplied channels (colour under zero alpha does not count) and the
/// PSNR (dB) over the canvas, between `a` and `b`.
fn compare(a: &RgbaImage, b: &RgbaImage) -> (u8, f64) {
    assert_eq!(a.dimensions(), b.dimensions(), "canvas sizes");
    let pre = |p: &image::Rgba<u8>, c: usize| {
        if c == 3 {
            p[3] as f64
        } else {
            p[c] as f64 * p[3] as f64 / 255.0
        }
    };
    let (mut max, mut se, mut n) = (0.0f64, 0.0, 0.0);
    for (p, q) in a.pixels().zip(b.pixels()) {
        for c in 0..4 {
            let d = (pre(p, c) - pre(q, c)).abs();
            max = max.max(d);
            se += d * d;
            n += 1.0;
        }
    }
    let mse = se / n;
    let psnr = if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    };
    (max.round() as u8, psnr)
}

fn paths(img: &LayeredImage) -> Vec<(&str, bool)> {
    img.layers
        .iter()
        .map(|l| (l.path.as_str(), l.visible))
        .collect()
}

const CHARACTER: [(&str, bool); 6] = [
    ("torso", true),
    ("arm_l/upper", true),
    ("arm_l/hand", true),
    ("head", true),
    ("leaf", true),
    ("sketch", false),
];

#[test]
fn psd_tools_psd_matches_psd_tools_composite() {
    let img = load("character.psd");
    assert_eq!(img.canvas_px, [120, 160]);
    assert_eq!(paths(&img), CHARACTER);
    let head = &img.layers[3];
    assert!((head.opacity - 200.0 / 255.0).abs() < 1e-6);
    // Trimmed to the drawn pixels (a 44 px image whose shape leaves a 1 px margin).
    assert_eq!(head.offset_px, [39, 9]);
    assert_eq!(head.image.dimensions(), (42, 42));
    // Half off the canvas: the pixels left of it are kept.
    assert_eq!(img.layers[4].offset_px[0], -11);
    assert!(
        matches!(&img.tree[1], TreeNode::Group { name, children, .. }
        if name == "arm_l" && children.len() == 2)
    );
    assert!(img.warnings.is_empty(), "{:?}", img.warnings);
    let (max, psnr) = compare(&composite(&img), &png("character.composite.png"));
    println!("character.psd vs psd-tools composite: max diff {max}, PSNR {psnr:.1} dB");
    assert!(
        max <= 2 && psnr >= 40.0,
        "max diff {max}, PSNR {psnr:.1} dB"
    );
}

#[test]
fn psb_reads_as_its_psd() {
    let psd = load("character.psd");
    let psb = load("character.psb");
    assert_eq!(psd, psb);
}

#[test]
fn grayscale_psd_matches_psd_tools_composite() {
    let img = load("gray.psd");
    assert_eq!(paths(&img), CHARACTER);
    let (max, psnr) = compare(&composite(&img), &png("gray.composite.png"));
    println!("gray.psd vs psd-tools composite: max diff {max}, PSNR {psnr:.1} dB");
    assert!(
        max <= 2 && psnr >= 40.0,
        "max diff {max}, PSNR {psnr:.1} dB"
    );
}

#[test]
fn krita_ora_matches_kritas_merged_image() {
    let img = load("krita.ora");
    assert_eq!(img.canvas_px, [120, 160]);
    assert_eq!(paths(&img), CHARACTER);
    let bytes = std::fs::read(fixture("krita.ora")).unwrap();
    let merged = ora::merged_image(&bytes).unwrap();
    let (max, psnr) = compare(&composite(&img), &merged);
    println!("krita.ora vs Krita's mergedimage.png: max diff {max}, PSNR {psnr:.1} dB");
    assert!(
        max <= 2 && psnr >= 40.0,
        "max diff {max}, PSNR {psnr:.1} dB"
    );
}

#[test]
fn krita_psd_matches_kritas_merged_image() {
    let img = load("krita.psd");
    assert_eq!(img.canvas_px, [120, 160]);
    let names: Vec<_> = img.layers.iter().map(|l| l.path.as_str()).collect();
    assert_eq!(names, CHARACTER.map(|c| c.0));
    let ora = std::fs::read(fixture("krita.ora")).unwrap();
    let merged = ora::merged_image(&ora).unwrap();
    let (max, psnr) = compare(&composite(&img), &merged);
    println!("krita.psd vs Krita's mergedimage.png: max diff {max}, PSNR {psnr:.1} dB");
    assert!(
        max <= 2 && psnr >= 40.0,
        "max diff {max}, PSNR {psnr:.1} dB"
    );
    // And the flattened image Krita stores in the PSD itself.
    let own = psd::merged_image(&std::fs::read(fixture("krita.psd")).unwrap(), true).unwrap();
    let (max, psnr) = compare(&composite(&img), &own);
    println!("krita.psd vs its own merged image: max diff {max}, PSNR {psnr:.1} dB");
    assert!(psnr >= 40.0, "PSNR {psnr:.1} dB");
}

#[test]
fn spine_script_layout_places_layers_as_the_psd() {
    let spine = load("spine/character.json");
    let psd = load("character.psd");
    let names: Vec<_> = spine.layers.iter().map(|l| l.path.as_str()).collect();
    // GimpToSpine writes visible layers only, without their groups.
    assert_eq!(names, ["torso", "upper", "hand", "head", "leaf"]);
    // Every layer keeps its place relative to the torso.
    let rel = |img: &LayeredImage, i: usize| {
        let (a, b) = (img.layers[i].offset_px, img.layers[0].offset_px);
        [a[0] - b[0], a[1] - b[1]]
    };
    let in_psd = [0, 1, 2, 3, 4];
    for (i, &j) in in_psd.iter().enumerate() {
        assert_eq!(rel(&spine, i), rel(&psd, j), "{}", names[i]);
        // psd-tools' composite() of one layer (what the script saved) carries its opacity.
        let mut b = psd.layers[j].image.clone();
        for p in b.pixels_mut() {
            p[3] = (p[3] as f32 * psd.layers[j].opacity).round() as u8;
        }
        let a = &spine.layers[i].image;
        assert_eq!(a.dimensions(), b.dimensions(), "{}", names[i]);
        assert!(compare(a, &b).0 <= 1, "{}", names[i]);
    }
}

#[test]
fn unsupported_documents_are_refused_by_name() {
    let err = |name: &str| {
        layered::load_layered(&fixture(name), &LayeredLimits::default())
            .expect_err(name)
            .to_string()
    };
    let e = err("deep16.psd");
    assert!(e.contains("16-bit") && e.contains("deep16.psd"), "{e}");
    let e = err("cmyk.psd");
    assert!(e.contains("CMYK"), "{e}");
}

#[test]
fn truncated_files_are_refused_without_panic() {
    let limits = LayeredLimits::default();
    for name in ["character.psd", "character.psb", "krita.psd"] {
        let bytes = std::fs::read(fixture(name)).unwrap();
        for cut in (0..bytes.len()).step_by(97) {
            // The merged image comes last: a file cut inside it still has all its layers.
            if let Err(e) = psd::parse(&bytes[..cut], &limits) {
                assert!(!e.to_string().is_empty());
            }
        }
    }
    let bytes = std::fs::read(fixture("krita.ora")).unwrap();
    for cut in (0..bytes.len()).step_by(61) {
        assert!(ora::parse(&bytes[..cut], &limits).is_err(), "cut at {cut}");
    }
}

#[test]
fn huge_declared_sizes_are_refused_before_allocating() {
    let mut bytes = std::fs::read(fixture("character.psd")).unwrap();
    // Header: width at byte 18, height at 14.
    bytes[18..22].copy_from_slice(&200_000u32.to_be_bytes());
    let e = psd::parse(&bytes, &LayeredLimits::default()).unwrap_err();
    assert!(matches!(e, LayeredError::TooLarge { .. }), "{e}");
    // A small limit refuses the layers' total.
    let limits = LayeredLimits {
        max_total_px: 1000,
        ..LayeredLimits::default()
    };
    let bytes = std::fs::read(fixture("character.psd")).unwrap();
    let e = psd::parse(&bytes, &limits).unwrap_err();
    assert!(e.to_string().contains("sinew reads at most 1000 px"), "{e}");
}
