#!/usr/bin/env bash
# The window-behind-pelvis runs, machine A (issue 9). (1) Window and bed checks, all at once on one GPU (accuracy only, no timing):
#     at 1.5 m/s, 16 robots x 5 s: 1.4 x 0.6 m lead 0.2 (reference) against 1.0 x 0.5 m lead -0.1 and
#     0.8 x 0.5 m lead -0.1 on a 25 cm bed; at 1.0 m/s, 8 robots x 5 s: 1.0 x 0.5 lead -0.1, 0.8 x 0.5 lead -0.1,
#     1.0 x 0.5 lead -0.1 bed 25 cm, 0.8 x 0.5 lead -0.1 bed 25 cm (reference: the accepted-setting runs' 1.4 x 0.6 runs).
#     The cheapest setting accepted at both speeds is the rows' window.
# (2) Cost on the idle GPU, side by side, 0.3 s episodes: 1.4 x 0.6 (anchor), 1.0 x 0.5, 0.8 x 0.5 bed 25 cm at
#     32 robots, and 0.8 x 0.5 bed 25 cm at 64 robots.
# (3) Rows (100 episodes, straight, 1.0-2.5 m/s, 50 lanes, resumable): ppo_rigid and clr50 on dry sand, then the
#     td student on poppy seed. Usage: bash job.sh END_EPOCH
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval ~/chunks/cost ~/chunks/verdicts
[ -d ~/src/.devsrc/row ] && cp -r ~/src/.devsrc/row/* ~/chunks/g1_eval/
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
POL=artifacts/gm_loco_student_td/policy.onnx
G="python3 -m gmloco.eval.g1_eval_cli --policy $POL --terrains dry_sand --no-mcap --fresh --episode-s 5"
log "start"
check() {  # check SPEED ROBOTS LENGTH WIDTH LEAD DEPTH
  L=td_v0.03_it500_d$6_l$3_w$4_lead$5_r$2_5s_v$1
  timeout 1000 $G --speeds $1 --num-episodes $2 --robots-per-batch $2 --window-length $3 --window-width $4 \
    --window-lead $5 --bed-depth $6 --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
  log "check $L rc=$?"
}
check 1.5 16 1.4 0.6 0.2 0.3 &
check 1.5 16 1.0 0.5 -0.1 0.3 &
check 1.5 16 0.8 0.5 -0.1 0.25 &
check 1.0 8 1.0 0.5 -0.1 0.3 &
check 1.0 8 0.8 0.5 -0.1 0.3 &
check 1.0 8 1.0 0.5 -0.1 0.25 &
check 1.0 8 0.8 0.5 -0.1 0.25 &
wait
log "checks done"
C=python3\ -m\ gmloco.eval.convergence
R15=~/chunks/g1_eval/td_v0.03_it500_d0.3_l1.4_w0.6_lead0.2_r16_5s_v1.5
R10="results/mpm_eval/convergence/accepted_setting/runs/td_v0.03_it500_d0.3_l1.4_r8_5s results/mpm_eval/convergence/accepted_setting/runs/td_v0.03_it500_d0.3_l1.4_r8_5s_seed1"
verdict() {  # verdict NAME REF CANDIDATE_DIR
  $C --reference $2 --candidate ~/chunks/g1_eval/$3 --out ~/chunks/verdicts/$1.json > ~/chunks/verdicts/$1.log 2>&1
  D=$(python3 -c "import json; print(json.load(open('$HOME/chunks/verdicts/$1.json'))['decision'])" 2>/dev/null)
  log "verdict $1: $D"; echo $D
}
A15=$(verdict v1.5_l1.0_w0.5_lead-0.1_d0.3 $R15 td_v0.03_it500_d0.3_l1.0_w0.5_lead-0.1_r16_5s_v1.5)
B15=$(verdict v1.5_l0.8_w0.5_lead-0.1_d0.25 $R15 td_v0.03_it500_d0.25_l0.8_w0.5_lead-0.1_r16_5s_v1.5)
A10=$(verdict v1.0_l1.0_w0.5_lead-0.1_d0.3 "$R10" td_v0.03_it500_d0.3_l1.0_w0.5_lead-0.1_r8_5s_v1.0)
verdict v1.0_l0.8_w0.5_lead-0.1_d0.3 "$R10" td_v0.03_it500_d0.3_l0.8_w0.5_lead-0.1_r8_5s_v1.0 > /dev/null
verdict v1.0_l1.0_w0.5_lead-0.1_d0.25 "$R10" td_v0.03_it500_d0.25_l1.0_w0.5_lead-0.1_r8_5s_v1.0 > /dev/null
B10=$(verdict v1.0_l0.8_w0.5_lead-0.1_d0.25 "$R10" td_v0.03_it500_d0.25_l0.8_w0.5_lead-0.1_r8_5s_v1.0)
if [ "$B15" = accepted ] && [ "$B10" = accepted ]; then
  WIN="--window-length 0.8 --window-width 0.5 --window-lead -0.1 --bed-depth 0.25"
elif [ "$A15" = accepted ] && [ "$A10" = accepted ]; then
  WIN="--window-length 1.0 --window-width 0.5 --window-lead -0.1"
else
  WIN=""
fi
log "rows window: '$WIN'"
P="python3 -m gmloco.eval.g1_eval_cli --policy $POL --terrains dry_sand --speeds 1.0 --no-mcap --fresh --episode-s 0.3"
cost() {  # cost NAME ROBOTS FLAGS...
  N=$1; R=$2; shift 2
  timeout 240 $P --num-episodes $R --robots-per-batch $R "$@" --out $HOME/chunks/cost/$N > ~/chunks/cost/$N.log 2>&1
  log "cost $N rc=$? $(grep -o '[0-9.]* frames/s' ~/chunks/cost/$N.log | tail -1)"
}
cost r32_l1.4_w0.6_d0.3 32
cost r32_l1.0_w0.5_d0.3 32 --window-length 1.0 --window-width 0.5 --window-lead -0.1
cost r32_l0.8_w0.5_d0.25 32 --window-length 0.8 --window-width 0.5 --window-lead -0.1 --bed-depth 0.25
cost r64_l0.8_w0.5_d0.25 64 --window-length 0.8 --window-width 0.5 --window-lead -0.1 --bed-depth 0.25
row() {  # row NAME POLICY TERRAIN: 100 episodes, straight, 1.0-2.5 m/s, resumable, time-boxed to the machine
  M=$(left 0.7)
  if python3 -c "import sys; sys.exit(0 if $M > 1.0 else 1)"; then
    timeout $(python3 -c "print(int(max(30,$M*60+20)))") python3 -m gmloco.eval.g1_eval_cli --policy $2 \
      --terrains $3 --scenarios straight --speeds 1.0 1.5 2.0 2.5 --num-episodes 100 --robots-per-batch 50 \
      $WIN --max-minutes $M --out $HOME/chunks/g1_eval/$1 >> ~/chunks/g1_eval/$1.log 2>&1
    log "row $1 rc=$?"
  else
    log "row $1 skipped: $M min left"
  fi
}
row table_ppo_rigid_dry_sand artifacts/ppo_rigid/policy.onnx dry_sand
row table_clr50_dry_sand artifacts/gm_loco_student_clr50/policy.onnx dry_sand
row table_td_poppy_seed artifacts/gm_loco_student_td/policy.onnx poppy_seed
touch ~/chunks/DONE
