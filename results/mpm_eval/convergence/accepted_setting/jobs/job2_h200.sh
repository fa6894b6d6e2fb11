#!/usr/bin/env bash
# Machine 2 of the accepted-setting runs (H200): the cost of the accepted 3 cm / 500 setting on the H200 and the next axes of the
# convergence check at converged iterations (td student, dry sand, 1.0 m/s, 8 robots, 5 s). Usage: bash job.sh END
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval ~/chunks/sweep12
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
P="python3 -m gmloco.eval.g1_eval_cli --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --speeds 1.0 --window-width 0.6 --no-mcap --fresh --frame-dt 0.005 --substeps 1"
# cost cases: 32 robots, 0.5 s (100 frames)
for c in "gs sweep12/h200_v0.03_it500_r32" "gs-soa sweep12/h200_v0.03_it500_r32_gssoa"; do
  set -- $c
  M=$(left 0.5)
  timeout $(python3 -c "print(int(max(30,$M*60)))") $P --episode-s 0.5 --num-episodes 32 --robots-per-batch 32 --voxel 0.03 --iters 500 --bed-depth 0.3 --rheology-solver $1 --max-minutes $(python3 -c "print(max(0.5,$M-0.2))") --out $HOME/chunks/$2 > ~/chunks/$2.log 2>&1
  log "cost $2 rc=$?"
done
# convergence cases: voxel iters bed window_length
for c in "0.03 500 0.3 1.4" "0.03 500 0.2 1.8" "0.03 350 0.3 1.8" "0.04 500 0.3 1.8"; do
  set -- $c
  L=td_v$1_it$2_d$3_l$4_r8_5s
  M=$(left 0.5)
  timeout $(python3 -c "print(int(max(30,$M*60)))") $P --episode-s 5 --num-episodes 8 --robots-per-batch 8 --voxel $1 --iters $2 --bed-depth $3 --window-length $4 --max-minutes $(python3 -c "print(max(0.5,$M-0.2))") --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
  log "g1_eval $L rc=$?"
done
touch ~/chunks/FG_DONE
