//! Peak heap memory of one colorization at 2048² with 10 scribble colors (target < 1 GiB),
//! and at 512² and 1024² for the trend, on the scenes of `benches/colorize.rs`: `closed` (every
//! region closed, one color each), `undrawn` (the background's two halves in one region: the
//! reach split runs over it) and `open` (the 10 scribbles on a blank page: one region holding
//! every color, the split's worst case). A counting global allocator records the high-water
//! mark of live heap bytes during the `colorize::colorize` call (the line art and scribbles,
//! allocated before, are not counted; they are printed). `cargo bench --bench colorize_memory`

use sinew::colorize::synthetic::{scene, SceneSpec};
use sinew::colorize::{self, ColorizeOptions, ScribbleOptions, Scribbles};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(live, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn main() {
    // `cargo bench` passes --bench; nothing to parse.
    for size in [512u32, 1024, 2048] {
        for scene_name in ["closed", "undrawn", "open"] {
            let s = scene(&SceneSpec {
                size,
                shapes: 9,
                split_background: scene_name == "undrawn",
                ..Default::default()
            });
            let lineart = if scene_name == "open" {
                image::RgbaImage::from_pixel(size, size, image::Rgba([255; 4]))
            } else {
                s.lineart
            };
            let scribbles =
                Scribbles::from_strokes(&s.strokes, size, size, &ScribbleOptions::default())
                    .expect("the strokes rasterize");
            let inputs = lineart.as_raw().len() + scribbles.labels.len() * 2;
            for layers in [false, true] {
                let before = LIVE.load(Ordering::Relaxed);
                PEAK.store(before, Ordering::Relaxed);
                let result =
                    colorize::colorize(&lineart, &scribbles, &ColorizeOptions::default(), layers)
                        .expect("colorizes");
                let extra = PEAK.load(Ordering::Relaxed) - before;
                println!(
                    "{scene_name} {size}², {} colors{}: peak heap during colorize {:.1} MB (inputs {:.1} MB; {} mesh vertices)",
                    scribbles.colors.len(),
                    if layers { ", with layers" } else { "" },
                    extra as f64 / 1e6,
                    inputs as f64 / 1e6,
                    result.stats.vertices
                );
            }
        }
    }
}
