#!/usr/bin/env bash
# Builds sinew's bbw_case example, writes the BBW cases into a temporary folder, installs the
# pinned libigl into a virtual environment and compares sinew's weights with igl.bbw.
# Exits non-zero when a case differs by more than the tolerance (0.01 unless --tolerance is
# given) or when libigl itself did not converge.
#
# Usage: tools/libigl-oracle/run.sh [compare_bbw.py options...]
#   env  VENV=DIR           the virtual environment (default: /tmp/sinew-libigl-venv)
#        CASE_ARGS="..."    extra arguments for the example (e.g. "--max-iterations 500",
#                           "--reference", or case names)
#        PYTHON=python3     the interpreter that creates the environment
#        CARGO_PROFILE_ARGS the example's build profile (default "--release"; "" for the dev
#                           profile, whose dependencies are optimized: no release build of
#                           every dependency when only libigl's figures are wanted)
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
venv="${VENV:-/tmp/sinew-libigl-venv}"
python="${PYTHON:-python3}"

cases="$(mktemp -d "${TMPDIR:-/tmp}/sinew-bbw-cases.XXXXXX")"
trap 'rm -rf "$cases"' EXIT

echo "== building and running examples/bbw_case.rs" >&2
(cd "$root" && cargo run --quiet ${CARGO_PROFILE_ARGS---release} --example bbw_case -- "$cases" ${CASE_ARGS:-})

if [[ ! -x "$venv/bin/python" ]]; then
  echo "== creating $venv" >&2
  "$python" -m venv "$venv"
fi
echo "== installing $here/requirements.txt" >&2
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$here/requirements.txt"

echo "== comparing with libigl" >&2
"$venv/bin/python" "$here/compare_bbw.py" "$cases" "$@"
