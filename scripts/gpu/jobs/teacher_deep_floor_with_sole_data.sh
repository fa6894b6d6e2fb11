#!/usr/bin/env bash
# Copy to .devsrc/job.sh with what jobs/teacher_deep_floor.sh needs; start it with launch_job.sh SECONDS and poll with
# jobs/poll_teacher.sh MAX_SECONDS gm_loco_teacher_calibrated (it brings back ~/chunks/calib*/MATERIAL.npz as
# calib_<tag>_MATERIAL.npz).
# jobs/teacher_deep_floor.sh with, beside it, MPM sole-calibration datasets of the three materials at the accepted
# settings (2 cm voxels, 250 iterations, 10 ms frames; ~2 GPU-minutes a material alone for every experiment):
#   CALIB_EXPERIMENTS  experiments of gmloco.eval.calibration.protocol (default: the probes, slide_repress and
#                      twist_repress: re-pressing a loaded sole after a 5 cm slide or a 15 deg turn, the extra depth
#                      MPM needs where 3D-RFT needs none, results/sand_calibration/shear/)
#   CALIB_TAG          folder under ~/chunks (default: calib_probes; the datasets with the twist were calib_twist,
#                      CALIB_EXPERIMENTS="press press_fast tilt drag drag_fast liftoff repeat twist")
#   TRAIN              0: the datasets alone, no teacher chunk (the probes of results/sand_calibration/dataset/probes/)
# Read the probes with python -m gmloco.eval.calibration.shear --probes ...; refit with gmloco.eval.calibration.fit_cli.
set -uo pipefail
end=$1
exps=${CALIB_EXPERIMENTS:-slide_repress twist_repress}
out=~/chunks/${CALIB_TAG:-calib_probes}
cd ~/src
source scripts/gpu/env.sh
mkdir -p "$out"
for m in dry_sand poppy_seed basalt; do
  left=$(( end - $(date +%s) - 45 ))
  # shellcheck disable=SC2086  # the experiment names are words
  ( WARP_CACHE_PATH=$HOME/.wc_$m timeout "$left" python3 -m gmloco.eval.calibration --material "$m" \
      --experiments $exps --device cuda:0 --out "$out" > "$out/$m.log" 2>&1
    echo "rc $?" >> "$out/$m.log" ) &
done
[ "${TRAIN:-1}" = 0 ] || NESTED=1 bash scripts/gpu/jobs/teacher_deep_floor.sh "$end"
wait
touch ~/chunks/DONE
