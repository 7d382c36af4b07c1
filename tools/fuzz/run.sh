#!/usr/bin/env bash
# Coverage-guided fuzzing of sinew's readers with AFL++ (cargo-afl, stable Rust).
#
#   tools/fuzz/run.sh [--quick] [SECONDS_PER_TARGET] [TARGET...]   # default 30 s each, every target
#   tools/fuzz/run.sh --seeds-only                                 # only (re)make the seed corpus
#
# --quick (what .ci/run uses): build at opt-level 1 with 16 codegen units instead of cargo-afl's
# opt-level 3 and one codegen unit. A cold build then takes about two thirds of the time (12.7 min
# against 19.5 min measured on a loaded machine; sinew itself 224 s against 532 s), for fewer
# executions per second. Targets run FUZZ_JOBS (default 2) at a time. After fuzzing,
# `cargo afl test --release` runs fuzz/tests/replay.rs over the seeds and whatever AFL++ saved
# (its crashes and its queue), with the fuzz build's compiled crates.
#
# Targets (fuzz/src/lib.rs): rig_document, handles, pose, animations, scribbles, png_trace_mesh,
# bvh, psd, ora, spine_script, batch_manifest. The seed corpus (fuzz/seeds/TARGET) comes from the
# bundled assets and test fixtures (bvh: three frames of two bundled motions, small enough for
# AFL++; psd: tests/fixtures/layered and the small files tools/fuzz/psd_seeds.py writes; ora: the
# fixtures and their stack.xml, which the target zips with fixed layers; spine_script: the
# fixture's JSON; batch_manifest: docs/formats.md's example) and hand-written tools/fuzz/seeds/.
# docs/fuzzing.md has the figures of the last long runs.
# cargo-afl is installed into tools/fuzz/.root (a local cargo root, never ~/.cargo) on first
# use, and AFL++ built by it. Where that cannot be done (no network to crates.io, no make or C compiler), the script says so
# and exits 0 without fuzzing: the run is skipped, not failed. A crash fails the run (exit 1);
# each is saved under fuzz/out/TARGET/default/crashes and replayed by `cargo test` in fuzz/.
#
# Long run (the goal is no panic in 1e7 executions per target; at the rates printed below that is
# hours per target): tools/fuzz/run.sh 14400 TARGET, one target per core, and look at the
# execs_done and saved_crashes it prints.
set -euo pipefail
cd "$(dirname "$0")/../.."
repo=$PWD
quick=0
if [[ "${1:-}" == --quick ]]; then
    quick=1
    shift
fi
seconds=${1:-30}
if [[ "$seconds" == --seeds-only ]]; then seconds=0; fi
shift || true
targets=("$@")
if [[ ${#targets[@]} -eq 0 ]]; then
    targets=(rig_document handles pose animations scribbles png_trace_mesh bvh psd ora spine_script
        batch_manifest)
fi

# Seeds: every bundled file of each kind (a rig document is made by hand from the
# example in docs/formats.md when no rig has been written).
seeds=fuzz/seeds
mkdir -p "$seeds"/{rig_document,handles,pose,animations,scribbles,png_trace_mesh,bvh,psd,ora,spine_script,batch_manifest}
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
            "animations": "animations", "scribbles": "scribbles",
            "batch": "batch_manifest"}.get(tag)
    if kind:
        (out / kind / f"formats-{n}.json").write_text(body)
PY
# BVH: hand-written files (odd layouts, a bad one) and three frames of a DeepMimic and of a CMU
# clip of the bundled library.
cp tools/fuzz/seeds/bvh/*.bvh "$seeds/bvh/"
python3 tools/motions/cut_bvh.py assets/motions/walk.bvh "$seeds/bvh/walk-3.bvh" 0 2
python3 tools/motions/cut_bvh.py assets/motions/idle.bvh "$seeds/bvh/idle-3.bvh" 0 2
for png in assets/character/head.png assets/character/tail.png assets/character/bag.png; do
    cp "$png" "$seeds/png_trace_mesh/"
done
# Layered files: the fixtures written by real tools (psd-tools, Krita; the 190 kB bundled
# character left out: AFL++ works best on small inputs) and small hand-made PSDs; for ORA also
# the stack.xml alone (the target zips it with krita.ora's layers).
layered=tests/fixtures/layered
cp "$layered"/{character,cmyk,deep16,gray,krita,pivots}.psd "$layered/character.psb" "$seeds/psd/"
python3 tools/fuzz/psd_seeds.py "$seeds/psd"
cp "$layered/krita.ora" tests/fixtures/autorig-real/goblin.ora "$seeds/ora/"
python3 -c 'import sys, zipfile; sys.stdout.buffer.write(zipfile.ZipFile(sys.argv[1]).read("stack.xml"))' \
    "$layered/krita.ora" >"$seeds/ora/krita-stack.xml"
cp tools/fuzz/seeds/ora/*.xml "$seeds/ora/"
cp "$layered/spine/character.json" tools/fuzz/seeds/spine_script/*.json "$seeds/spine_script/"
cp tools/fuzz/seeds/batch_manifest/*.json "$seeds/batch_manifest/"
if [[ "$seconds" == 0 ]]; then
    echo "fuzz: seeds in $seeds"
    exit 0
fi

mkdir -p "$repo/target"
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
if [[ $quick == 1 ]]; then
    # cargo-afl puts the user's RUSTFLAGS after its own `-C codegen-units=1`: the later wins.
    export AFL_OPT_LEVEL=1 RUSTFLAGS="-C codegen-units=16"
fi
bins=${CARGO_TARGET_DIR:-$PWD/target}/release
build_start=$SECONDS
cargo afl build --release --locked 2>"$repo/target/fuzz-build.log" || cargo afl build --release 2>>"$repo/target/fuzz-build.log"
echo "fuzz: built in $((SECONDS - build_start)) s"
failed=0
mkdir -p out
# One AFL++ run of a target; prints its figures, and a line with FAILED when it did not run or
# crashed.
fuzz_one() {
    local target=$1 out=out/$1
    rm -rf "$out"
    # No UI, no CPU governor or core-pattern demands (CI containers cannot change them); the
    # run ends after $seconds s.
    AFL_NO_UI=1 AFL_SKIP_CPUFREQ=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 \
        AFL_NO_AFFINITY=1 \
        cargo afl fuzz -V "$seconds" -t 2000+ -i "seeds/$target" -o "$out" \
        "$bins/$target" >"$out.log" 2>&1 || true
    local stats=$out/default/fuzzer_stats
    if [[ ! -f $stats ]]; then
        echo "fuzz: $target: FAILED: AFL++ did not run (see fuzz/$out.log)"
        return
    fi
    local execs crashes hangs rate
    execs=$(awk -F' *: *' '$1=="execs_done"{print $2}' "$stats")
    crashes=$(awk -F' *: *' '$1=="saved_crashes"{print $2}' "$stats")
    hangs=$(awk -F' *: *' '$1=="saved_hangs"{print $2}' "$stats")
    rate=$(awk -F' *: *' '$1=="execs_per_sec"{print $2}' "$stats")
    echo "fuzz: $target: $execs executions in ${seconds} s ($rate/s), $crashes crashes, $hangs hangs"
    if [[ "$crashes" != 0 ]]; then
        echo "fuzz: $target: FAILED: crashes saved in fuzz/$out/default/crashes"
    fi
}
jobs=${FUZZ_JOBS:-2}
results=$repo/target/fuzz-results.txt
: >"$results"
for ((i = 0; i < ${#targets[@]}; i += jobs)); do
    for target in "${targets[@]:i:jobs}"; do
        fuzz_one "$target" >>"$results" &
    done
    wait
done
cat "$results"
if grep -q FAILED "$results"; then failed=1; fi
# The replay test: every seed, crash and queue entry through the plain target functions
# (a crash shows its panic message and backtrace here).
if ! cargo afl test --release --locked --test replay >"$repo/target/fuzz-replay.log" 2>&1; then
    echo "fuzz: FAILED: the replay test (fuzz/tests/replay.rs) failed; see target/fuzz-replay.log"
    tail -n 40 "$repo/target/fuzz-replay.log"
    failed=1
else
    grep -E "^test |test result" "$repo/target/fuzz-replay.log" | sed 's/^/fuzz: replay: /'
fi
exit $failed
