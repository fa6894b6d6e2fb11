#!/usr/bin/env bash
# The voxel-reference runs, machine B (H100, issue 9). (1) Cost on an idle GPU, side by side: the accepted 1.4 x 0.6 m window
# (lead 0.2) against the 1.0 x 0.5 m window (lead 0.1) that machine A's check accepted; 32 robots, 0.3 s,
# 3 cm / 500, as the grid-capacity runs' cost table. (2) The contact-model ablation rows of ppo_rigid and the clr50 student
# (dry sand, straight, 1.0-2.5 m/s, 100 episodes) at the 1.0 x 0.5 window, then the td student on poppy seed
# (not reached: the machine's 30 minutes ran out). Usage: bash job.sh END_EPOCH
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval ~/chunks/cost
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
WIN="--window-length 1.0 --window-width 0.5 --window-lead 0.1"
row() {  # row NAME POLICY TERRAIN: 100 episodes, straight, 1.0-2.5 m/s, resumable, time-boxed to the machine
  M=$(left 0.7)
  if python3 -c "import sys; sys.exit(0 if $M > 1.0 else 1)"; then
    timeout $(python3 -c "print(int(max(30,$M*60+20)))") python3 -m gmloco.eval.g1_eval_cli --policy $2 \
      --terrains $3 --scenarios straight --speeds 1.0 1.5 2.0 2.5 --num-episodes 100 --robots-per-batch 36 \
      $WIN --max-minutes $M --out $HOME/chunks/g1_eval/$1 >> ~/chunks/g1_eval/$1.log 2>&1
    log "row $1 rc=$?"
  else
    log "row $1 skipped: $M min left"
  fi
}
log "start"
POL=artifacts/gm_loco_student_td/policy.onnx
P="python3 -m gmloco.eval.g1_eval_cli --policy $POL --terrains dry_sand --speeds 1.0 --no-mcap --fresh --episode-s 0.3 --num-episodes 32 --robots-per-batch 32 --iters 500"
timeout 200 $P --out $HOME/chunks/cost/gpu_r32_l1.4_w0.6 > ~/chunks/cost/l1.4_w0.6.log 2>&1
log "cost l1.4 w0.6 rc=$?"
timeout 200 $P $WIN --out $HOME/chunks/cost/gpu_r32_l1.0_w0.5 > ~/chunks/cost/l1.0_w0.5.log 2>&1
log "cost l1.0 w0.5 rc=$?"
row table_ppo_rigid_dry_sand artifacts/ppo_rigid/policy.onnx dry_sand
row table_clr50_dry_sand artifacts/gm_loco_student_clr50/policy.onnx dry_sand
row table_td_poppy_seed artifacts/gm_loco_student_td/policy.onnx poppy_seed
touch ~/chunks/DONE
