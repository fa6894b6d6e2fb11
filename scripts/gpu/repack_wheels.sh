#!/usr/bin/env bash
# Regroups the wheel parts made by pack_wheels.sh into smaller parts, offline (no download):
#
#   PART_MB=7 scripts/gpu/repack_wheels.sh [OUTDIR]     (default .devwheels)
#
# The working tree travels with every device call and the call's total is capped at 64 MiB, so when the tree grows
# the parts must shrink: PART_MB + tree size (tracked and untracked-not-ignored files) must stay under 64 MiB.
# Split wheels (WHEEL.piece.NN) are joined back first, then split and grouped as pack_wheels.sh does.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=${1:-.devwheels}
limit=$(( ${PART_MB:-7} * 1024 * 1024 ))
[ -d "$out/part1" ] || { echo "no parts in $out: run scripts/gpu/pack_wheels.sh first" >&2; exit 1; }
tmp=$(mktemp -d "${out%/}.repack.XXXX")
find "$out"/part* -maxdepth 1 -type f ! -name install_part.sh -exec mv {} "$tmp"/ \;
for first in "$tmp"/*.piece.00; do  # join split wheels
  [ -e "$first" ] || continue
  cat "${first%.piece.00}".piece.* > "${first%.piece.00}" && rm "${first%.piece.00}".piece.*
done
rm -rf "$out" && mkdir -p "$out/dl" && mv "$tmp"/*.whl "$out/dl/" && rmdir "$tmp"
bash "$here/group_parts.sh" "$out" "$limit"
