# Source on the GPU machine from the repository root: puts the installed wheels and the project's packages on
# PYTHONPATH (no uv, no network there) and sets headless, offline defaults.
export PYTHONPATH="$HOME/.gmloco-site:$PWD/packages/contact/src:$PWD/packages/train/src:$PWD/packages/eval/src:$PWD/packages/deploy/src:$PWD${PYTHONPATH:+:$PYTHONPATH}"
export MUJOCO_GL=${MUJOCO_GL:-disable} WANDB_MODE=${WANDB_MODE:-offline} PYTHONUNBUFFERED=1
export WARP_CACHE_PATH=${WARP_CACHE_PATH:-$HOME/.gmloco-warp-cache}
