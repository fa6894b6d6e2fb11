#!/usr/bin/env bash
# Pack the committed tree (HEAD) for the GPU machine: .devsrc/src.tar (git-ignored via .git/info/exclude).
# The device copies the *working tree*, including other people's uncommitted edits; a job run from this snapshot
# runs exactly the commit it names. There: carry [".devsrc"] and run scripts/gpu/launch_job.sh, or by hand
#   rm -rf ~/src && mkdir -p ~/src && tar -xf .devsrc/src.tar -C ~/src && cp -r artifacts ~/src/ && cd ~/src
#   source scripts/gpu/env.sh && <job>
set -euo pipefail
cd "$(git rev-parse --show-toplevel)"
mkdir -p .devsrc
grep -qx ".devsrc/" .git/info/exclude 2>/dev/null || echo ".devsrc/" >> .git/info/exclude
git archive --format=tar HEAD packages scripts benchmarks/gpu workflows conf pyproject.toml > .devsrc/src.tar
git rev-parse --short HEAD > .devsrc/COMMIT
echo "$(du -h .devsrc/src.tar | cut -f1) snapshot of $(cat .devsrc/COMMIT) in .devsrc/src.tar"
