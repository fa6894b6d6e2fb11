#!/usr/bin/env bash
# Prepared in the window-behind-pelvis runs for a machine of several GPUs (issue 9); ran in the per-terrain runs (results: ../../table_rows/per_terrain/). Device time counts the machine's
# held time whatever its GPU count, so on nvidia-h100-x4 (or x8) each GPU runs one evaluation at a time from a
# shared queue, in priority order: 4-8 times the rows of a one-GPU run. Every row uses the tables' accepted
# setting (1.4 x 0.6 m window, the default), except ppo_rigid, whose soles reach 0.64 m ahead / behind and 0.58 m
# sideways: it gets a 1.4 x 1.3 m window that covers them (strictly more sand; the tables footnote the setting).
# Rows are time-boxed to END and resumable: carry their folders back as .devsrc/row/<name> next time.
#   Usage (in ~/src, after the wheels and the Warp cache): bash job_next_multi.sh END_EPOCH
# Timings of runs that shared the machine are not compared with one-GPU timings; the lanes case (task "lanes")
# runs on one GPU while the others work, so it is indicative only.
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval ~/chunks/verdicts ~/chunks/cost ~/chunks/queue
[ -d ~/src/.devsrc/row ] && cp -r ~/src/.devsrc/row/* ~/chunks/g1_eval/
G=~/chunks/g1_eval Q=~/chunks/queue
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
TD=artifacts/gm_loco_student_td/policy.onnx
RIGID=artifacts/ppo_rigid/policy.onnx
CLR50=artifacts/gm_loco_student_clr50/policy.onnx
SMALL="--window-length 1.0 --window-width 0.5 --window-lead -0.1"
WIDE="--window-length 1.4 --window-width 1.3 --window-lead 0.0"
S15=results/mpm_eval/window_study/window_behind_pelvis/runs

row() {  # row NAME POLICY TERRAIN SCENARIO WINDOW_FLAGS...: 100 episodes, 1.0-2.5 m/s, time-boxed, resumable
  local N=$1 POL=$2 T=$3 SC=$4; shift 4
  local M; M=$(left 0.7)
  python3 -c "import sys; sys.exit(0 if $M > 1.0 else 1)" || { log "row $N skipped: $M min left"; return; }
  timeout $(python3 -c "print(int(max(30,$M*60+20)))") python3 -m gmloco.eval.g1_eval_cli --policy $POL \
    --terrains $T --scenarios $SC --speeds 1.0 1.5 2.0 2.5 --num-episodes 100 --robots-per-batch 50 "$@" \
    --max-minutes $M --out $G/$N >> $G/$N.log 2>&1
  log "row $N rc=$? (gpu $CUDA_VISIBLE_DEVICES)"
}
check() {  # check NAME SPEED SEED WINDOW_FLAGS...: the td student, 16 robots x 5 s, to the end
  local N=$1 V=$2 SEED=$3; shift 3
  timeout 600 python3 -m gmloco.eval.g1_eval_cli --policy $TD --terrains dry_sand --speeds $V --no-mcap --fresh \
    --episode-s 5 --num-episodes 16 --robots-per-batch 16 --seed $SEED "$@" --out $G/$N > $G/$N.log 2>&1
  log "check $N rc=$? (gpu $CUDA_VISIBLE_DEVICES)"
}
window_check() {  # the pooled 1.5 m/s check of the 1.0 x 0.5 m window (the window-behind-pelvis runs' 16 + 16 more, seed 1)
  check td_l1.4_w0.6_lead0.2_r16_5s_v1.5_seed1 1.5 1 --window-length 1.4 --window-width 0.6 --window-lead 0.2
  check td_l1.0_w0.5_lead-0.1_r16_5s_v1.5_seed1 1.5 1 $SMALL
  python3 -m gmloco.eval.convergence \
    --reference $S15/td_v0.03_it500_d0.3_l1.4_w0.6_lead0.2_r16_5s_v1.5 $G/td_l1.4_w0.6_lead0.2_r16_5s_v1.5_seed1 \
    --candidate $S15/td_v0.03_it500_d0.3_l1.0_w0.5_lead-0.1_r16_5s_v1.5 $G/td_l1.0_w0.5_lead-0.1_r16_5s_v1.5_seed1 \
    --out ~/chunks/verdicts/td_v1.5_l1.0_w0.5_pooled.json > ~/chunks/verdicts/td_v1.5_l1.0_w0.5_pooled.log 2>&1
  log "verdict pooled: $(head -1 ~/chunks/verdicts/td_v1.5_l1.0_w0.5_pooled.log)"
}
lanes() {  # cost of 32 / 50 / 100 robots per solver on the small window, 0.3 s episodes
  for R in 32 50 100; do
    timeout 300 python3 -m gmloco.eval.g1_eval_cli --policy $TD --terrains dry_sand --speeds 1.0 --no-mcap --fresh \
      --episode-s 0.3 --num-episodes $R --robots-per-batch $R $SMALL --out ~/chunks/cost/r$R > ~/chunks/cost/r$R.log 2>&1
    log "cost r$R rc=$? (gpu $CUDA_VISIBLE_DEVICES)"
  done
}

cat > $Q/tasks <<TASKS
row table_ppo_rigid_wide_dry_sand $RIGID dry_sand straight $WIDE
row table_td_poppy_seed $TD poppy_seed straight
row table_td_basalt $TD basalt straight
row table_clr50_dry_sand_l1.4 $CLR50 dry_sand straight
window_check
row table_td_dry_sand_deep $TD dry_sand_deep straight
row table_td_dry_sand_rough $TD dry_sand_rough straight
row table_td_transition $TD transition straight
lanes
row table_ppo_rft3d_dry_sand_circle artifacts/ppo_rft3d/policy.onnx dry_sand circle
row table_td_dry_sand_circle $TD dry_sand circle
TASKS
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
NGPU=$(nvidia-smi -L | wc -l)
log "start: $NGPU GPUs"
for k in $(seq 0 $((NGPU - 1))); do worker $k & done
wait
touch ~/chunks/DONE
