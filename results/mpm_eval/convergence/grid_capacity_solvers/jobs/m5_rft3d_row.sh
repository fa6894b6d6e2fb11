#!/usr/bin/env bash
# Machine 5 of the grid-capacity runs (H200, the budget's last ~8 held minutes): the start of the ppo_rft3d row (dry sand,
# straight, 1.0-2.5 m/s, 100 episodes, 36 lanes), time-boxed; resumable next run (job_next.sh part a).
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
log "start"
M=$(left 0.4)
L=table_ppo_rft3d_dry_sand
timeout $(python3 -c "print(int(max(30,$M*60+20)))") python3 -m gmloco.eval.g1_eval_cli --policy artifacts/ppo_rft3d/policy.onnx \
  --terrains dry_sand --scenarios straight --speeds 1.0 1.5 2.0 2.5 --num-episodes 100 --robots-per-batch 36 \
  --max-minutes $M --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
log "row $L rc=$?"
touch ~/chunks/DONE
