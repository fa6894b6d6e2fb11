#!/usr/bin/env bash
# Machine 1 of the touchdown-lift study (issue 9): teacher from clr50 (it 1276) with the touchdown lift reward and box-face RFT,
# then the adaptation walk of its newest checkpoint on the GPU.
# Usage (in ~/src): bash job.sh END_EPOCH
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks runs/gpu/gm_loco_teacher_td
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
log "start commit $(cat COMMIT 2>/dev/null)"
cp artifacts/gm_loco_teacher_clr50/checkpoint.pt runs/gpu/gm_loco_teacher_td/model_1276.pt
M=$(left 2.6)
timeout $(python3 -c "print(int(max(60,$M*60)))") python3 scripts/gpu/train_ts_chunk.py --stage teacher --run gm_loco_teacher_td --contact-model rft3d --terrain flat --num-envs 4096 --num-steps-per-env 24 --max-iterations 6000 --post-minutes 1.2 --save-interval 50 --latent-dim 16 --foot-clearance touchdown --foot-faces box --reward-weight foot_clearance_l2=-50 --curriculum-scale 0.1 --max-minutes $(python3 -c "print(max(1,$M-0.3))") --out $HOME/chunks/teacher_td > ~/chunks/td_train.log 2>&1; log "teacher chunk rc=$?"
CK=$(ls -t runs/gpu/gm_loco_teacher_td/model_*.pt | head -1); log "newest $CK"
timeout 120 python3 scripts/gpu/eval_ts.py --actor teacher --teacher $CK --foot-faces box --adaptation-envs 64 --baseline none --device cuda:0 --out $HOME/chunks/td_eval > ~/chunks/td_eval.log 2>&1; log "eval rc=$?"
mkdir -p ~/chunks/ckpt && cp $CK ~/chunks/ckpt/
touch ~/chunks/FG_DONE
