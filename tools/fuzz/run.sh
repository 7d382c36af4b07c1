#!/usr/bin/env bash
# Coverage-guided fuzzing of sinew's readers with AFL++ (cargo-afl, stable Rust).
#
#   tools/fuzz/run.sh [SECONDS_PER_TARGET] [TARGET...]   # default 30 s each, every target
#   tools/fuzz/run.sh --seeds-only                       # only (re)make the seed corpus
#
# Targets (fuzz/src/lib.rs): rig_document, handles, pose, animations, scribbles, png_trace_mesh.
# The seed corpus (fuzz/seeds/TARGET) comes from the bundled assets. cargo-afl is installed into
# tools/fuzz/.root (a local cargo root, never ~/.cargo) on first use, and AFL++ built by it.
# Where that cannot be done (no network to crates.io, no make or C compiler), the script says so
# and exits 0 without fuzzing: the run is skipped, not failed. A crash fails the run (exit 1);
# each is saved under fuzz/out/TARGET/default/crashes and replayed by `cargo test` in fuzz/.
#
# Long run (the goal is no panic in 1e7 executions per target; at the rates printed below that is
# hours per target): tools/fuzz/run.sh 14400 TARGET, one target per core, and look at the
# execs_done and saved_crashes it prints.
set -euo pipefail
cd "$(dirname "$0")/../.."
repo=$PWD
seconds=${1:-30}
if [[ "$seconds" == --seeds-only ]]; then seconds=0; fi
shift || true
targets=("$@")
if [[ ${#targets[@]} -eq 0 ]]; then
    targets=(rig_document handles pose animations scribbles png_trace_mesh)
fi

# Seeds: every bundled file of each kind (a rig document is made by hand from the README's
# example in docs/formats.md when no rig has been written).
seeds=fuzz/seeds
mkdir -p "$seeds"/{rig_document,handles,pose,animations,scribbles,png_trace_mesh}
cp assets/character/handles.json "$seeds/handles/"
cp assets/character/poses/*.json "$seeds/pose/"
cp assets/character/animations.json "$seeds/animations/"
# The examples of docs/formats.md, by their tag.
python3 - "$repo/docs/formats.md" "$seeds" <<'PY'
import re, sys, pathlib
text = pathlib.Path(sys.argv[1]).read_text()
out = pathlib.Path(sys.argv[2])
for n, (tag, body) in enumerate(re.findall(r"```json (\w+)\n(.*?)```", text, re.S)):
    kind = {"rig": "rig_document", "handles": "handles", "pose": "pose",
            "animations": "animations", "scribbles": "scribbles"}.get(tag)
    if kind:
        (out / kind / f"formats-{n}.json").write_text(body)
PY
for png in assets/character/head.png assets/character/tail.png assets/character/bag.png; do
    cp "$png" "$seeds/png_trace_mesh/"
done
if [[ "$seconds" == 0 ]]; then
    echo "fuzz: seeds in $seeds"
    exit 0
fi

root=$repo/tools/fuzz/.root
export PATH=$root/bin:$PATH
if ! command -v cargo-afl >/dev/null 2>&1; then
    echo "fuzz: installing cargo-afl into $root (first use)"
    if ! cargo install --locked --version 0.18.2 --root "$root" cargo-afl >"$repo/target/fuzz-install.log" 2>&1; then
        echo "fuzz: SKIPPED: cannot install cargo-afl (see target/fuzz-install.log)"
        exit 0
    fi
fi
if ! cargo afl config --build >"$repo/target/fuzz-afl-build.log" 2>&1 \
    && ! grep -q "was already built" "$repo/target/fuzz-afl-build.log"; then
    echo "fuzz: SKIPPED: cargo-afl cannot build AFL++ here (needs make and a C compiler; see target/fuzz-afl-build.log)"
    exit 0
fi
cd fuzz
cargo afl build --release --locked 2>"$repo/target/fuzz-build.log" || cargo afl build --release 2>>"$repo/target/fuzz-build.log"
failed=0
mkdir -p out
for target in "${targets[@]}"; do
    out=out/$target
    rm -rf "$out"
    # No UI, no CPU governor or core-pattern demands (CI containers cannot change them); the
    # run ends after $seconds s.
    AFL_NO_UI=1 AFL_SKIP_CPUFREQ=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 \
        AFL_NO_AFFINITY=1 \
        cargo afl fuzz -V "$seconds" -t 2000+ -i "seeds/$target" -o "$out" \
        "target/release/$target" >"$out.log" 2>&1 || true
    stats=$out/default/fuzzer_stats
    if [[ ! -f $stats ]]; then
        echo "fuzz: $target: AFL++ did not run (see fuzz/$out.log)"
        failed=1
        continue
    fi
    execs=$(awk -F' *: *' '$1=="execs_done"{print $2}' "$stats")
    crashes=$(awk -F' *: *' '$1=="saved_crashes"{print $2}' "$stats")
    hangs=$(awk -F' *: *' '$1=="saved_hangs"{print $2}' "$stats")
    rate=$(awk -F' *: *' '$1=="execs_per_sec"{print $2}' "$stats")
    echo "fuzz: $target: $execs executions in ${seconds} s ($rate/s), $crashes crashes, $hangs hangs"
    if [[ "$crashes" != 0 ]]; then failed=1; fi
done
exit $failed
