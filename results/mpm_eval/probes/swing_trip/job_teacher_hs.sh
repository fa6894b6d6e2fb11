#!/usr/bin/env bash
# Machine 3 of the swing-trip study (issue 9): continue the clr50 teacher (it 1276) with a 6x swing-clearance weight
# (foot_clearance_l2 = -300) as run gm_loco_teacher_hs. The student fine-tune of machine 2 showed that the
# distillation term holds the student to its teacher's ~4.5 cm swing, so the gait has to change in the teacher.
# Usage (in ~/src): bash job3.sh END_EPOCH
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks runs/gpu/gm_loco_teacher_hs
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
log "start commit $(cat COMMIT 2>/dev/null)"
cp artifacts/gm_loco_teacher_clr50/checkpoint.pt runs/gpu/gm_loco_teacher_hs/model_1276.pt
M=$(left 0.8)
timeout $(python3 -c "print(int(max(60,$M*60)))") python3 scripts/gpu/train_ts_chunk.py --stage teacher --run gm_loco_teacher_hs --contact-model rft3d --terrain flat --num-envs 4096 --num-steps-per-env 24 --max-iterations 6000 --post-minutes 1.2 --save-interval 50 --latent-dim 16 --reward-weight foot_clearance_l2=-300 --curriculum-scale 0.1 --max-minutes $(python3 -c "print(max(1,$M-0.3))") --out $HOME/chunks/teacher_hs > ~/chunks/teacher_hs.log 2>&1; log "teacher chunk rc=$?"
touch ~/chunks/FG_DONE
