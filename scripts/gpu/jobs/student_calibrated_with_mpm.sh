#!/usr/bin/env bash
# Copy to .devsrc/job.sh with what jobs/student_calibrated.sh needs; start it with launch_job.sh SECONDS and poll with
# jobs/poll_teacher.sh MAX_SECONDS gm_loco_student_calibrated.
# jobs/student_calibrated.sh until MPM_MINUTES (default 9) before the end, then the MPM judge on the exported
# student: straight ten-second walks on the tables' cell setting (3 cm voxels, 500 iterations, 5 ms frames, 30 cm
# bed, 1.4 x 0.6 m window), time-boxed and resumable, into ~/chunks/g1_eval/<terrain>. MPM_TERRAINS (default
# dry_sand) and MPM_SPEEDS (default 1.0) pick the cells, MPM_EPISODES (default 20) the episodes of each terrain,
# all robots of a terrain in one solver. MPM_MINUTES=0 trains to the end and skips the MPM part (the student alone).
# Without an exported policy (the training stopped before its export) the MPM part says so and runs nothing.
# MPM_POLICY=<policy.onnx, its policy.json beside it> skips the training and scores that export on MPM instead.
# MPM_EXTRA adds flags to the MPM evaluation, e.g. "--wrench-frames 2" (the two-frame mean of the sand wrench).
set -uo pipefail
end=$1
cd ~/src
mpm_s=$(python3 -c "print(round(60 * ${MPM_MINUTES:-9}))")
if [ -n "${MPM_POLICY:-}" ]; then
  policy=$MPM_POLICY
  echo "MPM_POLICY=$policy: training skipped" >> ~/chunks/job.log
else
  NESTED=1 bash scripts/gpu/jobs/student_calibrated.sh "$(( end - mpm_s ))"
  policy=~/chunks/student/policy.onnx
fi
if [ "$mpm_s" -le 0 ]; then
  echo "MPM_MINUTES=${MPM_MINUTES:-9}: MPM evaluation skipped" >> ~/chunks/job.log
elif [ ! -f "$policy" ]; then
  echo "no exported student ($policy): MPM evaluation skipped" >> ~/chunks/job.log
else
  source scripts/gpu/env.sh
  mkdir -p ~/chunks/g1_eval
  eps=${MPM_EPISODES:-20}
  for t in ${MPM_TERRAINS:-dry_sand}; do
    left=$(python3 -c "import time; print(round(($end - time.time()) / 60 - 0.7, 2))")
    echo "MPM $t: $left min from $(date +%T)" >> ~/chunks/job.log
    # shellcheck disable=SC2086  # the speeds and extra flags are words
    python3 -m gmloco.eval.g1.cli --out ~/chunks/g1_eval/"$t" --policy "$policy" --terrains "$t" \
      --speeds ${MPM_SPEEDS:-1.0} --num-episodes "$eps" --robots-per-batch "$eps" --max-minutes "$left" ${MPM_EXTRA:-} \
      > ~/chunks/g1_eval/"$t".log 2>&1
    echo "MPM $t rc $? at $(date +%T)" >> ~/chunks/job.log
  done
fi
touch ~/chunks/DONE
