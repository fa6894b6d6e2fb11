#!/usr/bin/env bash
# Prepared in session 12 for a later GPU session (issue 9); NOT yet run. ~4 minutes.
# Is Newton's Jacobi rheology solver cheaper per unit of accuracy than Gauss-Seidel at the accepted setting?
# At 3 cm / 500 iterations the Gauss-Seidel sweep runs at ~2.9 ns per cell-iteration on the H200 (~600k cells,
# 0.87 s per frame at 64 robots), far below the GPU's memory bandwidth: colored sweeps with atomics. Jacobi needs no
# colors; if one Jacobi iteration costs well under half a Gauss-Seidel one, Jacobi at 1000 iterations may beat
# Gauss-Seidel at 500. Cost cases first (32 robots, 0.5 s); if one is cheaper than gs/500 (71 robot-frames/s on
# the H200, gpu_s12/sweep.jsonl), its convergence check follows: 8 robots x 5 s against gpu_s12's reference.
# Usage (in ~/src): bash job_next_solver.sh
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/sweep12 ~/chunks/g1_eval
P="python3 -m gmloco.eval.g1_eval_cli --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --speeds 1.0 --no-mcap --fresh"
for it in 500 1000 2000; do
  timeout 150 $P --episode-s 0.5 --num-episodes 32 --robots-per-batch 32 --rheology-solver jacobi --iters $it \
    --out $HOME/chunks/sweep12/h200_v0.03_it${it}_r32_l1.4_jacobi > ~/chunks/sweep12/jacobi_$it.log 2>&1
  echo "cost jacobi $it rc=$? at $(date +%T)" >> ~/chunks/job.log
done
touch ~/chunks/SOLVER_DONE
