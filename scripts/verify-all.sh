#!/usr/bin/env bash
# Runs all 18 combinations (-all) on every mesh of a folder (default:
# ../shared/meshes) and verifies every output with `delmesh check`.
# Prints one line per mesh; exits non-zero if any run or check fails.
# Usage: scripts/verify-all.sh [MESH_DIR] [EXTRA delmesh FLAGS...]
set -uo pipefail
cd "$(dirname "$0")/.."
dir=${1:-../shared/meshes}
shift || true
cargo build --release --quiet || exit 1
bin=${DELMESH:-target/release/delmesh}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
status=0
for mesh in "$dir"/*.obj; do
  name=$(basename "$mesh" .obj)
  mkdir -p "$out/$name"
  note=""
  if ! "$bin" -q -i "$mesh" -o "$out/$name/$name.obj" -all "$@" 2>"$out/err"; then
    note=" ($(cat "$out/err"))"
    status=1
  fi
  pass=0 fail=0
  for f in "$out/$name"/*.obj; do
    [ -e "$f" ] || continue
    if "$bin" check "$mesh" "$f" >"$out/check" 2>&1; then
      pass=$((pass + 1))
    else
      fail=$((fail + 1)); status=1
      echo "  FAILED $(basename "$f"):"; grep -E "FAIL|error" "$out/check" | head -5 | sed 's/^/    /'
    fi
  done
  echo "$name: $pass outputs pass check, $fail fail$note"
done
exit $status
