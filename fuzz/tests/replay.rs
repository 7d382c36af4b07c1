//! Runs every fuzz target over its seed corpus and over what AFL++ saved under
//! `fuzz/out/TARGET/default` (its `crashes`, and its `queue`: the inputs that reached new code):
//! a found crash stays a failing test, with its panic message, until it is fixed.

use std::path::Path;

#[test]
fn every_target_takes_its_seeds_and_saved_inputs_without_panicking() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut seeds = 0;
    for (name, target) in sinew_fuzz::TARGETS {
        let mut runs = 0;
        for dir in [
            root.join("seeds").join(name),
            root.join("out").join(name).join("default/crashes"),
            root.join("out").join(name).join("default/queue"),
        ] {
            let Ok(entries) = std::fs::read_dir(&dir) else {
                continue;
            };
            let mut files: Vec<_> = entries
                .flatten()
                .map(|e| e.path())
                .filter(|p| p.is_file())
                .collect();
            files.sort();
            for file in files {
                let bytes = std::fs::read(&file).unwrap();
                eprintln!("{name}: {}", file.display());
                target(&bytes);
                runs += 1;
                if dir.starts_with(root.join("seeds")) {
                    seeds += 1;
                }
            }
        }
        println!("{name}: {runs} inputs");
        assert!(
            runs > 0,
            "{name}: no seeds: run tools/fuzz/run.sh --seeds-only first"
        );
    }
    assert!(seeds > 0);
}

/// The seeds (made from real files and docs/formats.md's examples, and by hand) are read, so
/// fuzzing starts from accepted inputs: a reader that came to refuse them would leave AFL++
/// mutating refusals only. The two PSDs of unsupported kinds (CMYK, 16-bit) are refused.
#[test]
fn the_readers_accept_their_seeds() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("seeds");
    let refused = ["cmyk.psd", "deep16.psd"];
    for (name, read) in sinew_fuzz::READERS {
        let dir = root.join(name);
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| {
                panic!(
                    "{}: {e}: run tools/fuzz/run.sh --seeds-only first",
                    dir.display()
                )
            })
            .flatten()
            .map(|e| e.path())
            .collect();
        files.sort();
        assert!(files.len() >= 2, "{name}: {} seeds", files.len());
        for file in files {
            let wanted = !refused.iter().any(|r| file.ends_with(r));
            let bytes = std::fs::read(&file).unwrap();
            assert_eq!(read(&bytes), wanted, "{name}: {}", file.display());
        }
    }
}
