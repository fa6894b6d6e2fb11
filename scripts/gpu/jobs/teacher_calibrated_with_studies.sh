#!/usr/bin/env bash
# Copy to .devsrc/job.sh, with .devsrc/checkpoint.pt = artifacts/gm_loco_teacher_sinkage/checkpoint.pt and
# .devsrc/rft3d_calibrated.json = results/sand_calibration/rft3d_calibrated.json (results/ does not travel with a
# slimmed tree); start it with launch_job.sh SECONDS and poll with jobs/poll_teacher.sh (run name below).
# The teacher resumes on the calibrated sand (contact_model rft3d_calibrated) beside two studies on the same GPU:
# * the sole-calibration datasets at the MPM walks' 3 cm / 500 iterations and then at 1 cm, which decide whether
#   MPM's sole response converges with the grid;
# * an action-scale A/B of the adaptive learning rate on mjlab's stock G1 velocity task (its per-joint scale
#   0.25 effort / stiffness against this project's uniform 0.25 rad), 150 PPO iterations each from scratch.
set -uo pipefail
end=$1
run=gm_loco_teacher_calibrated
cd ~/src
source scripts/gpu/env.sh
mkdir -p ~/chunks/calib_1cm ~/chunks/calib_3cm ~/chunks/teacher ~/chunks/lr_ab "artifacts/$run" results/sand_calibration
cp .devsrc/checkpoint.pt "artifacts/$run/checkpoint.pt"
cp .devsrc/rft3d_calibrated.json results/sand_calibration/rft3d_calibrated.json
nvidia-smi --query-gpu=name,memory.total --format=csv > ~/chunks/gpu.txt 2>&1
for variant in stock uniform; do
  extra=(); [ "$variant" = uniform ] && extra=(--uniform-action-scale 0.25)
  ( WARP_CACHE_PATH=$HOME/.wc_ab_$variant timeout "$(( end - $(date +%s) - 60 ))" python3 benchmarks/gpu/bench_tasks.py \
      --tasks Mjlab-Velocity-Flat-Unitree-G1 --num-envs 4096 --iterations 150 --sim-steps 50 "${extra[@]}" \
      --out ~/chunks/lr_ab/$variant.json > ~/chunks/lr_ab/$variant.log 2>&1; echo "rc $?" >> ~/chunks/lr_ab/$variant.log ) &
done
for m in dry_sand poppy_seed basalt; do
  left=$(( end - $(date +%s) - 45 ))
  ( WARP_CACHE_PATH=$HOME/.wc_1_$m timeout "$left" python3 -m gmloco.eval.calibration --material "$m" \
      --voxel-size 0.03 --max-iterations 500 --device cuda:0 --out ~/chunks/calib_3cm > ~/chunks/calib_3cm/$m.log 2>&1
    echo "rc $?" >> ~/chunks/calib_3cm/$m.log
    WARP_CACHE_PATH=$HOME/.wc_1_$m timeout "$(( end - $(date +%s) - 45 ))" python3 -m gmloco.eval.calibration \
      --material "$m" --voxel-size 0.01 --device cuda:0 --out ~/chunks/calib_1cm > ~/chunks/calib_1cm/$m.log 2>&1
    echo "rc $?" >> ~/chunks/calib_1cm/$m.log ) &
done
mins=$(python3 -c "import time; print(round(($end - time.time())/60 - 0.6, 2))")
echo "teacher chunk: max-minutes $mins" > ~/chunks/job.log
python3 scripts/gpu/train_ts_chunk.py --stage teacher --run "$run" --contact-model rft3d_calibrated \
  --foot-clearance sinkage --foot-faces box --curriculum-scale 0.1 --reward-weight foot_clearance_l2=-50 \
  --max-iterations 6000 --max-minutes "$mins" --post-minutes 2.0 --full-checkpoint --out ~/chunks/teacher \
  >> ~/chunks/job.log 2>&1
echo "train rc $?" >> ~/chunks/job.log
wait
touch ~/chunks/DONE
