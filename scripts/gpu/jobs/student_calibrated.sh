#!/usr/bin/env bash
# Copy to .devsrc/job.sh, with .devsrc/teacher.pt = the frozen teacher (artifacts/gm_loco_teacher_calibrated/
# checkpoint.pt once it passes the deep-bed gate), optionally .devsrc/checkpoint.pt = the student's newest checkpoint
# to resume, and .devsrc/rft3d_calibrated.json = results/sand_calibration/rft3d_calibrated.json; start it with
# launch_job.sh SECONDS and poll with jobs/poll_teacher.sh MAX_SECONDS gm_loco_student_calibrated.
# The TCN student distilled (DAgger + PPO) from the calibrated-sand teacher on the teacher's own sand and floor
# curriculum (survival rule, floors 0-20 cm in 2 cm steps), added-mass DR (U[0.5, 10]) and soft material share (a quarter
# of the draws from 500-800 kg/m^3, as the teacher from iteration 4,414 on); the post-training checks export
# policy.onnx with its deploy metadata and check it against torch. This command ran on a CPU with 8 envs for 3
# iterations from the teacher of iteration 4,638 (export and parity checks included).
set -uo pipefail
end=$1
run=gm_loco_student_calibrated
cd ~/src
source scripts/gpu/env.sh
stage_calibrated_run "$run" student
[ -f .devsrc/checkpoint.pt ] && cp .devsrc/checkpoint.pt "artifacts/$run/checkpoint.pt"
nvidia-smi --query-gpu=name,memory.total --format=csv > ~/chunks/gpu.txt 2>&1
mins=$(python3 -c "import time; print(round(($end - time.time())/60 - 0.3, 2))")  # END: the training's own end
echo "student chunk: max-minutes $mins" > ~/chunks/job.log
python3 scripts/gpu/train_ts_chunk.py --stage student --run "$run" --teacher-checkpoint .devsrc/teacher.pt \
  --contact-model rft3d_calibrated --foot-clearance sinkage --foot-faces box --curriculum-scale 0.1 \
  --reward-weight foot_clearance_l2=-50 --floor-promotion survival --floor-depth-max 0.20 --floor-levels 11 \
  --rft-extension-range added_mass=0.5,10 --soft-share 0.25 \
  --max-iterations 2000 --max-minutes "$mins" --post-minutes 1.5 --full-checkpoint --out ~/chunks/student \
  >> ~/chunks/job.log 2>&1
echo "train rc $?" >> ~/chunks/job.log
[ "${NESTED:-0}" = 1 ] || touch ~/chunks/DONE  # a wrapper job (NESTED=1) marks DONE itself
