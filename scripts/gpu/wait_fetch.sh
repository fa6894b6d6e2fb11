#!/usr/bin/env bash
# Poll a job started by scripts/gpu/launch_job.sh; once it has stopped (~/chunks/DONE), pack ~/chunks into $OUT.
#   There: bash scripts/gpu/wait_fetch.sh MAX_SECONDS TAG
# Waits up to MAX_SECONDS (keep it under the call's limit) printing the queue log's tail; when the job is done, writes
# $OUT/TAG.tgz.partaa, ab, ... (15 MB pieces: a call brings back at most 8 files of 16 MiB). Here, join them with
#   cat /work/.device/<n>/TAG.tgz.part* | tar xzf -
# rc 3 when the job is still running at MAX_SECONDS (nothing packed: call it again).
set -uo pipefail
max=${1:?usage: wait_fetch.sh MAX_SECONDS TAG}
tag=${2:?usage: wait_fetch.sh MAX_SECONDS TAG}
for _ in $(seq 1 $((max / 5))); do
  [ -e ~/chunks/DONE ] && break
  sleep 5
done
tail -n 15 ~/chunks/job.log 2>/dev/null
[ -e ~/chunks/DONE ] || { echo "still running at $(date +%T)"; exit 3; }
cp ~/src/.devsrc/COMMIT ~/chunks/ 2>/dev/null
cd ~/chunks && tar czf - g1_eval job.log job.out tasks.txt END COMMIT 2>/dev/null | split -b 15M - "$OUT/$tag.tgz.part"
ls -la "$OUT"
