#!/usr/bin/env bash
# Prepared in session 16 for the next session (issue 9); NOT yet run. For a machine of several GPUs (nvidia-h100-x4
# or larger; one GPU works too, slower): each GPU runs one evaluation at a time from a shared queue, in priority
# order. Rows split into four shares (--shard I/4: with four speeds, one speed each) run on four GPUs at once.
#   1. basalt at the square 1.4 x 1.4 m window (lead 0.2; it contains the tables' 1.4 x 0.6 m window at every
#      heading): session 16's basalt row left the window in 94 % of its episodes because the student turns
#      35-69 degrees in 10 s and the window does not turn;
#   2. the lanes case (32 / 50 / 100 robots per solver, 0.3 s, one after the other on one GPU: the last throughput
#      lever not measured side by side; indicative, the other GPUs keep working), then the ppo_rigid wide row's
#      last 16 episodes and the rough row (resumed: carry their folders, see below);
#   3. the transition course (square window: it starts on basalt, where the student turns);
#   4. the td student on dry sand at the square window (does session 13's 22 % row, scored before exits were
#      recorded, hold?); then the circles.
# Time-boxed to END, resumable: carry row folders back as .devsrc/row/<name> (this job copies them in).
#   Before: mkdir -p .devsrc/row && cp -r results/mpm_eval/gpu_s16/runs/table_ppo_rigid_wide_dry_sand \
#           results/mpm_eval/gpu_s16/runs/table_td_dry_sand_rough .devsrc/row/   (the two resumed rows)
#   Usage (in ~/src, after the wheels and the Warp cache): bash job_next.sh END_EPOCH
#   Fetch: cd ~/chunks && tar czf - g1_eval cost job.log | split -b 15M - $OUT/s17.tgz.part
#   Dry run on a CPU: G1EVAL="python3 stub.py" NGPU=2 bash job_next.sh $(( $(date +%s) + 60 ))
END=$1
G1EVAL=${G1EVAL:-python3 -m gmloco.eval.g1_eval_cli}
cd ~/src && { [ -n "${NO_ENV:-}" ] || source scripts/gpu/env.sh; } && mkdir -p ~/chunks/g1_eval ~/chunks/queue ~/chunks/cost
[ -d ~/src/.devsrc/row ] && cp -r ~/src/.devsrc/row/* ~/chunks/g1_eval/
G=~/chunks/g1_eval Q=~/chunks/queue
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
TD=artifacts/gm_loco_student_td/policy.onnx
RIGID=artifacts/ppo_rigid/policy.onnx
SQ="--window-length 1.4 --window-width 1.4 --window-lead 0.2"
WIDE="--window-length 1.4 --window-width 1.3 --window-lead 0.0"

row() {  # row NAME POLICY TERRAIN SCENARIO FLAGS...: 100 episodes (or a --shard of them), 1.0-2.5 m/s, resumable
  local N=$1 POL=$2 T=$3 SC=$4; shift 4
  local M; M=$(left 0.7)
  python3 -c "import sys; sys.exit(0 if $M > 1.0 else 1)" || { log "row $N skipped: $M min left"; return; }
  timeout $(python3 -c "print(int(max(30,$M*60+20)))") $G1EVAL --policy $POL \
    --terrains $T --scenarios $SC --speeds 1.0 1.5 2.0 2.5 --num-episodes 100 --robots-per-batch 50 "$@" \
    --max-minutes $M --out $G/$N >> $G/$N.log 2>&1
  log "row $N rc=$? (gpu $CUDA_VISIBLE_DEVICES)"
}
lanes() {  # cost of 32 / 50 / 100 lanes on the tables' window, 0.3 s episodes, one after the other on one GPU
  mkdir -p ~/chunks/cost
  for R in 32 50 100; do
    timeout 300 $G1EVAL --policy $TD --terrains dry_sand --speeds 1.0 --no-mcap --fresh \
      --episode-s 0.3 --num-episodes $R --robots-per-batch $R --out ~/chunks/cost/r$R > ~/chunks/cost/r$R.log 2>&1
    log "cost r$R rc=$? (gpu $CUDA_VISIBLE_DEVICES)"
  done
}
shares() {  # shares NAME POLICY TERRAIN SCENARIO FLAGS...: the row as four queue lines, one per share
  local N=$1; shift
  for i in 0 1 2 3; do echo "row ${N}_share${i}of4 $* --shard $i/4"; done
}

{
  shares table_td_basalt_sq $TD basalt straight $SQ
  echo "lanes"
  echo "row table_ppo_rigid_wide_dry_sand $RIGID dry_sand straight $WIDE"
  echo "row table_td_dry_sand_rough $TD dry_sand_rough straight"
  shares table_td_transition_sq $TD transition straight $SQ
  shares table_td_dry_sand_sq $TD dry_sand straight $SQ
  shares table_td_dry_sand_circle $TD dry_sand circle
  shares table_ppo_rft3d_dry_sand_circle artifacts/ppo_rft3d/policy.onnx dry_sand circle
} > $Q/tasks
echo 0 > $Q/idx
next_task() {  # the queue's next line ("" when empty), one worker at a time
  ( flock 9; i=$(cat $Q/idx); echo $((i + 1)) > $Q/idx; sed -n "$((i + 1))p" $Q/tasks ) 9> $Q/lock
}
worker() {  # worker GPU: run tasks until the queue is empty or too little time is left
  export CUDA_VISIBLE_DEVICES=$1
  while true; do
    local T; T=$(next_task)
    [ -z "$T" ] && break
    python3 -c "import sys; sys.exit(0 if $(left 0.7) > 1.0 else 1)" || { log "gpu $1 stops: time is up"; break; }
    log "gpu $1 starts: $T"
    eval "$T"
  done
}
NGPU=${NGPU:-$(nvidia-smi -L | wc -l)}
log "start: $NGPU GPUs"
for k in $(seq 0 $((NGPU - 1))); do worker $k & done
wait
touch ~/chunks/DONE
