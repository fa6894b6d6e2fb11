#!/usr/bin/env bash
# The v4 protocol's part command (results/mismatch_benchmark/v4/PROTOCOL.md, "Part P"), run for each part given,
# one after another, in the background of a GPU machine whose GPU runs other work (issue 8's sweep uses its CPUs).
# Before: a call carrying .devsrc_v4 extracts the protocol snapshot to ~/src_v4
#   (rm -rf ~/src_v4 && mkdir ~/src_v4 && tar xzf .devsrc_v4/src.tgz -C ~/src_v4),
# and ~/src holds a checkout with the committed v4 rows (results/), from which ~/mm_v4 is seeded.
# Usage (e.g. from a job script): (bash ~/src/scripts/gpu/v4_parts.sh 6 7 > ~/chunks/v4.log 2>&1 &)
# Each part ends with ~/mm_v4/logs/end_p<P>_<HHMM>.txt (the `missing` lists); bring ~/mm_v4 back with tar.
for P in "$@"; do
  R=~/src && T=$(date +%H%M) && mkdir -p ~/mm_v4/logs && for s in sand plane; do [ -d ~/mm_v4/$s ] || [ ! -d $R/results/mismatch_benchmark/v4/$s ] || cp -r $R/results/mismatch_benchmark/v4/$s ~/mm_v4/; done && rm -f ~/mm_v4/{sand,plane}/summary.json && (
    cd ~/src_v4 && test -f artifacts/ppo_rft3d/policy.onnx && source scripts/gpu/env.sh &&
    export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 &&
    python3 -c "import warp, onnxruntime, mujoco, scipy; from gmloco.deploy.mismatch.benchmark.episodes import SAND_MID_V4 as M; assert M['terrain.depth_hardening'] == {'kappa': [150.0]}" &&
    S="python3 -m gmloco.deploy.mismatch.benchmark.sweep --strength-table v4 --seeds 2 --seed-offset 20000 --part $P/8 --resume --deadline-s 300" &&
    ( timeout -k 10 570 $S --suite sand --motion composite --nulls 64 --workers 12 --out ~/mm_v4/sand > ~/mm_v4/logs/sand_p${P}_$T.log 2>&1 &
      timeout -k 10 570 $S --suite plane --nulls 20 --duration 9 --workers 4 --out ~/mm_v4/plane > ~/mm_v4/logs/plane_p${P}_$T.log 2>&1 &
      wait )
  )
  (date; nproc --all; uptime; for s in sand plane; do python3 -c "import json,sys;print(sys.argv[1],'missing',json.load(open(sys.argv[1]))['missing'])" ~/mm_v4/$s/summary.json; ls ~/mm_v4/$s/rows | wc -l; done) > ~/mm_v4/logs/end_p${P}_$T.txt 2>&1
  echo "part $P done at $(date +%T)"; cat ~/mm_v4/logs/end_p${P}_$T.txt
done
