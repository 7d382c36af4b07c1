//! Rendered animation frames → folder of PNGs, animated GIF, sprite sheet + JSON: round trips.

use image::{Rgba, RgbaImage};
use sinew::io::sequence::gif::{GifOptions, TRANSPARENT_INDEX};
use sinew::io::sequence::synthetic::synthetic_animation;
use sinew::io::sequence::{
    composite_over_background, encode_gif, write_folder, write_sequence, write_sheet, FrameNaming,
    SequenceError, SequenceFormat, SequenceOptions, SheetOptions,
};
use std::path::{Path, PathBuf};

mod command;

use command::scratch;

/// A decoded GIF: every frame composed onto the logical screen as a browser shows it.
struct DecodedGif {
    frames: Vec<RgbaImage>,
    delays_cs: Vec<u16>,
    transparent: Vec<Option<u8>>,
    disposals: Vec<gif::DisposalMethod>,
    repeat: gif::Repeat,
    global_palette_len: usize,
}

fn decode_gif(bytes: &[u8]) -> DecodedGif {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::Indexed);
    let mut decoder = options.read_info(bytes).unwrap();
    let (w, h) = (u32::from(decoder.width()), u32::from(decoder.height()));
    let palette = decoder.global_palette().unwrap().to_vec();
    let mut out = DecodedGif {
        frames: Vec::new(),
        delays_cs: Vec::new(),
        transparent: Vec::new(),
        disposals: Vec::new(),
        repeat: gif::Repeat::Finite(0),
        global_palette_len: palette.len() / 3,
    };
    let mut canvas = RgbaImage::new(w, h);
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert!(frame.palette.is_none(), "frames use the global palette");
        for y in 0..u32::from(frame.height) {
            for x in 0..u32::from(frame.width) {
                let i = frame.buffer[(y * u32::from(frame.width) + x) as usize];
                if Some(i) == frame.transparent {
                    continue;
                }
                let c = &palette[3 * usize::from(i)..3 * usize::from(i) + 3];
                let (cx, cy) = (x + u32::from(frame.left), y + u32::from(frame.top));
                canvas.put_pixel(cx, cy, Rgba([c[0], c[1], c[2], 255]));
            }
        }
        out.frames.push(canvas.clone());
        out.delays_cs.push(frame.delay);
        out.transparent.push(frame.transparent);
        out.disposals.push(frame.dispose);
        if frame.dispose == gif::DisposalMethod::Background {
            for y in 0..u32::from(frame.height) {
                for x in 0..u32::from(frame.width) {
                    let (cx, cy) = (x + u32::from(frame.left), y + u32::from(frame.top));
                    canvas.put_pixel(cx, cy, Rgba([0; 4]));
                }
            }
        }
    }
    out.repeat = decoder.repeat();
    out
}

/// PSNR (dB) over the pixels visible in `original`, colour channels only, and the largest
/// channel difference there.
fn colour_error(original: &RgbaImage, decoded: &RgbaImage, threshold: u8) -> (f64, u8) {
    let (mut sq, mut n, mut max) = (0f64, 0u64, 0u8);
    for (a, b) in original.pixels().zip(decoded.pixels()) {
        if a[3] < threshold {
            continue;
        }
        for k in 0..3 {
            let d = a[k].abs_diff(b[k]);
            max = max.max(d);
            sq += f64::from(d).powi(2);
            n += 1;
        }
    }
    let mse = sq / n.max(1) as f64;
    (10.0 * (255f64.powi(2) / mse).log10(), max)
}

#[test]
fn gif_round_trip_keeps_shape_timing_and_colours() {
    let frames = synthetic_animation(96, 12);
    let options = GifOptions::default();
    let gif = encode_gif(&frames, 24.0, &options).unwrap();
    let decoded = decode_gif(&gif.bytes);

    assert_eq!(decoded.frames.len(), 12);
    assert_eq!(decoded.repeat, gif::Repeat::Infinite);
    // 12 frames at 24 fps = 0.5 s, spread as 4/4/5/4 … hundredths.
    assert_eq!(
        decoded.delays_cs.iter().map(|&d| u32::from(d)).sum::<u32>(),
        50
    );
    assert!(decoded.delays_cs.iter().all(|&d| d == 4 || d == 5));
    assert_eq!(decoded.delays_cs, gif.delays_cs);
    assert!(decoded
        .transparent
        .iter()
        .all(|&t| t == Some(TRANSPARENT_INDEX)));
    assert!(decoded
        .disposals
        .iter()
        .all(|&d| d == gif::DisposalMethod::Background));
    assert_eq!(decoded.global_palette_len, 256);
    assert!(gif.palette_colours <= 255);

    for (original, shown) in frames.iter().zip(&decoded.frames) {
        // Alpha: exactly the threshold's split.
        for (a, b) in original.pixels().zip(shown.pixels()) {
            assert_eq!(a[3] >= options.alpha_threshold, b[3] == 255);
        }
        let (psnr, max) = colour_error(original, shown, options.alpha_threshold);
        assert!(psnr >= 38.0, "PSNR {psnr:.1} dB");
        assert!(max <= 24, "largest channel error {max}");
    }
}

#[test]
fn gif_with_few_colours_is_exact_and_bytes_are_deterministic() {
    // Eight colours moving over transparency: fits the palette, so lossless.
    let colours = [
        [255, 0, 0],
        [0, 255, 0],
        [0, 0, 255],
        [255, 255, 0],
        [0, 255, 255],
        [255, 0, 255],
        [10, 20, 30],
        [250, 250, 250],
    ];
    let frames: Vec<RgbaImage> = (0..6u32)
        .map(|f| {
            RgbaImage::from_fn(40, 30, |x, y| {
                if (x + 3 * f) % 40 < 20 && y > 5 {
                    let c = colours[((x / 5 + y / 5) % 8) as usize];
                    Rgba([c[0], c[1], c[2], 255])
                } else {
                    Rgba([0; 4])
                }
            })
        })
        .collect();
    let gif = encode_gif(&frames, 10.0, &GifOptions::default()).unwrap();
    assert_eq!(gif.palette_colours, 8);
    let decoded = decode_gif(&gif.bytes);
    assert_eq!(decoded.frames, frames);
    assert_eq!(decoded.delays_cs, vec![10; 6]);

    // Same bytes on one thread as on the default pool, and run after run.
    let animation = synthetic_animation(80, 6);
    let many = encode_gif(&animation, 12.0, &GifOptions::default()).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| encode_gif(&animation, 12.0, &GifOptions::default()).unwrap());
    assert_eq!(many.bytes, one.bytes);
    assert_eq!(
        many.bytes,
        encode_gif(&animation, 12.0, &GifOptions::default())
            .unwrap()
            .bytes
    );
}

#[test]
fn gif_over_a_background_is_opaque_and_blends_edges() {
    let frames = synthetic_animation(64, 4);
    let on_white = composite_over_background(&frames, [255, 255, 255, 255]);
    let gif = encode_gif(&on_white, 8.0, &GifOptions::default()).unwrap();
    let decoded = decode_gif(&gif.bytes);
    for (original, shown) in on_white.iter().zip(&decoded.frames) {
        assert!(shown.pixels().all(|p| p[3] == 255));
        let (psnr, _) = colour_error(original, shown, 0);
        assert!(psnr >= 38.0, "PSNR {psnr:.1} dB");
    }
    // The 30 %-opaque shadow, transparent in the plain GIF, shows as light grey here.
    let shadow = on_white[0].get_pixel(32, 54);
    assert!(shadow[0] < 255 && shadow[0] > 150, "{shadow:?}");
}

/// Sheet pixels of `rect` (JSON object with x, y, w, h).
fn rect(v: &serde_json::Value) -> (u32, u32, u32, u32) {
    let n = |k: &str| v[k].as_u64().unwrap() as u32;
    (n("x"), n("y"), n("w"), n("h"))
}

fn check_sheet(
    frames: &[RgbaImage],
    dir: &Path,
    name: &str,
    options: &SheetOptions,
) -> serde_json::Value {
    let path = dir.join(format!("{name}.png"));
    let report = write_sheet(frames, &[], 30.0, &path, options).unwrap();
    assert_eq!(report.format, SequenceFormat::Sheet);
    let sheet = sinew::io::load_png(&path).unwrap();
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join(format!("{name}.json"))).unwrap()).unwrap();
    assert_eq!(report.sheet_size_px, Some(sheet.dimensions()));

    let meta = &json["meta"];
    assert_eq!(meta["app"], "sinew");
    assert_eq!(meta["image"], format!("{name}.png"));
    assert_eq!(meta["format"], "RGBA8888");
    assert_eq!(meta["scale"], "1");
    assert_eq!(
        meta["size"]["w"].as_u64().unwrap(),
        u64::from(sheet.width())
    );
    assert_eq!(
        meta["size"]["h"].as_u64().unwrap(),
        u64::from(sheet.height())
    );
    assert!(sheet.width() <= options.max_side_px && sheet.height() <= options.max_side_px);
    let tag = &meta["frameTags"][0];
    assert_eq!(tag["name"], name);
    assert_eq!(tag["from"], 0);
    assert_eq!(tag["to"].as_u64().unwrap() as usize, frames.len() - 1);

    let table = json["frames"].as_object().unwrap();
    let names: Vec<String> = json["animations"][name]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect();
    assert_eq!(names.len(), frames.len());
    assert_eq!(table.len(), frames.len());
    let mut total_ms = 0;
    let mut placed: Vec<(u32, u32, u32, u32)> = Vec::new();
    for (frame_name, original) in names.iter().zip(frames) {
        let entry = &table[frame_name.as_str()];
        assert_eq!(entry["rotated"], false);
        let (fx, fy, fw, fh) = rect(&entry["frame"]);
        let (sx, sy, sw, sh) = rect(&entry["spriteSourceSize"]);
        assert_eq!((fw, fh), (sw, sh));
        assert_eq!(
            entry["sourceSize"]["w"].as_u64().unwrap(),
            u64::from(original.width())
        );
        assert_eq!(
            entry["sourceSize"]["h"].as_u64().unwrap(),
            u64::from(original.height())
        );
        let full = (sx, sy, sw, sh) == (0, 0, original.width(), original.height());
        assert_eq!(entry["trimmed"].as_bool().unwrap(), !full);
        total_ms += entry["duration"].as_u64().unwrap();
        // Crop from the sheet, re-expand to the source size: exactly the input frame.
        let mut rebuilt = RgbaImage::new(original.width(), original.height());
        for y in 0..fh {
            for x in 0..fw {
                rebuilt.put_pixel(sx + x, sy + y, *sheet.get_pixel(fx + x, fy + y));
            }
        }
        assert_eq!(&rebuilt, original, "{frame_name}");
        if !placed.contains(&(fx, fy, fw, fh)) {
            placed.push((fx, fy, fw, fh));
        }
    }
    assert_eq!(total_ms, (frames.len() as u64 * 1000 + 15) / 30);
    // Distinct rectangles keep the padding between them.
    let pad = options.padding_px;
    for (i, a) in placed.iter().enumerate() {
        for b in &placed[i + 1..] {
            let apart_x = a.0 + a.2 + pad <= b.0 || b.0 + b.2 + pad <= a.0;
            let apart_y = a.1 + a.3 + pad <= b.1 || b.1 + b.3 + pad <= a.1;
            assert!(apart_x || apart_y, "{a:?} and {b:?} closer than {pad} px");
        }
    }
    json
}

#[test]
fn sheet_json_reproduces_every_frame() {
    let tmp = scratch("sheet");
    let dir = tmp.path();
    let mut frames = synthetic_animation(72, 10);
    // A held pose (stored once) and an empty frame.
    frames.push(frames[3].clone());
    frames.push(RgbaImage::new(72, 72));
    let json = check_sheet(&frames, dir, "walk", &SheetOptions::default());
    let table = json["frames"].as_object().unwrap();
    assert!(table.contains_key("walk_0000.png") && table.contains_key("walk_0011.png"));
    assert_eq!(
        table["walk_0003.png"]["frame"],
        table["walk_0010.png"]["frame"]
    );
    assert_eq!(table["walk_0011.png"]["trimmed"], true);
    // Frames are trimmed: the synthetic frames leave transparent margins.
    assert!(table["walk_0000.png"]["frame"]["w"].as_u64().unwrap() < 72);

    // Untrimmed, no dedupe, index names (Phaser's createFromAseprite), 1 px padding.
    let plain = SheetOptions {
        padding_px: 1,
        trim: false,
        dedupe: false,
        naming: FrameNaming::Index,
        ..SheetOptions::default()
    };
    let json = check_sheet(&frames, dir, "plain", &plain);
    assert_eq!(json["frames"]["0"]["trimmed"], false);
    assert_ne!(json["frames"]["3"]["frame"], json["frames"]["10"]["frame"]);

    // Byte-identical on a second write.
    let first = std::fs::read(dir.join("walk.json")).unwrap();
    let first_png = std::fs::read(dir.join("walk.png")).unwrap();
    write_sheet(
        &frames,
        &[],
        30.0,
        &dir.join("walk.png"),
        &SheetOptions::default(),
    )
    .unwrap();
    assert_eq!(std::fs::read(dir.join("walk.json")).unwrap(), first);
    assert_eq!(std::fs::read(dir.join("walk.png")).unwrap(), first_png);
}

#[test]
fn folder_holds_numbered_frames() {
    let tmp = scratch("folder");
    let dir = tmp.path();
    let frames = synthetic_animation(32, 5);
    let out = dir.join("frames");
    // A frame of a longer earlier render goes with it; the user's files and folders stay.
    std::fs::create_dir_all(out.join("refs")).unwrap();
    std::fs::write(out.join("frame_0007.png"), b"old").unwrap();
    std::fs::write(out.join("notes.txt"), b"keep").unwrap();
    std::fs::write(out.join("refs/a.txt"), b"keep too").unwrap();
    let report = write_sequence(&frames, &[], 12.0, &out, &SequenceOptions::default()).unwrap();
    assert_eq!(report.format, SequenceFormat::Folder);
    assert_eq!(report.stale_files, vec![out.join("frame_0007.png")]);
    assert!(!out.join("frame_0007.png").exists());
    assert_eq!(std::fs::read(out.join("notes.txt")).unwrap(), b"keep");
    assert_eq!(std::fs::read(out.join("refs/a.txt")).unwrap(), b"keep too");
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let expected: Vec<String> = (0..5).map(|i| format!("frame_{i:04}.png")).collect();
    assert_eq!(&names[..5], &expected[..]);
    assert_eq!(names.len(), 7);
    for (i, frame) in frames.iter().enumerate() {
        assert_eq!(
            &sinew::io::load_png(&out.join(&expected[i])).unwrap(),
            frame
        );
    }
    assert!((report.duration_s - 5.0 / 12.0).abs() < 1e-12);

    // A path without extension that does not exist yet becomes a folder.
    let fresh = dir.join("new_frames");
    write_folder(&frames[..1], 12.0, &fresh).unwrap();
    assert!(fresh.join("frame_0000.png").is_file());
}

#[test]
fn bad_input_gives_one_line_errors_and_no_files() {
    let tmp = scratch("errors");
    let dir = tmp.path();
    let frames = synthetic_animation(16, 2);
    let options = SequenceOptions::default();
    let one_line = |e: SequenceError| {
        let text = e.to_string();
        assert!(!text.contains('\n') && !text.is_empty(), "{text}");
        e
    };

    let gif = dir.join("a.gif");
    let e =
        one_line(write_sequence(&Vec::<RgbaImage>::new(), &[], 10.0, &gif, &options).unwrap_err());
    assert!(matches!(e, SequenceError::NoFrames));
    let mixed = vec![frames[0].clone(), RgbaImage::new(8, 16)];
    for target in ["a.gif", "a.png", "a"] {
        let e =
            one_line(write_sequence(&mixed, &[], 10.0, &dir.join(target), &options).unwrap_err());
        assert!(
            matches!(e, SequenceError::MismatchedSize { index: 1, .. }),
            "{e}"
        );
    }
    let e = one_line(write_sequence(&frames, &[], 0.0, &gif, &options).unwrap_err());
    assert!(matches!(e, SequenceError::BadFrameRate { .. }));
    let e =
        one_line(write_sequence(&frames, &[], 10.0, &dir.join("a.webm"), &options).unwrap_err());
    assert!(matches!(e, SequenceError::UnknownFormat { .. }));

    // A file where a folder should be.
    std::fs::write(dir.join("blocker"), b"x").unwrap();
    for target in ["blocker/a.gif", "blocker/a.png", "blocker/frames"] {
        let e =
            one_line(write_sequence(&frames, &[], 10.0, &dir.join(target), &options).unwrap_err());
        assert!(matches!(e, SequenceError::Write { .. }), "{e}");
        assert!(e.to_string().contains("blocker"));
    }

    let tiny = SequenceOptions {
        sheet: SheetOptions {
            max_side_px: 8,
            ..SheetOptions::default()
        },
        ..SequenceOptions::default()
    };
    let e = one_line(write_sequence(&frames, &[], 10.0, &dir.join("big.png"), &tiny).unwrap_err());
    assert!(matches!(
        e,
        SequenceError::SheetTooLarge { max_side_px: 8, .. }
    ));

    let left: Vec<_> = std::fs::read_dir(dir).unwrap().collect();
    assert_eq!(left.len(), 1, "only the blocker file remains");
}

/// PSNR (dB) of the visible colours of `frames` after Wu + k-means and after NeuQuant, both
/// palettes of 255 entries, each colour mapped to its exact nearest entry.
fn palette_psnr_vs_neuquant(frames: &[RgbaImage]) -> (f64, f64) {
    use sinew::io::sequence::palette::{pack_rgb, quantize, Histogram};
    let threshold = GifOptions::default().alpha_threshold;
    let visible: Vec<[u8; 3]> = frames
        .iter()
        .flat_map(|f| {
            f.pixels()
                .filter(|p| p[3] >= threshold)
                .map(|p| [p[0], p[1], p[2]])
        })
        .collect();
    let histogram = Histogram::from_frames(vec![visible
        .iter()
        .map(|c| pack_rgb(c[0], c[1], c[2]))
        .collect()]);
    let sse = |palette: &[[u8; 3]]| -> f64 {
        histogram
            .colours
            .iter()
            .zip(&histogram.counts)
            .map(|(&c, &n)| {
                let c = [(c >> 16) as u8, (c >> 8) as u8, c as u8];
                let best = palette
                    .iter()
                    .map(|p| {
                        (0..3)
                            .map(|k| f64::from(c[k].abs_diff(p[k])).powi(2))
                            .sum::<f64>()
                    })
                    .fold(f64::INFINITY, f64::min);
                best * n as f64
            })
            .sum()
    };
    let psnr = |sse: f64| 10.0 * (255f64.powi(2) * 3.0 * visible.len() as f64 / sse).log10();
    let ours = quantize(&histogram, 255).palette;
    let rgba: Vec<u8> = visible
        .iter()
        .flat_map(|c| [c[0], c[1], c[2], 255])
        .collect();
    // Sample factor 1: NeuQuant's best quality (what `gif::Frame::from_rgba` uses).
    let neuquant: Vec<[u8; 3]> = color_quant::NeuQuant::new(1, 255, &rgba)
        .color_map_rgb()
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    eprintln!(
        "{} distinct colours: Wu + k-means {:.2} dB, NeuQuant {:.2} dB",
        histogram.colours.len(),
        psnr(sse(&ours)),
        psnr(sse(&neuquant))
    );
    (psnr(sse(&ours)), psnr(sse(&neuquant)))
}

#[test]
fn palette_beats_neuquant() {
    // The cutout-like test animation: few flat colours, one gradient, antialiased edges.
    let cutout = synthetic_animation(128, 12);
    // A dense colour field: smooth, many colours in every region of the colour cube.
    let field: Vec<RgbaImage> = (0..4)
        .map(|f| {
            RgbaImage::from_fn(128, 128, |x, y| {
                let (u, v, t) = (x as f64 / 20.0, y as f64 / 17.0, f as f64);
                let ch = |a: f64| (127.5 + 127.5 * a.sin()) as u8;
                Rgba([ch(u + t), ch(v - 0.7 * t), ch((u + v) * 0.6 + 2.0), 255])
            })
        })
        .collect();
    for frames in [cutout, field] {
        let (ours, neuquant) = palette_psnr_vs_neuquant(&frames);
        assert!(ours > neuquant, "{ours:.2} dB vs NeuQuant {neuquant:.2} dB");
    }
}

/// Frames drawn on demand (as a render draws them), counting what the writers ask for.
struct OnDemand {
    frames: Vec<RgbaImage>,
    largest_draw: std::sync::atomic::AtomicUsize,
    drawn: std::sync::atomic::AtomicUsize,
}

impl sinew::io::sequence::FrameSource for OnDemand {
    fn frame_count(&self) -> usize {
        self.frames.len()
    }

    fn frame_size_px(&self) -> (u32, u32) {
        self.frames[0].dimensions()
    }

    fn draw(
        &self,
        range: std::ops::Range<usize>,
    ) -> Result<Vec<std::borrow::Cow<'_, RgbaImage>>, SequenceError> {
        use std::sync::atomic::Ordering::Relaxed;
        self.largest_draw.fetch_max(range.len(), Relaxed);
        self.drawn.fetch_add(range.len(), Relaxed);
        // Fresh copies, as a render makes them.
        Ok(self.frames[range]
            .iter()
            .map(|f| std::borrow::Cow::Owned(f.clone()))
            .collect())
    }
}

#[test]
fn frames_drawn_on_demand_are_written_a_chunk_at_a_time_with_the_same_bytes() {
    use sinew::io::sequence::STREAM_CHUNK_FRAMES;
    use std::sync::atomic::Ordering::Relaxed;
    let tmp = scratch("stream");
    let dir = tmp.path();
    let frames = synthetic_animation(48, 2 * STREAM_CHUNK_FRAMES + 5);
    let count = frames.len();
    let source = OnDemand {
        frames: frames.clone(),
        largest_draw: 0.into(),
        drawn: 0.into(),
    };
    let options = SequenceOptions::default();
    for target in ["walk.gif", "walk.png", "walk"] {
        let (streamed, held) = (
            dir.join("streamed").join(target),
            dir.join("held").join(target),
        );
        source.drawn.store(0, Relaxed);
        for side in ["streamed", "held"] {
            std::fs::create_dir_all(dir.join(side)).unwrap();
        }
        write_sequence(&source, &[], 24.0, &streamed, &options).unwrap();
        write_sequence(&frames, &[], 24.0, &held, &options).unwrap();
        // A GIF reads the frames twice but keeps what it drew (they fit its budget).
        assert_eq!(source.drawn.load(Relaxed), count, "{target}");
        let files = |p: &Path| -> Vec<(String, Vec<u8>)> {
            let mut paths: Vec<PathBuf> = if p.is_dir() {
                std::fs::read_dir(p)
                    .unwrap()
                    .map(|e| e.unwrap().path())
                    .collect()
            } else {
                vec![p.to_path_buf(), p.with_extension("json")]
                    .into_iter()
                    .filter(|f| f.exists())
                    .collect()
            };
            paths.sort();
            paths
                .iter()
                .map(|f| {
                    let name = f.file_name().unwrap().to_string_lossy().into_owned();
                    (name, std::fs::read(f).unwrap())
                })
                .collect()
        };
        assert_eq!(files(&streamed), files(&held), "{target}");
    }
    assert!(source.largest_draw.load(Relaxed) <= STREAM_CHUNK_FRAMES);

    // With no room to keep frames, a GIF draws them again for its second pass: same bytes.
    source.drawn.store(0, Relaxed);
    let tight = GifOptions {
        keep_frames_mib: 0,
        ..GifOptions::default()
    };
    assert_eq!(
        encode_gif(&source, 24.0, &tight).unwrap(),
        encode_gif(&frames, 24.0, &GifOptions::default()).unwrap()
    );
    assert_eq!(source.drawn.load(Relaxed), 2 * count);
}
