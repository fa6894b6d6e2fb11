#!/usr/bin/env bash
# The batched-cuts runs throughput sweep of g1_eval at the accepted setting (3 cm / 250 its / 5 ms frames / 1 substep):
# 0.5 s episodes (100 frames), robots per solver and window size varied. Usage (in ~/src): bash sweep.sh END_EPOCH
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/sweep
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
POL=artifacts/gm_loco_student_td/policy.onnx
C="python3 -m gmloco.eval.g1_eval_cli --policy $POL --terrains dry_sand --speeds 1.0 --episode-s 0.5 --voxel 0.03 --iters 250 --frame-dt 0.005 --substeps 1 --no-mcap --fresh"
for cfg in "16 1.8 1.0 0.3" "16 1.2 0.7 0.2" "1 1.8 1.0 0.3" "32 1.2 0.7 0.2" "32 1.8 1.0 0.3" "64 1.2 0.7 0.2" "1 1.2 0.7 0.2"; do
  set -- $cfg
  L="r$1_w$2x$3_d$4"
  timeout $(python3 -c "print(int(max(10,($(left 8))*60)))") $C --out $HOME/chunks/sweep/$L --num-episodes $1 --robots-per-batch $1 --window-length $2 --window-width $3 --bed-depth $4 > ~/chunks/sweep/$L.log 2>&1
  log "sweep $L rc=$?"
  python3 - "$HOME/chunks/sweep/$L/episodes.jsonl" >> ~/chunks/job.log <<'PY'
import json,sys
r=[json.loads(l) for l in open(sys.argv[1])]
x=r[0]; print(f"  particles {x['particles']} batch {x['batch_size']} build {x['build_s']:.1f}s sim {x['sim_s']:.1f}s fps {x['frames_per_s']:.2f} ep/min(10s) {60*x['batch_size']/(x['build_s']+2000/x['frames_per_s']):.2f}")
PY
done
touch ~/chunks/FG_DONE
