# Shared names for MPM-evaluation task files (issue 9); source it in a job script, then write task lines with them.
# The policies, the tables' row (100 ten-second episodes at 1.0-2.5 m/s, 50 lanes), the square window (holds the
# tables' 1.4 x 0.6 m window at every heading: for walks that turn), ppo_rigid's wide window, the reach window (for
# soles left far behind), and `shares NAME ARGS`:
# a row as four task lines, one per share (--shard I/4; with four speeds, one speed each).
TD=artifacts/gm_loco_student_td/policy.onnx
CLR50=artifacts/gm_loco_student_clr50/policy.onnx
RIGID=artifacts/ppo_rigid/policy.onnx
RFT=artifacts/ppo_rft3d/policy.onnx
ROW="--speeds 1.0 1.5 2.0 2.5 --num-episodes 100 --robots-per-batch 50"
SQ="--window-length 1.4 --window-width 1.4 --window-lead 0.2"
WIDE="--window-length 1.4 --window-width 1.3 --window-lead 0.0"
# Reach window for walks that sink and stumble (poppy seed, deep sand): their trailing sole stays up to 0.73 m
# behind the pelvis (the per-terrain runs), past the tables' window's rear (0.5 m at lead 0.2); ahead it reaches 0.13 m. This
# window (g1_eval.covering_window of that reach) has its rear 0.8 m behind and keeps the accepted front (0.9 m).
REACH="--window-length 1.7 --window-width 0.8 --window-lead 0.05"
shares() {
  local N=$1; shift
  for i in 0 1 2 3; do echo "${N}_share${i}of4 $* --shard $i/4"; done
}
