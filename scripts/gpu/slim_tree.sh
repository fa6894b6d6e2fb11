#!/usr/bin/env bash
# Shrink what a device call carries (the working tree must stay under 64 MiB with a wheel part; the committed tree
# is ~83 MB, most of it results/ and artifacts/ checkpoints the GPU jobs do not read).
#
#   scripts/gpu/slim_tree.sh on     untrack results/ and artifacts/ except the exported policies (policy.onnx /
#                                   policy.json) and ignore them in .git/info/exclude: the device sees ~12 MB
#   scripts/gpu/slim_tree.sh off    put the index back as HEAD has it and drop the exclude lines (before any commit!)
#   scripts/gpu/slim_tree.sh size   what a call would carry now (tracked + untracked-not-ignored), in MB
#
# Only the index and .git/info/exclude change: no file is deleted. Never commit while it is on (the commit would
# delete results/ and artifacts/ from main); `git status` shows the untracked paths as deleted while it is on.
set -euo pipefail
cd "$(git rev-parse --show-toplevel)"
ex=.git/info/exclude
mark="# slim_tree.sh"
size() {
  (git ls-files -z; git ls-files -z --others --exclude-standard) | du -cb --files0-from=- 2>/dev/null | tail -1 |
    awk '{printf "%.1f MB carried\n", $1 / 1e6}'
}
case "${1:-}" in
  on)
    git ls-files -z results artifacts | grep -zv -E '^artifacts/[^/]+/policy\.(onnx|json)$' |
      xargs -0 -r git rm -q --cached --
    grep -qx "$mark" "$ex" 2>/dev/null || printf '%s\n/results/\n/artifacts/\n' "$mark" >> "$ex"
    size ;;
  off)
    git reset -q -- results artifacts
    [ -f "$ex" ] && sed -i "/^$mark\$/,+2d" "$ex"
    size ;;
  size) size ;;
  *) echo "usage: $0 on|off|size" >&2; exit 2 ;;
esac
