#!/usr/bin/env bash
# Two builds of delmesh compared on the same meshes, runs interleaved (A, B,
# A, B, ...) so that this virtual machine's drift of speed falls on both:
#   scripts/compare.sh OLD_BINARY NEW_BINARY [RUNS] [MESH ...]
# RUNS defaults to 21; the meshes default to every mesh of ../shared/meshes
# that ../shared/reference/peers.md times, by name (armadillo, bunny, ...).
# For each mesh and binary it prints the median seconds of each phase and of
# the total as delmesh reports them (default settings, output replaced each
# run). Timings are never asserted; a baseline build comes from
#   git worktree add /tmp/base <commit> &&
#   (cd /tmp/base && CARGO_TARGET_DIR=/tmp/base-target cargo build --release)
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 2 ]; then
  echo "usage: scripts/compare.sh OLD_BINARY NEW_BINARY [RUNS] [MESH ...]" >&2
  exit 2
fi
old=$(realpath "$1")
new=$(realpath "$2")
runs=${3:-21}
shift $(($# < 3 ? $# : 3))
meshes=("$@")
if [ ${#meshes[@]} -eq 0 ]; then
  meshes=(bunny elephant fandisk armadillo nefertiti knot rotor anchor)
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# Both timed from fresh copies: a binary the linker has just written starts
# slower while it stays in the page cache (about 0.03 ms a process), which
# would favour the older build.
cp "$old" "$out/old-delmesh" && old=$out/old-delmesh
cp "$new" "$out/new-delmesh" && new=$out/new-delmesh

median() { sort -g | awk '{a[NR]=$1} END {print (NR%2==1) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }

printf '%-10s %-4s %8s %8s %8s %8s %8s\n' mesh bin read build refine write total
for mesh in "${meshes[@]}"; do
  input=../shared/meshes/$mesh.obj
  [ -f "$input" ] || { echo "$input: not found" >&2; exit 1; }
  : > "$out/old" && : > "$out/new"
  for run in $(seq "$runs"); do
    # Each goes first every other run: the second of two runs in a row is
    # about 1% faster here, whichever binary it is.
    order="old new"
    [ $((run % 2)) = 0 ] && order="new old"
    for which in $order; do
      bin=$old; [ $which = new ] && bin=$new
      # "seconds T total (read R, build B, refine F, write W)"
      "$bin" -i "$input" -o "$out/out.obj" | tail -n 1 | tr -d '(),' |
        awk '{print $5, $7, $9, $11, $2}' >> "$out/$which"
    done
  done
  for which in old new; do
    printf '%-10s %-4s' "$mesh" "$which"
    for col in 1 2 3 4 5; do
      printf ' %8s' "$(awk -v c=$col '{print $c}' "$out/$which" | median)"
    done
    echo
  done
done
