#!/usr/bin/env bash
# Copy to .devsrc/job.sh; start with launch_job.sh SECONDS; poll with `bash .devsrc/poll.sh MAX_SECONDS` where
# .devsrc/poll.sh is jobs/poll_files.sh.
# Reward A/B of PPO's adaptive learning rate and action std on gmloco's own G1 task (rigid ground, vanilla PPO, no
# encoder): the task's GM-Loco reward weights against mjlab-like leg action-rate penalties and against no
# termination penalty, three runs from scratch side by side on one GPU, as many iterations as the time box allows.
set -uo pipefail
end=$1
cd ~/src
source scripts/gpu/env.sh
mkdir -p ~/chunks/reward_ab
nvidia-smi --query-gpu=name,memory.total --format=csv > ~/chunks/gpu.txt 2>&1
iters=${REWARD_AB_ITERATIONS:-80}
run() {  # NAME, then bench_tasks.py arguments
  local name=$1; shift
  ( WARP_CACHE_PATH=$HOME/.wc_ab_$name timeout "$(( end - $(date +%s) - 20 ))" python3 benchmarks/gpu/bench_tasks.py \
      --tasks Gmloco-Velocity-Rigid-Flat-G1 --import gmloco.train.tasks.registry --num-envs 4096 \
      --iterations "$iters" --sim-steps 50 "$@" --out ~/chunks/reward_ab/$name.json > ~/chunks/reward_ab/$name.log 2>&1
    echo "rc $?" >> ~/chunks/reward_ab/$name.log ) &
}
run default
run action_rate --reward-weight action_rate_lower_l2=-0.1 --reward-weight action_rate_upper_l2=-0.1
run no_termination --reward-weight termination_penalty=0
wait
[ -n "${REWARD_AB_NESTED:-}" ] || touch ~/chunks/DONE  # a job that runs this beside its own work marks DONE itself
