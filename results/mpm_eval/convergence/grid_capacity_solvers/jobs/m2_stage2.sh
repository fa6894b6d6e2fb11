#!/usr/bin/env bash
# The grid-capacity runs stage 2 (H200): the rheology-solver study from mid-walk states, then the CUDA-graph cost of 32 robots
# (0.3 s, accepted setting): gs at grid capacity 3.0 (anchor) / 1.5 / 1.25, jacobi and gs-batched at 3.0.
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/sweep13 ~/chunks/study
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
POL=artifacts/gm_loco_student_td/policy.onnx
timeout 300 python3 -m gmloco.eval.mpm.solver_study --policy $POL --out $HOME/chunks/study/v1.0_r8 \
  --variants gs jacobi jacobi,gs gs-batched --robots 8 --warm-s 1.0 --probe-iterations 2000 --cycles 3 \
  > ~/chunks/study/v1.0_r8.log 2>&1
log "study v1.0 rc=$?"
P="python3 -m gmloco.eval.g1_eval_cli --policy $POL --terrains dry_sand --speeds 1.0 --no-mcap --fresh --episode-s 0.3 --num-episodes 32 --robots-per-batch 32 --iters 500"
for c in 3.0 1.5 1.25; do
  timeout 150 $P --cell-capacity-factor $c --out $HOME/chunks/sweep13/h200_v0.03_it500_r32_l1.4_gs_cap$c > ~/chunks/sweep13/cost_gs_cap$c.log 2>&1
  log "cost gs cap $c rc=$?"
done
for s in jacobi gs-batched; do
  timeout 150 $P --rheology-solver $s --out $HOME/chunks/sweep13/h200_v0.03_it500_r32_l1.4_$s > ~/chunks/sweep13/cost_$s.log 2>&1
  log "cost $s 500 rc=$?"
done
