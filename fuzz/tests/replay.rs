//! Runs every fuzz target over its seed corpus (and any crashes AFL++ saved under
//! `fuzz/out/TARGET/default/crashes`): a found crash stays a failing test until it is fixed.

use std::path::Path;

#[test]
fn every_target_takes_its_seeds_and_saved_crashes_without_panicking() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut runs = 0;
    for (name, target) in sinew_fuzz::TARGETS {
        for dir in [
            root.join("seeds").join(name),
            root.join("out").join(name).join("default/crashes"),
        ] {
            let Ok(entries) = std::fs::read_dir(&dir) else {
                continue;
            };
            for entry in entries.flatten() {
                let bytes = std::fs::read(entry.path()).unwrap();
                target(&bytes);
                runs += 1;
            }
        }
    }
    assert!(runs > 0, "no seeds: run tools/fuzz/run.sh --seeds-only first");
}
