#!/usr/bin/env bash
# There, from ~/src: bash .devsrc/poll.sh MAX_SECONDS [RUN] (copy it to .devsrc/poll.sh); rc 3 while the job runs.
# Poll the job; copy what exists into $OUT (slim newest checkpoint while running; everything once DONE).
max=${1:-540}
for _ in $(seq 1 $((max / 5))); do [ -e ~/chunks/DONE ] && break; sleep 5; done
grep -v "^\s*$" ~/chunks/job.log | tail -n 6
run=${2:-gm_loco_teacher_sinkage}
for d in ~/chunks/calib*; do for m in dry_sand poppy_seed basalt; do
  echo "== $(basename "$d") $m"; tail -n 3 "$d/$m.log" 2>/dev/null
  [ -f "$d/$m.npz" ] && cp "$d/$m.npz" "$OUT/$(basename "$d")_$m.npz"
done; done
if [ -e ~/chunks/DONE ]; then
  cp ~/src/.devsrc/COMMIT ~/chunks/ 2>/dev/null
  # a call brings back files of at most 16 MiB: the full checkpoint alone is ~21 MB
  tar czf - -C ~/chunks --exclude='*.npz' . | split -b 12M - "$OUT/chunks.tgz.part" && ls -la "$OUT"; exit 0
fi
ck=$(ls -t ~/src/runs/gpu/"$run"/model_*.pt 2>/dev/null | head -1)
[ -n "$ck" ] && python3 scripts/gpu/slim_checkpoint.py "$ck" "$OUT/$(basename "$ck")"
tar czf "$OUT/logs.tgz" -C ~/chunks --exclude='*.npz' job.log $(cd ~/chunks && ls -d calib* lr_ab reward_ab 2>/dev/null)
echo "still running at $(date +%T)"; exit 3
