#!/usr/bin/env bash
# Machine 1 of the accepted-setting runs (H100), after ../../batched_cuts/job_next.sh (run as is on this machine): 5 cm / 1000 it cost at 32 and 64 robots (1.5 s episodes).
# The 64-robot case was cut by its time box before an episode ended: its 1.7 frames/s is read from the progress log.
cd ~/src && source scripts/gpu/env.sh
for n in 32 64; do timeout 170 python3 -m gmloco.eval.g1_eval_cli --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --speeds 1.0 --episode-s 1.5 --window-width 0.6 --bed-depth 0.3 --num-episodes $n --robots-per-batch $n --no-mcap --fresh --voxel 0.05 --iters 1000 --frame-dt 0.005 --substeps 1 --max-minutes 2.6 --out $HOME/chunks/sweep12/td_v0.05_it1000_r${n}; done
