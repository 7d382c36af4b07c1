//! Inputs at sinew's documented limits, through the release binary: each must finish (or be
//! refused) within a few seconds on the two-core reference machine (issue 44: median < 5 s).
//!
//! - `rig/psd_10000_layers`: `sinew rig` on a PSD of 10,000 layers (`LayeredLimits::default`'s
//!   `max_layers`), each a 9 px disc on a 1200² canvas; the rig re-written over its previous
//!   run (its `.parts/` folder replaced), as an artist re-rigs.
//! - `autorig/psd_10000_layers`: `sinew autorig` on the same file (refused: more layers than a
//!   rig's weight columns; the refusal must come before the work).
//! - `rig/spine_script_10000_slots`: `sinew rig` on a Spine-script JSON (what PhotoshopToSpine
//!   writes) of 10,000 slots, each a 9 px PNG.
//! - `export_spine/1000_skins`: `sinew export spine` of the bundled character (from `sinew demo`)
//!   with 1,000 skins over its 12 slots.
//!
//! Each is run `RUNS` times; printed: the median, the fastest and slowest run, the load average
//! before and after, and whether the median meets `TARGET_S`. The inputs are generated into a
//! scratch folder (kept with `SINEW_KEEP_TEST_DIRS=1`).
//!
//! `cargo bench --bench limits`

#[path = "../tests/command/mod.rs"]
mod command;

use serde_json::{json, Value};
use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// Runs per case.
const RUNS: usize = 5;
/// The target median per case, s.
const TARGET_S: f64 = 5.0;
/// Layers of the PSD and slots of the Spine-script JSON: the documented limit.
const LAYERS: usize = 10_000;
/// Skins of the exported rig.
const SKINS: usize = 1_000;
/// Grid cell and disc of each layer, px.
const CELL_PX: u32 = 12;
const DISC_PX: u32 = 9;

fn main() {
    let tmp = command::scratch("limits");
    let dir = tmp.path();
    let psd = dir.join("layers.psd");
    std::fs::write(&psd, psd_of_discs(LAYERS)).unwrap();
    let script = spine_script_of_discs(dir, LAYERS);
    let skins = rig_with_skins(dir, SKINS);
    let out = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let cases: Vec<(&str, Vec<String>, bool)> = vec![
        (
            "rig/psd_10000_layers",
            vec!["rig".into(), s(&psd), "-o".into(), out("psd-rig.json")],
            true,
        ),
        (
            "autorig/psd_10000_layers",
            vec![
                "autorig".into(),
                s(&psd),
                "-o".into(),
                out("psd-handles.json"),
            ],
            false,
        ),
        (
            "rig/spine_script_10000_slots",
            vec![
                "rig".into(),
                s(&script),
                "-o".into(),
                out("script-rig.json"),
            ],
            true,
        ),
        (
            "export_spine/1000_skins",
            vec![
                "export".into(),
                "spine".into(),
                s(&skins),
                "-o".into(),
                out("spine"),
            ],
            true,
        ),
    ];
    println!("{RUNS} runs each; target: median < {TARGET_S} s");
    for (name, args, succeeds) in cases {
        let load_before = load_average();
        let mut times: Vec<f64> = (0..RUNS).map(|_| run(&args, succeeds)).collect();
        times.sort_by(f64::total_cmp);
        let median = times[RUNS / 2];
        println!(
            "{name}: median {median:.2} s (fastest {:.2}, slowest {:.2}); load {load_before} -> {}; {}",
            times[0],
            times[RUNS - 1],
            load_average(),
            if median < TARGET_S { "met" } else { "MISSED" }
        );
    }
}

fn s(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

/// Runs the binary once; its wall time, s. Panics when it does not end as expected (a
/// refusal is exit code 2).
fn run(args: &[String], succeeds: bool) -> f64 {
    let started = Instant::now();
    let output = Command::new(env!("CARGO_BIN_EXE_sinew"))
        .args(args)
        .output()
        .expect("run sinew");
    let seconds = started.elapsed().as_secs_f64();
    let expected = if succeeds { 0 } else { command::EXIT_BAD_INPUT };
    assert_eq!(
        output.status.code(),
        Some(expected),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    seconds
}

/// The 1-minute load average (`/proc/loadavg`), or `?`.
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "?".into())
}

/// A disc of `DISC_PX`, opaque inside, in colour `i`, as straight RGBA rows.
fn disc(i: usize) -> image::RgbaImage {
    let c = DISC_PX as f64 / 2.0 - 0.5;
    image::RgbaImage::from_fn(DISC_PX, DISC_PX, |x, y| {
        let inside = (x as f64 - c).powi(2) + (y as f64 - c).powi(2) <= c * c + 2.0;
        let v = |k: usize| ((i * k) % 256) as u8;
        image::Rgba([v(37), v(91), v(53), if inside { 255 } else { 0 }])
    })
}

/// Grid cell (column, row) of item `i` of `n`.
fn cell(i: usize, n: usize) -> (u32, u32, u32) {
    let cols = (n as f64).sqrt().ceil() as usize;
    ((i % cols) as u32, (i / cols) as u32, cols as u32)
}

/// An uncompressed 8-bit RGB PSD of `n` layers, a disc each on a grid (Adobe's layer and mask
/// section: records, then each layer's raw channels; a merged image of the canvas's size).
fn psd_of_discs(n: usize) -> Vec<u8> {
    let (_, _, cols) = cell(0, n);
    let rows = (n as u32).div_ceil(cols);
    let (w, h) = (cols * CELL_PX, rows * CELL_PX);
    let mut records = Vec::new();
    let mut channels = Vec::new();
    for i in 0..n {
        let (c, r, _) = cell(i, n);
        let (top, left) = (r * CELL_PX + 1, c * CELL_PX + 1);
        let image = disc(i);
        for v in [top, left, top + DISC_PX, left + DISC_PX] {
            records.extend((v as i32).to_be_bytes());
        }
        records.extend(4u16.to_be_bytes());
        let plane = |k: usize| -> Vec<u8> { image.pixels().map(|p| p[k]).collect() };
        let planes = [
            (-1i16, plane(3)),
            (0, plane(0)),
            (1, plane(1)),
            (2, plane(2)),
        ];
        for (id, data) in &planes {
            records.extend(id.to_be_bytes());
            records.extend((2 + data.len() as u32).to_be_bytes());
        }
        records.extend(b"8BIMnorm");
        records.extend([255, 0, 0, 0]);
        let name = format!("part {i}");
        let mut pascal = vec![name.len() as u8];
        pascal.extend(name.as_bytes());
        while pascal.len() % 4 != 0 {
            pascal.push(0);
        }
        records.extend((8 + pascal.len() as u32).to_be_bytes());
        records.extend([0u8; 8]);
        records.extend(pascal);
        for (_, data) in planes {
            channels.extend(0u16.to_be_bytes());
            channels.extend(data);
        }
    }
    let mut layer_info = (-(n as i16)).to_be_bytes().to_vec();
    layer_info.extend(records);
    layer_info.extend(channels);
    if layer_info.len() % 2 == 1 {
        layer_info.push(0);
    }
    let mut out = b"8BPS".to_vec();
    out.extend(1u16.to_be_bytes());
    out.extend([0u8; 6]);
    out.extend(4u16.to_be_bytes());
    out.extend(h.to_be_bytes());
    out.extend(w.to_be_bytes());
    out.extend(8u16.to_be_bytes());
    out.extend(3u16.to_be_bytes());
    out.extend(0u32.to_be_bytes());
    out.extend(0u32.to_be_bytes());
    out.extend((layer_info.len() as u32 + 8).to_be_bytes());
    out.extend((layer_info.len() as u32).to_be_bytes());
    out.extend(layer_info);
    out.extend(0u32.to_be_bytes());
    out.extend(0u16.to_be_bytes());
    out.extend(std::iter::repeat_n(0x80u8, (w * h * 4) as usize));
    out
}

/// A Spine-script JSON of `n` slots (one region each, a disc PNG under `images/`) in `dir`.
fn spine_script_of_discs(dir: &Path, n: usize) -> std::path::PathBuf {
    let images = dir.join("images");
    std::fs::create_dir_all(&images).unwrap();
    let mut slots = Vec::new();
    let mut attachments = serde_json::Map::new();
    for i in 0..n {
        let name = format!("p{i}");
        disc(i).save(images.join(format!("{name}.png"))).unwrap();
        let (c, r, _) = cell(i, n);
        let half = DISC_PX as f64 / 2.0;
        slots.push(json!({"name": name, "bone": "root", "attachment": name}));
        attachments.insert(
            name.clone(),
            json!({ name: {
                "x": (c * CELL_PX) as f64 + half,
                "y": -((r * CELL_PX) as f64 + half),
                "width": DISC_PX,
                "height": DISC_PX,
            }}),
        );
    }
    let script = json!({
        "skeleton": {"images": "./images/"},
        "bones": [{"name": "root"}],
        "slots": slots,
        "skins": [{"name": "default", "attachments": attachments}],
    });
    let path = dir.join("script.json");
    std::fs::write(&path, script.to_string()).unwrap();
    path
}

/// The bundled character (`sinew demo` into `dir/demo`) with `n` skins, each choosing an
/// attachment for every slot (cycling through each slot's attachments).
fn rig_with_skins(dir: &Path, n: usize) -> std::path::PathBuf {
    let demo = dir.join("demo");
    let output = Command::new(env!("CARGO_BIN_EXE_sinew"))
        .args(["demo", "-o", &s(&demo)])
        .output()
        .expect("run sinew demo");
    assert!(output.status.success(), "sinew demo failed");
    let path = demo.join("character.json");
    let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let parts = doc["parts"].as_array().unwrap().clone();
    let slots: Vec<&str> = parts
        .iter()
        .filter(|p| p.get("slot").is_none())
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    let mut skins = serde_json::Map::new();
    for k in 0..n {
        let mut skin = serde_json::Map::new();
        for slot in &slots {
            let mut choices = vec![*slot];
            choices.extend(
                parts
                    .iter()
                    .filter(|p| p.get("slot").and_then(Value::as_str) == Some(slot))
                    .map(|p| p["name"].as_str().unwrap()),
            );
            skin.insert(slot.to_string(), json!(choices[k % choices.len()]));
        }
        skins.insert(format!("skin_{k}"), Value::Object(skin));
    }
    doc["skins"] = Value::Object(skins);
    let out = demo.join("skins.json");
    std::fs::write(&out, doc.to_string()).unwrap();
    out
}
