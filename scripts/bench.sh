#!/usr/bin/env bash
# End-to-end benchmark of the release binary, rerunnable by anyone:
#   scripts/bench.sh [RUNS]        (default 5 runs per measurement)
# Meshes: armadillo (../shared/meshes, 52k faces), the dragon at ~202k faces
# and the full dragon (871k faces), both fetched by scripts/fetch-dragon.sh
# and read with --repair (they are real scans with defects), and the full
# dragon once more as an OBJ repaired beforehand (read like the armadillo:
# the linear-scaling comparison). Per mesh it
# prints the faces, the median seconds of each phase as delmesh reports them,
# the median end-to-end wall time (hyperfine if installed, else a loop), the
# peak memory (/usr/bin/time -v), and the I/O floor: the same command with
# --no-refine (read, validate, write), and the wall time again with the
# output removed before each run (a new file, not one replaced). Also `-all`
# on armadillo, parallel
# against sequential (--jobs 1), and --prune on the armadillo and the
# dragon at 202k faces. Then every mesh of ../shared/meshes that
# ../shared/reference/peers.md times, against those figures, with the
# default build and with a statically linked one (the musl build where its
# target is installed, else glibc's; built into target/static, README:
# Performance). Timings are never asserted.
# DELMESH_BIN=path measures that binary instead of building
# target/release/delmesh (and no static one).
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
static_bin=
if [ -n "${DELMESH_BIN:-}" ]; then
  bin=$(realpath "$DELMESH_BIN") # another build, e.g. the static one (README, Performance)
else
  cargo build --release --quiet
  bin=${CARGO_TARGET_DIR:-$PWD/target}/release/delmesh
  # A statically linked build of the README (Performance), in a target
  # folder of its own so that it leaves the default build alone: the peer
  # table below times both (a process starts sooner without the dynamic
  # loader). The musl build where its target is installed, else glibc's
  # static build at a fixed address. Skipped, with a note and the build's
  # last error line, if it fails (as where glibc's static libraries are
  # missing).
  static_dir=${CARGO_TARGET_DIR:-$PWD/target}/static
  if rustup target list --installed 2>/dev/null | grep -qx x86_64-unknown-linux-musl; then
    static_kind="the musl build"
    if CARGO_TARGET_DIR=$static_dir cargo build --release --quiet --bin delmesh \
      --target x86_64-unknown-linux-musl 2>"$out/static.err"; then
      static_bin=$static_dir/x86_64-unknown-linux-musl/release/delmesh
    fi
  else
    static_kind="glibc, statically linked at a fixed address"
    if CARGO_TARGET_DIR=$static_dir cargo rustc --release --quiet --bin delmesh -- \
      -C target-feature=+crt-static -C relocation-model=static \
      2>"$out/static.err"; then
      static_bin=$static_dir/release/delmesh
    fi
  fi
fi
# Timed from fresh copies, as an installed binary is run (`cargo install`
# copies it): one the linker has just written is slower to start while it
# stays in the page cache (about 0.03 ms a process in the thirty-seventh
# session, 7 more page faults).
cp "$bin" "$out/delmesh" && bin=$out/delmesh
if [ -n "$static_bin" ]; then
  cp "$static_bin" "$out/delmesh-static" && static_bin=$out/delmesh-static
fi
data=$(scripts/fetch-dragon.sh 2>/dev/null || true)

median() { sort -g | awk '{a[NR]=$1} END {print (NR%2==1) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }

wall() { # median wall seconds of a command
  wall_new "" "$@"
}

wall_new() { # as wall, with FILE (if not empty) removed before each run
  local file=$1; shift
  if command -v hyperfine >/dev/null; then
    local prepare=()
    [ -n "$file" ] && prepare=(--prepare "rm -f $file")
    hyperfine -N --warmup 1 --runs "$runs" "${prepare[@]}" --export-json "$out/h.json" "$*" >/dev/null 2>&1
    python3 -c "import json;print('%.4f' % json.load(open('$out/h.json'))['results'][0]['median'])"
  else
    # $EPOCHREALTIME (bash 5) reads the clock without a process of its
    # own: two `date` processes per run would add about 2 ms to each.
    for _ in $(seq "$runs"); do
      [ -n "$file" ] && rm -f "$file"
      s=$EPOCHREALTIME; "$@" >/dev/null; e=$EPOCHREALTIME
      echo "$e - $s" | bc -l
    done | median
  fi
}

bench_mesh() { # name path [flags...]
  local name=$1 path=$2; shift 2
  [ -f "$path" ] || { echo "$name: $path missing, skipped"; return; }
  local cmd=("$bin" -i "$path" -o "$out/o.obj" "$@")
  for _ in $(seq "$runs"); do "${cmd[@]}" | grep '^seconds'; done > "$out/phases"
  local faces
  # Faces in the file ("N vertices, N faces" or, repaired, "... (N faces in the file)").
  faces=$("${cmd[@]}" | sed -n -e 's/^input .*(\([0-9]*\) faces in the file).*/\1/p;t' \
    -e 's/^input .* vertices, \([0-9]*\) faces.*/\1/p')
  local phase
  printf '%-12s %8s faces' "$name" "$faces"
  for phase in read build refine write; do
    printf '  %s %s' "$phase" "$(sed -n "s/.*$phase \([0-9.]*\).*/\1/p" "$out/phases" | median)"
  done
  local total floor mem new
  total=$(wall "${cmd[@]}")
  floor=$(wall "${cmd[@]}" --no-refine)
  mem=$(/usr/bin/time -v "${cmd[@]}" 2>&1 >/dev/null | sed -n 's/.*Maximum resident set size (kbytes): //p')
  # Each run above replaces the previous run's output; a run writing a new
  # file is spared what ext4 does at such a rename (it allocates the new
  # file's blocks there: auto_da_alloc).
  new=$(wall_new "$out/o.obj" "${cmd[@]}")
  printf '  | total %s s  I/O floor %s s  (x%.2f)  peak %s MB  %.2f us/face  | new file %s s  %.2f us/face\n' \
    "$total" "$floor" "$(echo "$total / $floor" | bc -l)" "$((mem / 1024))" \
    "$(echo "$total * 1000000 / $faces" | bc -l)" "$new" "$(echo "$new * 1000000 / $faces" | bc -l)"
}

if command -v hyperfine >/dev/null; then
  timer=$(hyperfine --version)
else
  timer="a shell loop (hyperfine is not installed: Debian's package hyperfine)"
fi
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs); median of $runs runs; wall times by $timer"
bench_mesh armadillo ../shared/meshes/armadillo.obj
bench_mesh dragon-202k "$data/dragon_vrip_res2.ply.gz" --repair
bench_mesh dragon-871k "$data/dragon_vrip.ply.gz" --repair
# Linear scaling, like for like: the same pipeline as the armadillo (an OBJ
# that needs no repair), on the full dragon once repaired and converted.
if [ -f "$data/dragon_vrip.ply.gz" ]; then
  "$bin" -q -i "$data/dragon_vrip.ply.gz" --repair --repaired "$out/dragon.obj" --no-refine -o "$out/x.obj"
  bench_mesh dragon-obj "$out/dragon.obj"
fi

mkdir -p "$out/all"
par=$(wall "$bin" -q -i ../shared/meshes/armadillo.obj -o "$out/all/a.obj" -all)
seq1=$(wall "$bin" -q -i ../shared/meshes/armadillo.obj -o "$out/all/a.obj" -all --jobs 1)
printf -- '-all armadillo: %s s with one job per core, %s s with --jobs 1 (x%.2f)\n' "$par" "$seq1" "$(echo "$seq1 / $par" | bc -l)"

# --prune: the construction then pruning, median wall time of the whole
# process (no repetitions of the full dragon, about two minutes: set
# BENCH_PRUNE_FULL=1 for one run of it).
echo
prune_row() { # name path [flags...]
  local name=$1 path=$2; shift 2
  [ -f "$path" ] || return 0
  local w; w=$(wall "$bin" -q -i "$path" -o "$out/p.obj" --prune "$@")
  printf -- '--prune %-12s %8s s  (%s)\n' "$name" "$w" "$("$bin" -i "$path" -o "$out/p.obj" --prune "$@" 2>&1 | grep '^prune')"
}
prune_row armadillo ../shared/meshes/armadillo.obj
prune_row dragon-202k "$data/dragon_vrip_res2.ply.gz" --repair
if [ "${BENCH_PRUNE_FULL:-0}" = 1 ] && [ -f "$data/dragon_vrip.ply.gz" ]; then
  s=$EPOCHREALTIME
  line=$("$bin" -i "$data/dragon_vrip.ply.gz" --repair -o "$out/p.obj" --prune 2>&1 | grep '^prune')
  e=$EPOCHREALTIME
  printf -- '--prune %-12s %8.2f s  (%s; one run)\n' dragon-871k "$(echo "$e - $s" | bc -l)" "$line"
fi

# Mesh by mesh against the public C++ re-implementation of Liu et al.
# (SplitToDelaunay, ../shared/reference/peers.md: refine s, total s), with
# delmesh's default settings: median refine seconds (full precision, from
# --stats-json) and median wall time of the whole process (hyperfine).
peers="bunny 0.0026 0.016
elephant 0.0031 0.023
fandisk 0.0076 0.048
armadillo 0.111 0.294
nefertiti 0.0005 0.006
knot 0.0016 0.017
rotor 0.016 0.026
anchor 0.456 0.477"
printf '\n%-10s %12s %12s %8s | %10s %10s %8s | %12s %8s\n' mesh refine peer-refine ratio total peer-total ratio \
  static-total ratio
while read -r name prefine ptotal; do
  mesh=../shared/meshes/$name.obj
  [ -f "$mesh" ] || continue
  for _ in $(seq "$runs"); do
    "$bin" -q -i "$mesh" -o "$out/p.obj" --stats-json "$out/p.json"
    python3 -c "import json;print('%.9f' % json.load(open('$out/p.json'))['runs'][0]['seconds_refine'])"
  done > "$out/refine"
  r=$(median < "$out/refine")
  t=$(wall "$bin" -q -i "$mesh" -o "$out/p.obj")
  printf '%-10s %12.6f %12s %8.1f | %10.4f %10s %8.1f' "$name" "$r" "$prefine" \
    "$(echo "$prefine / $r" | bc -l)" "$t" "$ptotal" "$(echo "$ptotal / $t" | bc -l)"
  if [ -n "$static_bin" ]; then
    t=$(wall "$static_bin" -q -i "$mesh" -o "$out/p.obj")
    printf ' | %12.4f %8.1f\n' "$t" "$(echo "$ptotal / $t" | bc -l)"
  else
    printf ' | %12s %8s\n' - -
  fi
done <<< "$peers"
if [ -n "$static_bin" ]; then
  echo "(static-total: $static_kind)"
else
  if [ -n "${DELMESH_BIN:-}" ]; then
    echo "(static-total: not measured with DELMESH_BIN)"
  else
    echo "(static-total: the static build failed: $(grep -m1 -i error "$out/static.err" || tail -n1 "$out/static.err"))"
  fi
fi

# Many small files: the seven small meshes above, 30 copies each (210
# files), refined with one process per file (a shell loop), and with one
# `delmesh batch` (two files at a time on two cores, then one at a time).
mkdir -p "$out/many/in" "$out/many/out"
while read -r name _ _; do
  [ "$name" = armadillo ] && continue
  [ -f "../shared/meshes/$name.obj" ] || continue
  for i in $(seq 30); do cp "../shared/meshes/$name.obj" "$out/many/in/$name-$i.obj"; done
done <<< "$peers"
files=$(ls "$out/many/in" | wc -l)
cat > "$out/loop.sh" <<LOOP
for f in $out/many/in/*.obj; do "$bin" -q -i "\$f" -o "$out/many/out/\${f##*/}"; done
LOOP
loop=$(wall bash "$out/loop.sh")
together=$(wall "$bin" batch -q -d "$out/many/out" "$out/many/in")
one=$(wall "$bin" batch -q -j 1 -d "$out/many/out" "$out/many/in")
printf '\n%s small files: a process each %s s, batch %s s (x%.2f), batch -j 1 %s s (x%.2f)\n' "$files" \
  "$loop" "$together" "$(echo "$loop / $together" | bc -l)" "$one" "$(echo "$loop / $one" | bc -l)"
