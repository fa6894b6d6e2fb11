#!/usr/bin/env bash
# Machine 2 of the batched-cuts runs: (1) cost sweep (0.5 s episodes, 32 robots) of cheaper windows at 3 cm / 250 / 5 ms;
# (2) 10 s episodes at 1.0 m/s, concurrently: 3 cm on the narrow window (16 robots) and 2 cm on it (4 robots).
# Usage (in ~/src): bash job2.sh END_EPOCH
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/sweep2 ~/chunks/g1_eval
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
POL=artifacts/gm_loco_student_td/policy.onnx
B="python3 -m gmloco.eval.g1_eval_cli --policy $POL --terrains dry_sand --speeds 1.0 --frame-dt 0.005 --substeps 1 --fresh"
C="$B --episode-s 0.5 --voxel 0.03 --no-mcap --num-episodes 32 --robots-per-batch 32"
summ() { python3 - "$1" >> ~/chunks/job.log <<'PY'
import json,sys
r=[json.loads(l) for l in open(sys.argv[1])]
x=r[0]; print(f"  particles {x['particles']} batch {x['batch_size']} build {x['build_s']:.1f}s sim {x['sim_s']:.1f}s fps {x['frames_per_s']:.2f} ep/min(10s) {60*x['batch_size']/(x['build_s']+2000/x['frames_per_s']):.2f}")
PY
}
while read -r L ARGS; do
  timeout $(python3 -c "print(int(max(10,($(left 14))*60)))") $C --out $HOME/chunks/sweep2/$L $ARGS > ~/chunks/sweep2/$L.log 2>&1
  log "sweep2 $L rc=$?"; summ $HOME/chunks/sweep2/$L/episodes.jsonl
done <<'CASES'
w18x06_d03 --window-length 1.8 --window-width 0.6 --bed-depth 0.3 --iters 250
w18x06_d02 --window-length 1.8 --window-width 0.6 --bed-depth 0.2 --iters 250
w14x06_d02_lead0 --window-length 1.4 --window-width 0.6 --bed-depth 0.2 --window-lead 0.0 --iters 250
w18x06_d03_ppv1 --window-length 1.8 --window-width 0.6 --bed-depth 0.3 --particles-per-voxel 1 --iters 250
w18x06_d03_it150 --window-length 1.8 --window-width 0.6 --bed-depth 0.3 --iters 150
CASES
M=$(left 1)
TB="timeout $(python3 -c "print(int(max(30,$M*60)))")"
MM=$(python3 -c "print(max(0.5,$M-0.3))")
W="--window-length 1.8 --window-width 0.6 --bed-depth 0.3 --iters 250 --max-minutes $MM"
$TB $B --voxel 0.03 --num-episodes 16 --robots-per-batch 16 $W --out $HOME/chunks/g1_eval/td_v03_r16_w18x06_d03 > ~/chunks/g1_eval/td_v03_r16_w18x06_d03.log 2>&1 &
$TB $B --voxel 0.02 --num-episodes 4 --robots-per-batch 4 $W --out $HOME/chunks/g1_eval/td_v02_r4_w18x06_d03 > ~/chunks/g1_eval/td_v02_r4_w18x06_d03.log 2>&1 &
wait
log "10 s runs done"
tar czf ~/chunks/warpcache.tgz -C ~ .gmloco-warp-cache 2>/dev/null; ls -la ~/chunks/warpcache.tgz >> ~/chunks/job.log
touch ~/chunks/FG_DONE
