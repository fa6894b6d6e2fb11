#!/usr/bin/env bash
# Prepared in the grid-capacity runs for a later GPU run (issue 9); NOT yet run. One H200 machine per part, ~25 min each.
#   part a: (1) the voxel check that the grid-capacity runs left open: 2 cm at 1000 rheology iterations, 8 robots x 5 s
#           (~9 min), then  python -m gmloco.eval.convergence --reference <2 cm / 1000> --candidate
#           results/mpm_eval/convergence/accepted_setting/runs/td_v0.03_it500_d0.3_l1.4_r8_5s{,_seed1}  (and the 2 cm / 500 run of
#           ./runs as a second candidate: do iterations or the voxel move the sinkage?);
#           (2) the contact-model ablation's first row: ppo_rft3d, dry sand, straight, 1.0-2.5 m/s, 100 episodes
#           (69 done in the grid-capacity runs: copy results/mpm_eval/convergence/grid_capacity_solvers/runs/table_ppo_rft3d_dry_sand to
#           .devsrc/row/ before the launch and it resumes).
#   part b: the rows of ppo_rigid and the clr50 student (same cell). Policies that fall within ~3 s cost ~1/4 of a
#           walking policy's row (lanes refill as robots fall), ~8 min each on an H200.
# Every row is resumable: carry a run folder back under .devsrc/row/<name> and it continues from its episodes.jsonl.
# Afterwards: python -m gmloco.eval.paper_tables --run gm_loco_student_td=results/mpm_eval/convergence/grid_capacity_solvers/runs/table_td_dry_sand
#   --run ppo_rft3d=<dir> --run ppo_rigid=<dir> --run gm_loco_student_clr50=<dir> --out results/mpm_eval/tables
#   --summary results/mpm_eval/summary.json
# Usage (in ~/src, after the wheels and the Warp cache): bash job_next.sh END_EPOCH a|b
END=$1
PART=$2
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval
[ -d ~/src/.devsrc/row ] && cp -r ~/src/.devsrc/row/* ~/chunks/g1_eval/
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
row() {  # row NAME POLICY: 100 episodes, dry sand, straight, 1.0-2.5 m/s, resumable, time-boxed to the machine
  M=$(left 0.7)
  timeout $(python3 -c "print(int(max(30,$M*60+20)))") python3 -m gmloco.eval.g1_eval_cli --policy $2 \
    --terrains dry_sand --scenarios straight --speeds 1.0 1.5 2.0 2.5 --num-episodes 100 --robots-per-batch 36 \
    --max-minutes $M --out $HOME/chunks/g1_eval/$1 >> ~/chunks/g1_eval/$1.log 2>&1
  log "row $1 rc=$?"
}
log "start part $PART"
if [ "$PART" = a ]; then
  L=td_v0.02_it1000_d0.3_l1.4_r8_5s
  timeout 720 python3 -m gmloco.eval.g1_eval_cli --policy artifacts/gm_loco_student_td/policy.onnx \
    --terrains dry_sand --speeds 1.0 --no-mcap --fresh --voxel 0.02 --iters 1000 --episode-s 5 --num-episodes 8 \
    --robots-per-batch 8 --max-minutes 11 --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
  log "g1_eval $L rc=$?"
  row table_ppo_rft3d_dry_sand artifacts/ppo_rft3d/policy.onnx
else
  row table_ppo_rigid_dry_sand artifacts/ppo_rigid/policy.onnx
  row table_clr50_dry_sand artifacts/gm_loco_student_clr50/policy.onnx
fi
touch ~/chunks/DONE
