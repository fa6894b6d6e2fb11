#!/usr/bin/env bash
# Start a study's job on the GPU machine in the background, time-boxed (issue 9's MPM queues; the ablation-circle runs' way).
#   There, from the device call's repository root, after the last wheel part's --install, in the same call:
#     bash scripts/gpu/launch_job.sh SECONDS        (SECONDS: the job's END, counted from now)
# Needs here: .devsrc/src.tar + .devsrc/job.sh (scripts/gpu/snapshot_src.sh, then copy the job script), optionally
# .devsrc/row/ (run folders to resume) and .devcache/warpcache.tgz (scripts/gpu/warm_cache.py); carry .devsrc and
# .devcache/warpcache.tgz. Unpacks the snapshot into ~/src with artifacts/ and .devsrc/ beside it, the Warp cache into
# ~/.gmloco-warp-cache (what scripts/gpu/env.sh points Warp at), and starts `bash .devsrc/job.sh END` with setsid, so
# it runs on between calls while the machine is held. Poll and fetch with scripts/gpu/wait_fetch.sh.
set -euo pipefail
secs=${1:?usage: launch_job.sh SECONDS (the time box of the job, from now)}
[ -f .devsrc/src.tar ] && [ -f .devsrc/job.sh ] || { echo "no .devsrc/src.tar or .devsrc/job.sh: carry .devsrc" >&2; exit 2; }
rm -rf ~/src ~/chunks && mkdir -p ~/src ~/chunks ~/.gmloco-warp-cache
tar -xf .devsrc/src.tar -C ~/src
cp -r artifacts .devsrc ~/src/
if [ -f .devcache/warpcache.tgz ]; then
  tar xzf .devcache/warpcache.tgz -C ~/.gmloco-warp-cache && echo "Warp cache: $(ls ~/.gmloco-warp-cache/*/ | wc -l) module folders"
else
  echo "no .devcache/warpcache.tgz: every kernel compiles here first (~4.5 min)"
fi
end=$(( $(date +%s) + secs ))
echo "$end" > ~/chunks/END
cd ~/src && (setsid nohup bash .devsrc/job.sh "$end" > ~/chunks/job.out 2>&1 < /dev/null &)
echo "job started at $(date +%T), time box until $(date -d "@$end" +%T), code $(cat ~/src/.devsrc/COMMIT 2>/dev/null)"
