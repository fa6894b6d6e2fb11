# SPDX-License-Identifier: Apache-2.0
"""Fill a Warp kernel cache for the GPU machine from a CPU-only machine (no driver needed: NVRTC is in the wheel).

A fresh GPU machine spends ~4.5 minutes compiling the MPM evaluation's kernels before its first frame. This runs one
tiny evaluation episode on the CPU in the CUDA layout (one mujoco_warp world per robot), so that every Warp module
the evaluation uses is built and its kernel overloads exist, then compiles each module that was loaded ahead of
time for CUDA into ``--cache``: at the module's launch block size (``Module.options['block_dim']``, which CUDA loads
use; CPU loads use 1), as CUBIN (or PTX), for the given architectures. Kernels launched with a block size of their
own (mujoco_warp's tile kernels) hash differently; ``--gpu-logs`` names the logs of an earlier GPU run, and every
module variant they show compiled there is compiled here too when some block size reproduces its hash. Carry the
folder to the GPU machine (``tar czf``) and point ``WARP_CACHE_PATH`` at it: modules whose hash matches load as
``(cached)``; any the CPU run did not reproduce still compile there as before, so a partial cache is never wrong.

    python scripts/gpu/warm_cache.py --cache .devcache/warp --gpu-logs results/mpm_eval/table_rows/ablation_circles/logs/*.log \
        -- --terrains dry_sand --speeds 1.0
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

_COMPILED = re.compile(r"Module (\S+) ([0-9a-f]{7}) load on device 'cuda:\d+' took [\d.]+ ms\s+\(compiled\)")
BLOCK_DIMS = (16, 32, 64, 128, 256, 512, 1024)
"""Block sizes tried for a module a GPU log names (tile kernels are launched with their own)."""


def wanted_from_logs(paths: list[str]) -> dict[str, set[str]]:
    """The modules a GPU run had to compile, by name, with their 7-digit hashes (its logs' ``(compiled)`` lines)."""
    out: dict[str, set[str]] = {}
    for path in paths:
        for m in _COMPILED.finditer(Path(path).read_text(errors="replace")):
            out.setdefault(m[1], set()).add(m[2])
    return out


def _block_dims(module: Any, wanted: dict[str, set[str]]) -> list[int]:
    """The module's default block size, plus those at which it hashes as a GPU log's compiled variant did."""
    dims = [module.options["block_dim"]]
    for bd in BLOCK_DIMS:
        if bd not in dims and module.get_module_hash(bd).hex()[:7] in wanted.get(module.name, ()):
            dims.append(bd)
    return dims


def _compile_loaded(arches: list[int], formats: list[str], wanted: dict[str, set[str]]) -> tuple[int, int, set]:
    """AOT-compile every module with a loaded executable; returns (variants, failures, GPU-log hashes matched)."""
    import warp as wp
    from warp._src import context as ctx

    done = failed = 0
    matched: set[tuple[str, str]] = set()
    for module in list(ctx.user_modules.values()):
        if not module.execs:
            continue
        for block_dim in _block_dims(module, wanted):
            digest = module.get_module_hash(block_dim).hex()[:7]
            if digest in wanted.get(module.name, ()):
                matched.add((module.name, digest))
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
            print(f"[warm_cache] {done} module variants ({module.name}, block {block_dim})", flush=True)
    return done, failed, matched


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
    p.add_argument("--gpu-logs", nargs="*", default=[], help="logs of an earlier GPU run: also compile the block-size "
                   "variants of the modules it had to compile (their '(compiled)' lines)")  # fmt: skip
    p.add_argument("eval_args", nargs="*", help="gmloco.eval.g1.cli arguments of the tiny CPU episode (after --)")
    a = p.parse_args(argv)
    os.environ["WARP_CACHE_PATH"] = os.path.abspath(a.cache)
    import warp as wp

    wp.config.kernel_cache_dir = os.path.abspath(a.cache)
    from gmloco.eval.g1 import cli as g1_cli
    from gmloco.eval.g1 import scene as g1_scene

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
        g1_cli.main(tiny + a.eval_args)
    print(f"[warm_cache] CPU episode done in {time.time() - t0:.0f} s; compiling for sm{a.arch} {a.formats}")
    wanted = wanted_from_logs(a.gpu_logs)
    done, failed, matched = _compile_loaded(a.arch, a.formats, wanted)
    print(
        f"[warm_cache] {done} module variants compiled into {a.cache} ({failed} failures) in {time.time() - t0:.0f} s"
    )
    if wanted:
        missed = sorted(f"{n} {h}" for n, hs in wanted.items() for h in hs if (n, h) not in matched)
        print(f"[warm_cache] of the GPU logs' {sum(map(len, wanted.values()))} compiled variants, {len(matched)} are "
              f"in the cache now; not reproduced on the CPU: {', '.join(missed) or 'none'}")  # fmt: skip
    sys.exit(0)


if __name__ == "__main__":
    main()
