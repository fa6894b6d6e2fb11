#!/usr/bin/env bash
# Copy to .devsrc/job.sh, with .devsrc/checkpoint.pt = the checkpoint to resume (e.g. the newest of a chunk) and
# .devsrc/rft3d_calibrated.json = results/sand_calibration/rft3d_calibrated.json; start it with launch_job.sh SECONDS
# and poll with jobs/poll_teacher.sh MAX_SECONDS gm_loco_teacher_calibrated.
# The calibrated-sand teacher alone on the GPU, resumed with the survival rule of the floor-depth curriculum and
# floors down to 20 cm: the top levels are the gate's and MPM's deep bed, where no foot meets the floor (over a 2.5 cm
# floor the teacher walks every gate cell on the calibrated sand; over the deep bed it tips over within 2 s).
# The last ~3 minutes score the newest checkpoint on the gate's deep bed (success part, 20 episodes per cell, on the
# GPU) into ~/chunks/gate/; GATE=0 in the environment of launch_job.sh gives them to training instead (the gate
# then runs on a CPU afterwards).
# The curriculum spans 0-20 cm in 11 levels (2 cm steps; poppy seed's deepest stance, 12 cm, is level 6): at 0-30 cm in
# 10 levels the first step (3.3 cm) already sat past the teacher's frontier and the floors stayed at ~2 cm. Resumed,
# each env starts at the level nearest to its saved floor depth.
# The added mass of the fitted sand is drawn per env from U[0.5, 10] instead of the fit's 10 (at its bound): in
# results/sand_calibration/walk_gap_terms/ the fit's value makes dry sand too stiff under a walking foot (stance 2 cm
# against MPM's 8), 0 too soft at 1.5 m/s (27 cm), and MPM's walks lie between.
# A quarter of the material draws come from 500-800 kg/m^3 (--soft-share 0.25): at 4,414 the teacher walks the deep
# bed's dry sand and basalt but tips on poppy seed (638 kg/m^3) within 0.3 s, also over a hard floor 12 or 20 cm down
# (results/training_gate/poppy_probe/), and packing x bulk density puts only ~8 % of the draws below 800.
# The sand is whatever .devsrc/rft3d_calibrated.json holds: results/sand_calibration/rft3d_calibrated.json (the sole fit)
# or, to train on the sand whose walks fail where MPM's do (term (f), loosening by horizontal travel;
# results/sand_calibration/walk_gap_terms/), results/sand_calibration/walk_gap_terms/extensions/refit_loosening.json
# (this command ran on a CPU with it from 4,414, 8 envs).
# The entropy coefficient drops from 0.005 to 0.001 (the student PPO's): at 0.005 the action std rose from 0.86 to
# 1.22 over 2,048 iterations, the entropy bonus outweighing the little the GM-Loco rewards charge for noisy actions.
set -uo pipefail
end=$1
run=gm_loco_teacher_calibrated
cd ~/src
source scripts/gpu/env.sh
stage_calibrated_run "$run" teacher
cp .devsrc/checkpoint.pt "artifacts/$run/checkpoint.pt"
nvidia-smi --query-gpu=name,memory.total --format=csv > ~/chunks/gpu.txt 2>&1
gate=${GATE:-1}
mins=$(python3 -c "import time; print(round(($end - time.time())/60 - (3.4 if $gate == 1 else 0.3), 2))")
echo "teacher chunk: max-minutes $mins" > ~/chunks/job.log
python3 scripts/gpu/train_ts_chunk.py --stage teacher --run "$run" --contact-model rft3d_calibrated \
  --foot-clearance sinkage --foot-faces box --curriculum-scale 0.1 --reward-weight foot_clearance_l2=-50 \
  --floor-promotion survival --floor-depth-max 0.20 --floor-levels 11 --entropy-coef 0.001 \
  --rft-extension-range added_mass=0.5,10 --allow-changed task.rft_extension_ranges \
  --soft-share 0.25 --allow-changed task.material.soft_share \
  --allow-changed task.terrain.floor.promotion --allow-changed task.terrain.floor.depth_range \
  --allow-changed task.terrain.floor.num_levels \
  --allow-changed rsl_rl_overrides.algorithm.entropy_coef \
  --max-iterations 6000 --max-minutes "$mins" --post-minutes 1.0 --full-checkpoint --out ~/chunks/teacher \
  >> ~/chunks/job.log 2>&1
echo "train rc $?" >> ~/chunks/job.log
mkdir -p ~/chunks/gate "artifacts/${run}_newest"
[ "$gate" = 1 ] && cp ~/chunks/teacher/checkpoint.pt ~/chunks/teacher/summary.json "artifacts/${run}_newest/" &&
  timeout "$(( end - $(date +%s) - 10 ))" python3 -m gmloco.train.gate --policy "artifacts/${run}_newest" \
    --episodes 20 --num-envs 240 --seconds 10 --materials dry_sand,poppy_seed,basalt --speeds 0.5,1.0,1.5,2.0 \
    --parts success --contact-model rft3d_calibrated --device cuda:0 --out ~/chunks/gate/deep_bed.json \
    > ~/chunks/gate/deep_bed.log 2>&1
echo "gate rc $?" >> ~/chunks/job.log
[ "${NESTED:-0}" = 1 ] || touch ~/chunks/DONE  # a wrapper job (NESTED=1) marks DONE itself
