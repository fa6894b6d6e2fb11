# SPDX-License-Identifier: Apache-2.0
"""Fill a Warp kernel cache for the GPU machine from a CPU-only machine (no driver needed: NVRTC is in the wheel).

A fresh GPU machine spends ~4.5 minutes compiling the MPM evaluation's kernels before its first frame. This runs one
tiny evaluation episode on the CPU in the CUDA layout (one mujoco_warp world per robot; so every Warp module the evaluation uses is built and its kernel overloads
exist), then compiles each module that was loaded for CUDA ahead of time, at the launch block size
(``Module.options['block_dim']``, which CUDA loads use; CPU loads use 1) as CUBIN (or PTX) for the given
architectures, into ``--cache``. Carry the folder to the GPU machine (``tar czf``) and point ``WARP_CACHE_PATH`` at
it: modules whose hash matches load as ``(cached)``; any the CPU run did not touch (CUDA-only code paths, kernels
launched with their own block size) still compile there as before, so a partial cache is never wrong.

    python scripts/gpu/warm_cache.py --cache .devcache/warp -- --terrains dry_sand --speeds 1.0
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from typing import Any


def _compile_loaded(arches: list[int], formats: list[str]) -> tuple[int, int]:
    """AOT-compile every module with a loaded executable; returns (modules, failures)."""
    import warp as wp
    from warp._src import context as ctx

    done = failed = 0
    for module in list(ctx.user_modules.values()):
        if not module.execs:
            continue
        block_dim = module.options["block_dim"]
        module.resolved_options[block_dim] = module.resolve_options(wp.config, block_dim=block_dim)
        module.get_module_hash(block_dim)
        module_dir = os.path.join(wp.config.kernel_cache_dir, module.get_module_identifier(block_dim))
        for arch in arches:
            for fmt in formats:
                try:
                    module._compile(None, module_dir, output_arch=arch, use_ptx=fmt == "ptx",
                                    options=module.resolved_options[block_dim])  # fmt: skip
                except Exception as e:  # a module that fails here simply compiles on the GPU
                    failed += 1
                    print(f"  {module.name} sm{arch} {fmt}: {type(e).__name__}: {e}"[:300], flush=True)
        done += 1
        print(f"[warm_cache] {done} modules ({module.name})", flush=True)
    return done, failed


def main(argv: list[str] | None = None) -> None:
    """Run the tiny CPU episode, then compile the modules it loaded for the GPU (see the module docstring)."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cache", required=True, help="kernel cache folder to fill (WARP_CACHE_PATH there)")
    p.add_argument("--arch", type=int, nargs="+", default=[90], help="CUDA architectures (H100 / H200: 90)")
    p.add_argument(
        "--formats",
        nargs="+",
        default=["cubin"],
        choices=["ptx", "cubin"],
        help="Warp loads CUBIN where the driver is older than its toolkit (the lent machines: driver 13.0, "
        "Warp 1.19's toolkit 13.4), PTX otherwise",
    )
    p.add_argument("eval_args", nargs="*", help="g1_eval_cli arguments of the tiny CPU episode (after --)")
    a = p.parse_args(argv)
    os.environ["WARP_CACHE_PATH"] = os.path.abspath(a.cache)
    import warp as wp

    wp.config.kernel_cache_dir = os.path.abspath(a.cache)
    from gmloco.eval import g1_eval_cli
    from gmloco.eval.mpm import g1_scene

    build = g1_scene.G1MpmScene._build_robots

    def as_worlds(self: Any, newton: Any, wp_: Any) -> Any:
        # the CUDA layout (one mujoco_warp world per robot), so that mujoco_warp's kernels load too
        if self.cfg.robots_as_worlds is None:
            object.__setattr__(self.cfg, "robots_as_worlds", True)
        return build(self, newton, wp_)

    g1_scene.G1MpmScene._build_robots = as_worlds

    t0 = time.time()
    with tempfile.TemporaryDirectory() as out:
        tiny = ["--out", out, "--device", "cpu", "--num-episodes", "1", "--episode-s", "0.1", "--voxel", "0.05",
                "--robots-per-batch", "2", "--no-mcap", "--fresh"]  # fmt: skip
        g1_eval_cli.main(tiny + a.eval_args)
    print(f"[warm_cache] CPU episode done in {time.time() - t0:.0f} s; compiling for sm{a.arch} {a.formats}")
    done, failed = _compile_loaded(a.arch, a.formats)
    print(f"[warm_cache] {done} modules compiled into {a.cache} ({failed} failures) in {time.time() - t0:.0f} s")
    sys.exit(0)


if __name__ == "__main__":
    main()
