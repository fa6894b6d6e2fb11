#!/usr/bin/env bash
# Machine 2 of the accepted-setting runs (H200), started from device calls after job2_h200.sh (recorded here as they ran):
# (a) cost cases at 3 cm / 500 it: 8 robots with the 1.8 m window, 32 / 8 / 64 robots with the 1.4 m window;
# (b) the accepted setting with 10 s episodes (8 robots); (c) 8 more 5 s episodes of the 1.4 m window, seed 1.
cd ~/src && source scripts/gpu/env.sh
P="python3 -m gmloco.eval.g1_eval_cli --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --speeds 1.0 --window-width 0.6 --no-mcap --fresh --frame-dt 0.005 --substeps 1 --voxel 0.03 --iters 500 --bed-depth 0.3"
for c in "8 1.8" "32 1.4" "8 1.4" "64 1.4"; do set -- $c
  timeout 200 $P --episode-s 0.5 --num-episodes $1 --robots-per-batch $1 --window-length $2 --out $HOME/chunks/sweep12/h200_v0.03_it500_r$1_l$2
done
$P --episode-s 10 --window-length 1.4 --num-episodes 8 --robots-per-batch 8 --max-minutes 6.2 --out $HOME/chunks/g1_eval/td_v0.03_it500_d0.3_l1.4_r8_10s
$P --episode-s 5 --window-length 1.4 --num-episodes 8 --robots-per-batch 8 --seed 1 --max-minutes 3.6 --out $HOME/chunks/g1_eval/td_v0.03_it500_d0.3_l1.4_r8_5s_seed1
