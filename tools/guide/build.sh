#!/usr/bin/env bash
# Builds the user guide (docs/guide/, an mdBook) into target/guide/ and fails on any warning
# of mdbook's or a broken link.
#
#   tools/guide/build.sh
#
# mdbook is installed into tools/guide/.root (a local cargo root, never ~/.cargo) on first use,
# pinned, without its default features (watch, serve, search: none is needed to write HTML),
# as tools/fuzz/run.sh installs cargo-afl. Where it cannot be installed (no network to
# crates.io), the script says "SKIPPED" and why and exits 0: the build is skipped, not failed.
#
# Links are checked by tools/guide/links.py over the book's sources: a link to another chapter
# must name a file of docs/guide/src/ (and its #anchor a heading there), a link out of the book
# (docs/formats.md, an image, ARCHITECTURE.md) a file of the repository. The commands in the
# chapters are run by `cargo test --test guide_commands`, not here.
set -euo pipefail
cd "$(dirname "$0")/../.."
repo=$PWD
version=0.5.4
root=$repo/tools/guide/.root
mkdir -p "$repo/target"
if ! "$root/bin/mdbook" --version 2>/dev/null | grep -qx "mdbook v$version"; then
    echo "guide: installing mdbook $version into $root (first use)"
    if ! cargo install --locked --version "$version" --no-default-features --root "$root" mdbook \
        >"$repo/target/guide-install.log" 2>&1; then
        echo "guide: SKIPPED: cannot install mdbook (see target/guide-install.log)"
        exit 0
    fi
fi
out=$repo/target/guide
log=$repo/target/guide-build.log
rm -rf "$out"
if ! "$root/bin/mdbook" build docs/guide --dest-dir "$out" >"$log" 2>&1; then
    cat "$log"
    echo "guide: FAILED: mdbook build failed (above)"
    exit 1
fi
if grep -Ei '\b(WARN|ERROR)\b|warning' "$log"; then
    echo "guide: FAILED: mdbook warned (above; the whole log in target/guide-build.log)"
    exit 1
fi
python3 tools/guide/links.py docs/guide
echo "guide: built into target/guide/ ($(find "$out" -name '*.html' | wc -l) pages)"
