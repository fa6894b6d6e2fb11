#!/usr/bin/env bash
# Machine 1 of the swing-trip study (issue 9). GPU: fine-tune the delivered student (clr50, it 1081) with a 6x swing-clearance
# weight (foot_clearance_l2 = -300) as run gm_loco_student_hs; chunk A, then (background) the chunk-A student on MPM
# sand at 3 cm / 5 ms / 250 its in the probe while chunk B trains on.
# Usage (in ~/src): bash job.sh END_EPOCH
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/probe runs/gpu/gm_loco_student_hs
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
log "start commit $(cat COMMIT 2>/dev/null)"
cp artifacts/gm_loco_student_clr50/checkpoint.pt runs/gpu/gm_loco_student_hs/model_1081.pt
T="python3 scripts/gpu/train_ts_chunk.py --stage student --run gm_loco_student_hs --contact-model rft3d --terrain flat --num-envs 4096 --num-steps-per-env 24 --max-iterations 3000 --post-minutes 1.5 --save-interval 50 --history-length 50 --latent-dim 16 --curriculum-finish 300 --decoder-loss-weight 100 --reward-weight foot_clearance_l2=-300 --teacher-checkpoint artifacts/gm_loco_teacher_clr50/checkpoint.pt --curriculum-scale 0.1"
timeout 720 $T --max-minutes 11 --out $HOME/chunks/hs_a > ~/chunks/hs_a.log 2>&1; log "chunk A rc=$?"
P="python3 results/mpm_eval/policy_probe.py --window eval --vx 1.0 --duration 3 --every 4 --iterations 250 --frame-dt 0.005 --substeps 1 --handover predict --voxel 0.03"
if [ -f ~/chunks/hs_a/policy.onnx ]; then
  ( timeout 600 $P --policy $HOME/chunks/hs_a/policy.onnx --label student_hs_A_v3_i250_dt0.005_sub1 --log $HOME/chunks/probe/hs.jsonl > ~/chunks/probe/hs_a.log 2>&1; log "probe A rc=$?" ) &
fi
M=$(left 1.2)
timeout $(python3 -c "print(int(max(60,$M*60)))") $T --max-minutes $(python3 -c "print(max(1,$M-0.3))") --out $HOME/chunks/hs_b > ~/chunks/hs_b.log 2>&1; log "chunk B rc=$?"
touch ~/chunks/FG_DONE
wait
