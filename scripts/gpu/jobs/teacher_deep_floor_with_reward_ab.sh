#!/usr/bin/env bash
# Copy to .devsrc/job.sh with what jobs/teacher_deep_floor.sh needs; start it with launch_job.sh SECONDS and poll with
# jobs/poll_teacher.sh MAX_SECONDS gm_loco_teacher_calibrated.
# jobs/teacher_deep_floor.sh with, beside it, a reward A/B of the adaptive rate and the action std on gmloco's rigid
# task (jobs/reward_ab.sh's three runs), first, while the teacher compiles. Sharing the GPU slows the teacher ~4x
# while the A/B runs.
set -uo pipefail
end=$1
cd ~/src
REWARD_AB_ITERATIONS=150 REWARD_AB_NESTED=1 bash scripts/gpu/jobs/reward_ab.sh "$end" &
bash scripts/gpu/jobs/teacher_deep_floor.sh "$end"
wait
