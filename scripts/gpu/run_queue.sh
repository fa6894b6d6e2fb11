#!/usr/bin/env bash
# Run an MPM-evaluation task file on every GPU of the lent machine, time-boxed to END (issue 9).
#   Usage (in ~/src, after the wheels and the Warp cache): bash scripts/gpu/run_queue.sh TASKS END_EPOCH
#   Check on a CPU instead (parses every line as g1_eval_cli will, runs nothing): DRY=1 bash scripts/gpu/run_queue.sh TASKS 0
# TASKS: one `NAME g1_eval_cli-arguments` line per task (python -m gmloco.eval.g1.queue --help). Run folders go
# to ~/chunks/g1_eval (an existing folder resumes: copy earlier ones from ~/src/.devsrc/row/ first), the log to
# ~/chunks/job.log; ~/chunks/DONE appears when the queue has stopped. The queue stops 0.7 min before END, leaving
# the fetch call time to pack ~/chunks before the machine's held time runs out.
TASKS=$1
END=$2
if [ -n "${DRY:-}" ]; then
  python3 -m gmloco.eval.g1.queue --tasks "$TASKS" --check
  exit
fi
source scripts/gpu/env.sh
mkdir -p ~/chunks/g1_eval
[ -d .devsrc/row ] && cp -r .devsrc/row/* ~/chunks/g1_eval/
NGPU=$(nvidia-smi -L | wc -l)
M=$(python3 -c "import time; print(round(($END - time.time()) / 60 - 0.7, 2))")
echo "start: $NGPU GPUs, $M min at $(date +%T)" > ~/chunks/job.log
python3 -m gmloco.eval.g1.queue --gpus $(seq -s ' ' 0 $((NGPU - 1))) --out ~/chunks/g1_eval \
  --tasks "$TASKS" --max-minutes "$M" >> ~/chunks/job.log 2>&1
echo "queue rc=$? at $(date +%T)" >> ~/chunks/job.log
touch ~/chunks/DONE
