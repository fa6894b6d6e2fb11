#!/usr/bin/env bash
# The voxel-reference runs, machine A (H100, issue 9): stream A = the voxel check left open (2 cm / 1000 sweeps, 8 robots x 5 s),
# then two cheaper windows (3 cm / 500); stream B (after 150 s, so the Warp cache is written once) = the
# contact-model ablation rows on dry sand. Both streams share the GPU (physics results; no timing is read from
# them). Stream B was stopped by hand (kill of the parent shell) once the ppo_rft3d row had finished, to give the
# GPU to the 2 cm run; ppo_rigid and clr50 moved to machine B. Usage: bash job.sh END_EPOCH
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval
[ -d ~/src/.devsrc/row ] && cp -r ~/src/.devsrc/row/* ~/chunks/g1_eval/   # ../../grid_capacity_solvers/runs/table_ppo_rft3d_dry_sand (69 episodes)
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
row() {  # row NAME POLICY TERRAIN: 100 episodes, straight, 1.0-2.5 m/s, resumable, time-boxed to the machine
  M=$(left 0.7)
  if python3 -c "import sys; sys.exit(0 if $M > 1.0 else 1)"; then
    timeout $(python3 -c "print(int(max(30,$M*60+20)))") python3 -m gmloco.eval.g1_eval_cli --policy $2 \
      --terrains $3 --scenarios straight --speeds 1.0 1.5 2.0 2.5 --num-episodes 100 --robots-per-batch 36 \
      --max-minutes $M --out $HOME/chunks/g1_eval/$1 >> ~/chunks/g1_eval/$1.log 2>&1
    log "row $1 rc=$?"
  else
    log "row $1 skipped: $M min left"
  fi
}
log "start"
(
  L=td_v0.02_it1000_d0.3_l1.4_r8_5s
  M=$(left 0.7)
  timeout $(python3 -c "print(int(max(30,$M*60+20)))") python3 -m gmloco.eval.g1_eval_cli \
    --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --speeds 1.0 --no-mcap --fresh \
    --voxel 0.02 --iters 1000 --episode-s 5 --num-episodes 8 --robots-per-batch 8 \
    --max-minutes $M --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
  log "g1_eval $L rc=$?"
  for W in "1.0 0.6" "1.0 0.5"; do  # cost levers: a shorter / narrower window against 1.4 x 0.6 (3 cm / 500)
    set -- $W
    L=td_v0.03_it500_d0.3_l${1}_w${2}_lead0.1_r8_5s
    M=$(left 0.7)
    python3 -c "import sys; sys.exit(0 if $M > 3.5 else 1)" || { log "skip $L: $M min left"; continue; }
    timeout $(python3 -c "print(int(max(30,$M*60+20)))") python3 -m gmloco.eval.g1_eval_cli \
      --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --speeds 1.0 --no-mcap --fresh \
      --window-length $1 --window-width $2 --window-lead 0.1 --episode-s 5 --num-episodes 8 --robots-per-batch 8 \
      --max-minutes $M --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
    log "g1_eval $L rc=$?"
  done
  touch ~/chunks/DONE_A
) &
sleep 150
row table_ppo_rft3d_dry_sand artifacts/ppo_rft3d/policy.onnx dry_sand
row table_ppo_rigid_dry_sand artifacts/ppo_rigid/policy.onnx dry_sand
row table_clr50_dry_sand artifacts/gm_loco_student_clr50/policy.onnx dry_sand
row table_td_poppy_seed artifacts/gm_loco_student_td/policy.onnx poppy_seed
touch ~/chunks/DONE_B
wait
touch ~/chunks/DONE
