//! Peak heap memory of trace + mesh, against the size of the decoded image (target: < 10×).
//!
//! A counting global allocator records the high-water mark of live heap bytes while one sprite
//! is traced and meshed. `cargo bench --bench trace_mesh_memory`

#[path = "../tests/common/mod.rs"]
mod common;

use sinew::mesh::{triangulate, MeshOptions};
use sinew::trace::{trace, TraceOptions};
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
    for size in [512u32, 1024, 4096] {
        let image = common::critter(size);
        let image_bytes = image.as_raw().len();
        let before = LIVE.load(Ordering::Relaxed);
        PEAK.store(before, Ordering::Relaxed);
        let outlines = trace(&image, &TraceOptions::default()).unwrap();
        let mesh = triangulate(&outlines, (size * size) as f64, &MeshOptions::default()).unwrap();
        let extra = PEAK.load(Ordering::Relaxed) - before;
        println!(
            "{size}²: decoded image {:.1} MB, peak extra heap during trace + mesh {:.1} MB = {:.2}× the image ({} vertices)",
            image_bytes as f64 / 1e6,
            extra as f64 / 1e6,
            extra as f64 / image_bytes as f64,
            mesh.vertices.len()
        );
    }
}
