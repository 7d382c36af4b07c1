#!/usr/bin/env bash
# Rebuilds the bundled motion library, assets/motions/*.bvh, from the packages it comes from
# (assets/motions/SOURCES.md says what each file is):
#
#   tools/motions/fetch.sh            # downloads into a temp folder, writes assets/motions/
#
# - Debian's assimp-testmodels (the CMU clips as BVH): `apt-get download`, unpacked with
#   `dpkg-deb -x` in the temp folder (nothing is installed);
# - PyPI's pybullet (pybullet_data carries the DeepMimic clips): `pip download` of one wheel,
#   unzipped in the temp folder (not installed, not built);
# - the wave is keyed by tools/motions/key_wave.py.
# Needs apt-get (run `apt-get update` first on a fresh machine), pip, unzip, python3. Then
# `git diff --stat assets/motions` shows whether anything changed; `cargo test --test
# motion_library` checks the set.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=assets/motions
tools=tools/motions
assimp_version=5.2.5~ds0-1
pybullet_version=3.2.7
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

(cd "$tmp" && { apt-get download "assimp-testmodels=$assimp_version" 2>/dev/null \
    || { echo "fetch: assimp-testmodels $assimp_version not offered; taking the current version" >&2
         apt-get download assimp-testmodels; }; })
dpkg-deb -x "$tmp"/assimp-testmodels_*.deb "$tmp/assimp"
cmu=$tmp/assimp/usr/share/assimp/models/BVH

pip download --quiet --no-deps --only-binary=:all: --python-version 3.11 \
    --platform manylinux_2_17_x86_64 -d "$tmp/pip" "pybullet==$pybullet_version"
unzip -q "$tmp"/pip/pybullet-*.whl 'pybullet_data/data/motions/humanoid3d_*' -d "$tmp/pybullet"
deepmimic=$tmp/pybullet/pybullet_data/data/motions

mkdir -p "$out"
# CMU subject 1, trial 1 (playground: forward jumps, turn around), 120 fps. Frame 0 of the
# file is the conversion's T-pose and is left out; the subject stands from frame 1 until the
# crouch of the first jump (about frame 150).
python3 "$tools/cut_bvh.py" "$cmu/01_01.bvh" "$out/idle.bvh" 1 144
python3 "$tools/cut_bvh.py" "$cmu/01_01.bvh" "$out/jump_forward.bvh" 145 336
for clip in walk run jump; do
    python3 "$tools/deepmimic_to_bvh.py" "$deepmimic/humanoid3d_$clip.txt" "$out/$clip.bvh"
done
python3 "$tools/key_wave.py" "$out/wave.bvh"
ls -l "$out"/*.bvh
