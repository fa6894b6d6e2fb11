# Source on the GPU machine from the repository root: puts the installed wheels and the project's packages on
# PYTHONPATH (no uv, no network there) and sets headless, offline defaults.
export PYTHONPATH="$HOME/.gmloco-site:$PWD/packages/contact/src:$PWD/packages/train/src:$PWD/packages/eval/src:$PWD/packages/deploy/src:$PWD${PYTHONPATH:+:$PYTHONPATH}"
export MUJOCO_GL=${MUJOCO_GL:-disable} WANDB_MODE=${WANDB_MODE:-offline} PYTHONUNBUFFERED=1
export WARP_CACHE_PATH=${WARP_CACHE_PATH:-$HOME/.gmloco-warp-cache}

# stage_calibrated_run RUN CHUNK: make ~/chunks/CHUNK and artifacts/RUN, and put the sand terms the job was given
# (.devsrc/rft3d_calibrated.json) where contact_model rft3d_calibrated reads them.
stage_calibrated_run() {
  mkdir -p ~/chunks/"$2" "artifacts/$1" results/sand_calibration
  cp .devsrc/rft3d_calibrated.json results/sand_calibration/rft3d_calibrated.json
}
