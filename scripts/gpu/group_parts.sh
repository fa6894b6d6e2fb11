#!/usr/bin/env bash
# Splits the wheels in OUTDIR/dl larger than LIMIT bytes into WHEEL.piece.NN and groups everything into
# OUTDIR/part1..N (first fit, largest first), each with a copy of install_part.sh. Used by pack_wheels.sh and
# repack_wheels.sh.
#
#   scripts/gpu/group_parts.sh OUTDIR LIMIT_BYTES
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=$1
limit=$2
for w in "$out"/dl/*.whl; do
  if [ "$(stat -c %s "$w")" -gt "$limit" ]; then split -b "$limit" -d -a 2 "$w" "$w.piece." && rm "$w"; fi
done
n=0
for f in $(ls -S "$out/dl"); do
  size=$(stat -c %s "$out/dl/$f"); placed=
  for ((i = 1; i <= n; i++)); do
    if [ $(( $(du -sb "$out/part$i" | cut -f1) + size )) -le "$limit" ]; then
      mv "$out/dl/$f" "$out/part$i/"; placed=1; break
    fi
  done
  if [ -z "$placed" ]; then n=$((n + 1)); mkdir -p "$out/part$n"; mv "$out/dl/$f" "$out/part$n/"; fi
done
rmdir "$out/dl"
for ((i = 1; i <= n; i++)); do cp "$here/install_part.sh" "$out/part$i/"; done
echo "$n parts in $out:"; du -sh "$out"/part*
