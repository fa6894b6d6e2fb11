#!/usr/bin/env bash
# Packs the Python 3.12 wheels the GPU image lacks into parts that each fit one device call.
#
#   scripts/gpu/pack_wheels.sh [REQUIREMENTS] [OUTDIR]     (defaults: scripts/gpu/requirements-gpu.txt .devwheels)
#
# Wheels are fetched without dependencies for CPython 3.12 / x86_64 (the GPU image), so REQUIREMENTS names
# every package the image lacks. Source-only packages (antlr4-python3-runtime) are built into wheels here.
# Wheels larger than PART_MB (default 30) are split; pieces are grouped into OUTDIR/part1..N, each with a copy
# of install_part.sh. OUTDIR must be git-ignored; the working tree travels with every call as well, so
# PART_MB + tree size must stay under 64 MiB.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
req=${1:-$here/requirements-gpu.txt}
out=${2:-.devwheels}
limit=$(( ${PART_MB:-30} * 1024 * 1024 ))
rm -rf "$out" && mkdir -p "$out/dl" "$out/sdist"
plat=()
for p in manylinux_2_28 manylinux_2_27 manylinux_2_24 manylinux_2_17 manylinux2014 manylinux1 manylinux_2_5; do
  plat+=(--platform "${p}_x86_64")
done
plat+=(--platform any)
grep -vE '^\s*(#|$)' "$req" | sed 's/\s*#.*//' | while read -r pin; do
  if ! python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
      "${plat[@]}" -d "$out/dl" "$pin" 2>/dev/null; then
    echo "no wheel for $pin: building it from source"
    python3 -m pip download -q --no-deps --no-binary=:all: -d "$out/sdist" "$pin"
    python3 -m pip wheel -q --no-deps -w "$out/dl" "$out"/sdist/* && rm -f "$out"/sdist/*
  fi
done
rmdir "$out/sdist"
bash "$here/group_parts.sh" "$out" "$limit"
