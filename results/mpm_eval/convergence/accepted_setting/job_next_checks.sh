#!/usr/bin/env bash
# Prepared in the accepted-setting runs for a later GPU run (issue 9); NOT yet run. ~15-23 minutes on an H200; run it before
# job_next.sh (the table run), whose window width depends on (1).
# (1) The window width at the accepted setting (3 cm, 500 iterations, 1.4 m long): 1.0 m against the accepted-setting runs'
#     0.6 m runs (results/mpm_eval/convergence/accepted_setting/runs/td_v0.03_it500_d0.3_l1.4_r8_5s{,_seed1}: 16 episodes). The batched-cuts runs
#     accepted 0.6 m at 250 iterations on time alive, success and sinkage; with the tracking errors in the check
#     that pair is rejected on the yaw error. 8 robots x 5 s, seeds 0 and 1 (16 episodes, ~5 min each). Then here:
#       python -m gmloco.eval.convergence --reference <the two 1.0 m runs> \
#         --candidate results/mpm_eval/convergence/accepted_setting/runs/td_v0.03_it500_d0.3_l1.4_r8_5s{,_seed1}
# (2) The cost of Newton's Jacobi rheology solver (no colors, one launch per sweep) at 500 / 1000 / 2000
#     iterations, 32 robots, 0.3 s (60 frames). The Gauss-Seidel sweep runs at ~2.9 ns per cell-iteration on the H200, far below
#     its memory bandwidth; if Jacobi at 1000+ beats Gauss-Seidel at 500 (71 robot-frames/s, ./sweep.jsonl),
#     its convergence check follows.
# Usage (in ~/src, after the wheels and the Warp cache): bash job_next_checks.sh END_EPOCH
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/sweep12 ~/chunks/g1_eval
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
P="python3 -m gmloco.eval.g1_eval_cli --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --speeds 1.0 --no-mcap --fresh"
for seed in 0 1; do
  L=td_v0.03_it500_d0.3_l1.4_w1.0_r8_5s_seed$seed
  M=$(left 0.5)
  timeout $(python3 -c "print(int(max(30,$M*60)))") $P --window-width 1.0 --episode-s 5 --num-episodes 8 \
    --robots-per-batch 8 --seed $seed --max-minutes $(python3 -c "print(max(0.5,$M-0.2))") \
    --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
  log "g1_eval $L rc=$?"
done
for it in 500 1000 2000; do
  timeout 150 $P --episode-s 0.3 --num-episodes 32 --robots-per-batch 32 --rheology-solver jacobi --iters $it \
    --out $HOME/chunks/sweep12/h200_v0.03_it${it}_r32_l1.4_jacobi > ~/chunks/sweep12/jacobi_$it.log 2>&1
  log "cost jacobi $it rc=$?"
done
# (3) If time is left: the voxel axis below 3 cm, 2 cm at 500 iterations (~3.4x the cells of 3 cm: ~8 min for
#     8 robots x 5 s on an H200), against the 3 cm / 500 runs of (1) or . (same width).
M=$(left 0.5)
L=td_v0.02_it500_d0.3_l1.4_r8_5s
timeout $(python3 -c "print(int(max(30,$M*60)))") $P --voxel 0.02 --episode-s 5 --num-episodes 8 --robots-per-batch 8 \
  --max-minutes $(python3 -c "print(max(0.5,$M-0.2))") --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
log "g1_eval $L rc=$?"
touch ~/chunks/CHECKS_DONE
