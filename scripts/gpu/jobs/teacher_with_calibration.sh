#!/usr/bin/env bash
# Copy to .devsrc/job.sh (with the seed checkpoint as .devsrc/checkpoint.pt) and start it with launch_job.sh SECONDS.
# Teacher chunk (sinkage swing clearance, resumed from the yaw teacher) beside the MPM sole-calibration dataset.
set -uo pipefail
end=$1
cd ~/src
source scripts/gpu/env.sh
mkdir -p ~/chunks/calib ~/chunks/teacher artifacts/gm_loco_teacher_sinkage
cp .devsrc/checkpoint.pt artifacts/gm_loco_teacher_sinkage/checkpoint.pt
nvidia-smi --query-gpu=name,memory.total --format=csv > ~/chunks/gpu.txt 2>&1
for m in dry_sand poppy_seed basalt; do
  left=$(( end - $(date +%s) - 45 ))
  ( WARP_CACHE_PATH=$HOME/.wc_$m timeout "$left" python3 -m gmloco.eval.calibration --material "$m" \
      --device cuda:0 --out ~/chunks/calib > ~/chunks/calib/$m.log 2>&1; echo "rc $?" >> ~/chunks/calib/$m.log ) &
done
mins=$(python3 -c "import time; print(round(($end - time.time())/60 - 0.6, 2))")
echo "teacher chunk: max-minutes $mins" > ~/chunks/job.log
python3 scripts/gpu/train_ts_chunk.py --stage teacher --run gm_loco_teacher_sinkage --foot-clearance sinkage \
  --foot-faces box --curriculum-scale 0.1 --reward-weight foot_clearance_l2=-50 --max-iterations 6000 \
  --max-minutes "$mins" --post-minutes 2.0 --full-checkpoint --out ~/chunks/teacher >> ~/chunks/job.log 2>&1
echo "train rc $?" >> ~/chunks/job.log
wait
touch ~/chunks/DONE
