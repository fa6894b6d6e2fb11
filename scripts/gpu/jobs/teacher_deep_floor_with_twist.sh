#!/usr/bin/env bash
# Copy to .devsrc/job.sh with what jobs/teacher_deep_floor.sh needs; start it with launch_job.sh SECONDS and poll with
# jobs/poll_teacher.sh MAX_SECONDS gm_loco_teacher_calibrated (it brings back ~/chunks/calib*/MATERIAL.npz).
# jobs/teacher_deep_floor.sh with, beside it, the three MPM sole-calibration datasets rebuilt with the twist (a loaded
# sole turned about the vertical, the yaw torque the fit has lacked): every experiment of
# gmloco.eval.calibration.protocol.EXPERIMENTS, split by seed 0, at the accepted settings (2 cm voxels, 250
# iterations, 10 ms frames), ~2 GPU-minutes per material alone. Refit with gmloco.eval.calibration.fit_cli.
set -uo pipefail
end=$1
cd ~/src
source scripts/gpu/env.sh
mkdir -p ~/chunks/calib_twist
for m in dry_sand poppy_seed basalt; do
  left=$(( end - $(date +%s) - 45 ))
  ( WARP_CACHE_PATH=$HOME/.wc_$m timeout "$left" python3 -m gmloco.eval.calibration --material "$m" \
      --device cuda:0 --out ~/chunks/calib_twist > ~/chunks/calib_twist/$m.log 2>&1
    echo "rc $?" >> ~/chunks/calib_twist/$m.log ) &
done
NESTED=1 bash scripts/gpu/jobs/teacher_deep_floor.sh "$end"
wait
touch ~/chunks/DONE
