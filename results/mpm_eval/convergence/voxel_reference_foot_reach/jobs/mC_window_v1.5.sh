#!/usr/bin/env bash
# The voxel-reference runs, machine C (issue 9): the window check at a faster command. The td student at 1.5 m/s, 16 robots x 5 s,
# 3 cm / 500: the 1.4 x 0.6 m window (lead 0.2) against 1.0 x 0.5 m (lead 0.1). Usage: bash job.sh END_EPOCH
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
log "start"
for W in "1.0 0.5 0.1" "1.4 0.6 0.2"; do
  set -- $W
  L=td_v0.03_it500_d0.3_l${1}_w${2}_lead${3}_r16_5s_v1.5
  M=$(left 0.4)
  timeout $(python3 -c "print(int(max(30,$M*60+20)))") python3 -m gmloco.eval.g1_eval_cli \
    --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --speeds 1.5 --no-mcap --fresh \
    --window-length $1 --window-width $2 --window-lead $3 --episode-s 5 --num-episodes 16 --robots-per-batch 16 \
    --max-minutes $M --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
  log "g1_eval $L rc=$?"
done
touch ~/chunks/DONE
