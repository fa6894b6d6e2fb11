#!/usr/bin/env bash
# There, from ~/src: bash .devsrc/poll.sh MAX_SECONDS (copy it to .devsrc/poll.sh); rc 3 while the job runs.
# Waits for the job's DONE mark, then brings ~/chunks back (logs tail-trimmed, everything under 16 MiB per file).
max=${1:-540}
for _ in $(seq 1 $((max / 5))); do [ -e ~/chunks/DONE ] && break; sleep 5; done
for f in ~/chunks/*/*.log; do echo "== $f"; grep -v "^\s*$" "$f" | tail -n 3; done
tar czf "$OUT/chunks.tgz" -C ~/chunks . && ls -la "$OUT"
[ -e ~/chunks/DONE ] || { echo "still running at $(date +%T)"; exit 3; }
