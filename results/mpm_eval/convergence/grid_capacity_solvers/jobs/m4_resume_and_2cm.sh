#!/usr/bin/env bash
# Machine 4 of the grid-capacity runs (H200): (1) the 4 episodes of the first row that the time box dropped (resumed from the
# carried run folder); (2) the voxel axis below 3 cm: 2 cm at 500 iterations, 8 robots x 5 s (time-boxed).
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
log "start"
cp -r ~/src/.devsrc/row/table_td_dry_sand ~/chunks/g1_eval/  # the run folder machine 2 brought back
L=table_td_dry_sand
timeout 400 python3 -m gmloco.eval.g1_eval_cli \
  --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --scenarios straight \
  --speeds 1.0 1.5 2.0 2.5 --num-episodes 100 --robots-per-batch 36 --cell-capacity-factor 1.5 --max-minutes 6 \
  --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/${L}_resume.log 2>&1
log "g1_eval $L resume rc=$?"
M=$(left 0.6)
L=td_v0.02_it500_d0.3_l1.4_r8_5s
timeout $(python3 -c "print(int(max(30,$M*60+20)))") python3 -m gmloco.eval.g1_eval_cli \
  --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --speeds 1.0 --no-mcap --fresh \
  --voxel 0.02 --episode-s 5 --num-episodes 8 --robots-per-batch 8 --cell-capacity-factor 1.5 \
  --max-minutes $M --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
log "g1_eval $L rc=$?"
touch ~/chunks/DONE
