#!/usr/bin/env bash
# Output size, the way the project tracks it: for every mesh of a folder
# (default ../shared/meshes), the input vertices and the vertices added by
# each of the 18 DelMesh combinations, by -s 3 and by --shells with -s 2 and
# -s 4 (each with every DS), the best of them, the
# same with --prune (keys prefixed "P:"), and the best public tool's figure
# from ../shared/reference/peers.md (tools whose output is not a Delaunay
# mesh do not count). "lb" is a proven lower bound for any method that keeps
# the geometry: the input's non-Delaunay edges between two single-face
# planar regions, each of which needs a vertex on it.
# Output format (stable; one line per mesh, space-separated key=value):
#   mesh=NAME input=V lb=L s-0-m=N s-0=N ... p-2=N s3-s-m=N s3-q-m=N s3-p-m=N
#     sh2-s=N sh4-s=N sh2-q=N sh4-q=N sh2-p=N sh4-p=N best=N best_combo=C
#     P:s-0-m=N ... P:sh4-p=N pbest=N pbest_combo=C smallest=N peer=N ratio=R pratio=R sratio=R
# ("smallest" is what `--smallest` writes: the fewest of its 24 pruned settings.)
# A combination that fails (work limit, or edges that can be neither split
# nor flipped) prints "limit".
set -uo pipefail
cd "$(dirname "$0")/.."
dir=${1:-../shared/meshes}
peers=${PEERS:-../shared/reference/peers.md}
cargo build --release --quiet || exit 1
bin=${DELMESH:-target/release/delmesh}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

peer_of() { # best public figure for a mesh: smaller of the two tools' "added" columns that are numbers
  awk -F'|' -v m="$1" '$2 ~ "^ *"m"( |$)" {
      best = ""
      for (i = 3; i <= NF; i++) if (i == 4 || i == 7) { v = $i; gsub(/ /, "", v); if (v ~ /^[0-9]+$/ && (best == "" || v + 0 < best + 0)) best = v }
      print best }' "$peers" 2>/dev/null | head -1
}

# record KEY N: appends KEY=N (prefixed with $prefix) to $line and keeps the
# smallest in $sbest/$sbest_combo ("limit" never counts).
record() {
  line="$line $prefix$1=$2"
  if [ "$2" != limit ] && { [ -z "$sbest" ] || [ "$2" -lt "$sbest" ]; }; then sbest=$2 sbest_combo=$1; fi
}

# added FLAGS...: the vertices one run adds, or "limit" if it fails.
added() {
  local n
  n=$("$bin" -i "$mesh" -o "$out/x.obj" --max-added 2000000 "$@" 2>/dev/null | sed -n 's/^output .* \([0-9]*\) added vert[a-z]*$/\1/p')
  echo "${n:-limit}"
}

# sweep FLAGS...: appends the 27 keys (prefixed with $prefix) to $line and
# sets $sbest/$sbest_combo.
sweep() {
  "$bin" -i "$mesh" -o "$out/$name.obj" -all --max-added 2000000 "$@" > "$out/table" 2>/dev/null
  sbest="" sbest_combo=""
  for ds in s q p; do for s in 0 1 2; do for m in -m ""; do
    key="$ds-$s$m"
    row=$(grep -v "^note" "$out/table" | grep " $name-$key.obj\$")
    if [ -n "$row" ]; then n=$(echo "$row" | awk '{print $(NF-4)}'); else n=limit; fi
    record "$key" "$n"
  done; done; done
  for ds in stack queue pqueue; do
    record "s3-${ds:0:1}-m" "$(added -s 3 -ds "$ds" "$@")"
  done
  for ds in stack queue pqueue; do for s in 2 4; do
    record "sh$s-${ds:0:1}" "$(added --shells -s "$s" -ds "$ds" "$@")"
  done; done
}

ratio_of() { # best peer
  if [ -n "$2" ] && [ -n "$1" ] && [ "$2" -gt 0 ]; then awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; else echo NA; fi
}

for mesh in "$dir"/*.obj; do
  name=$(basename "$mesh" .obj)
  line="mesh=$name"
  "$bin" -i "$mesh" -o "$out/x.obj" --no-refine > "$out/info" 2>/dev/null
  input=$(sed -n 's/^input .*: \([0-9]*\) vertices.*/\1/p' "$out/info")
  lb=$(sed -n 's/^bound .* at least \([0-9]*\) vert.*/\1/p' "$out/info")
  line="$line input=$input lb=${lb:-NA}"
  prefix="" ; sweep
  best=$sbest best_combo=$sbest_combo
  line="$line best=$best best_combo=$best_combo"
  prefix="P:" ; sweep --prune
  line="$line pbest=$sbest pbest_combo=$sbest_combo"
  smallest=$("$bin" -i "$mesh" -o "$out/x.obj" --smallest --max-added 2000000 2>/dev/null | sed -n 's/^output .* \([0-9]*\) added vert[a-z]*$/\1/p')
  peer=$(peer_of "$name")
  echo "$line smallest=${smallest:-failed} peer=${peer:-NA} ratio=$(ratio_of "$best" "$peer") pratio=$(ratio_of "$sbest" "$peer") sratio=$(ratio_of "$smallest" "$peer")"
done
