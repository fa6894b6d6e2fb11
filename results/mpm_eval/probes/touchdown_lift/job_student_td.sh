#!/usr/bin/env bash
# Machine 2 of the touchdown-lift study (issue 9): distil the touchdown/box teacher (gm_loco_teacher_td) into a new student
# (gm_loco_student_td): actor/critic from the teacher, TCN from the delivered clr50 student; chunk A, then (background)
# chunk A's export on MPM sand at 3 cm / 5 ms / 250 its in the probe while chunk B trains on.
# Usage (in ~/src): bash job.sh END_EPOCH TEACHER_CKPT
END=$1; TCK=$2
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/probe
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
log "start commit $(cat COMMIT 2>/dev/null) teacher $TCK"
T="python3 scripts/gpu/train_ts_chunk.py --stage student --run gm_loco_student_td --contact-model rft3d --terrain flat --num-envs 4096 --num-steps-per-env 24 --max-iterations 3000 --post-minutes 1.5 --save-interval 50 --history-length 50 --latent-dim 16 --curriculum-finish 200 --decoder-loss-weight 100 --foot-clearance touchdown --foot-faces box --reward-weight foot_clearance_l2=-50 --teacher-checkpoint $TCK --curriculum-scale 0.1"
timeout 600 $T --warm-start-encoder artifacts/gm_loco_student_clr50/checkpoint.pt --max-minutes 9 --out $HOME/chunks/std_a > ~/chunks/std_a.log 2>&1; log "chunk A rc=$?"
P="python3 results/mpm_eval/policy_probe.py --window eval --vx 1.0 --duration 3 --every 4 --iterations 250 --frame-dt 0.005 --substeps 1 --handover predict --voxel 0.03"
if [ -f ~/chunks/std_a/policy.onnx ]; then
  ( timeout 480 $P --policy $HOME/chunks/std_a/policy.onnx --label student_td_A_v3_i250_dt0.005_sub1 --log $HOME/chunks/probe/td.jsonl > ~/chunks/probe/td_a.log 2>&1; log "probe A rc=$?" ) &
fi
M=$(left 1.2)
timeout $(python3 -c "print(int(max(60,$M*60)))") $T --max-minutes $(python3 -c "print(max(1,$M-0.3))") --out $HOME/chunks/std_b > ~/chunks/std_b.log 2>&1; log "chunk B rc=$?"
touch ~/chunks/FG_DONE
wait
