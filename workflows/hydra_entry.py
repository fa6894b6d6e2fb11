# SPDX-License-Identifier: Apache-2.0
"""The one ``@hydra.main`` entry used by every workflow: checks the command line first, picks the scale.

Before Hydra runs the task, the command line is composed once with the compose API. Bad input (unknown
``+exp=``, a typo in an override, a missing value) is reported as one paragraph and exit code 2 instead of a
traceback; ``HYDRA_FULL_ERROR=1`` re-raises the original error with its full traceback. On a machine without
CUDA, when no scale was chosen, ``+scale=smoke`` is appended and announced.
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Callable, Sequence

import hydra
from hydra import compose, initialize_config_dir
from hydra._internal.utils import get_args_parser
from omegaconf import DictConfig, OmegaConf, open_dict
from omegaconf.errors import OmegaConfBaseException
from rich.markup import escape

from workflows import (
    schemas,  # noqa: F401  (registers the schemas and resolvers)
    stage_registry,
)
from workflows.config_errors import CONF_DIR, ConfigInputError, explain, group_options, groups, unknown_key_error
from workflows.config_ranges import range_problem
from workflows.input_checks import input_problem
from workflows.pipeline_report import console
from workflows.run_guard import run_dir_problem
from workflows.schemas import PipelineCfg
from workflows.stage_runner import PipelineConfigError, validate_selection
from workflows.task_fields import TASK_SECTION

__all__ = ["EXIT_BAD_INPUT", "check_config", "compose_checked", "hydra_entry"]

EXIT_BAD_INPUT = 2
"""Exit code for bad command-line or config input."""

SMOKE_OVERRIDE = "+scale=smoke"
"""Appended on CPU-only machines when no scale is chosen."""


def _full_error() -> bool:
    """Whether the user asked Hydra for full tracebacks."""
    return os.environ.get("HYDRA_FULL_ERROR") == "1"


def _missing_values(cfg: DictConfig, prefix: str = "") -> list[str]:
    """Dotted keys whose value is ``???`` (checked without resolving interpolations)."""
    out: list[str] = []
    for key in map(str, cfg):
        if OmegaConf.is_missing(cfg, key):
            out.append(f"{prefix}{key}")
            continue
        node = cfg._get_node(key)
        if isinstance(node, DictConfig) and not node._is_none() and not node._is_interpolation():
            out.extend(_missing_values(node, f"{prefix}{key}."))
    return out


def _check_missing(cfg: DictConfig, stage_names: Sequence[str]) -> None:
    """Raise for ``???`` values outside the unselected stages' sections."""
    ignored = (*(f"{s}." for s in stage_names if s not in cfg.stages), "hydra.")
    missing = [k for k in _missing_values(cfg) if not k.startswith(ignored)]
    if "exp_name" in missing:
        exps = ", ".join(group_options("exp"))
        raise ConfigInputError(
            "exp_name", f"no experiment chosen: add +exp=<name> to the command. Valid choices for 'exp': {exps}."
        )
    if missing:
        key = missing[0]
        raise ConfigInputError(
            key, f"missing config value '{key}' (marked ??? in the config): set it, e.g. {key}=<value>."
        )


def _check_appended(overrides: Sequence[str]) -> None:
    """Refuse ``+key=value`` for keys that are neither config groups nor schema fields (``+expp=gm_loco``).

    Keys under ``train_teacher.task`` are the task's fields, checked against the task by ``input_checks``.
    """
    for o in overrides:
        if not o.startswith("+") or o.startswith("++") or "=" not in o:
            continue
        key = o[1:].split("=", 1)[0].split("@", 1)[0]
        if key not in groups() and not key.startswith(f"{TASK_SECTION}."):
            raise unknown_key_error(key, o)


def check_config(cfg: DictConfig, overrides: Sequence[str] = ()) -> None:
    """Check a composed config: keys, ``???`` values, stage names, interpolations, ranges and stage inputs.

    Ranges are those the schema declares (``config_ranges``); inputs are the selected stages' recordings and
    effect ids (``input_checks``).
    """
    names = stage_registry.stage_names()
    _check_appended(overrides)
    _check_missing(cfg, names)
    try:
        validate_selection(cfg, stage_registry.STAGES)
    except PipelineConfigError as e:
        raise ConfigInputError(e.key, str(e)) from e
    for key in cfg:
        if key == "hydra" or (key in names and key not in cfg.stages):
            continue
        value = cfg[key]  # resolves a scalar's interpolation
        if isinstance(value, DictConfig):
            OmegaConf.to_container(value, resolve=True)
    problem = range_problem(cfg, PipelineCfg) or input_problem(cfg)
    if problem is not None:
        raise ConfigInputError(*problem)


def compose_checked(config_name: str, overrides: Sequence[str], keep_hydra: bool = False) -> DictConfig:
    """Compose like Hydra would and check the result; raise :class:`ConfigInputError` on bad input.

    Args:
        config_name: primary config in ``conf/``.
        overrides: command-line overrides.
        keep_hydra: keep the ``hydra`` node (``@hydra.main`` tasks never see it).
    """
    try:
        with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
            cfg = compose(config_name, overrides=list(overrides), return_hydra_config=True)
        check_config(cfg, overrides)
    except ConfigInputError:
        raise
    except Exception as e:
        if _full_error():
            raise
        raise explain(e, overrides) from e
    if not keep_hydra:
        with open_dict(cfg):
            del cfg["hydra"]
    return cfg


def _cuda_available() -> bool:
    """``torch.cuda.is_available()``, False without torch."""
    try:
        import torch
    except ImportError:
        return False
    return bool(torch.cuda.is_available())


def _announce_smoke() -> None:
    """Say in one line that this is not a full-scale run, and how to get one."""
    console.print(
        f"[bold yellow]SMOKE SCALE[/][yellow] ({SMOKE_OVERRIDE}): no CUDA device, so tiny sizes that check every stage "
        "end to end in minutes and train no usable policy; +scale=full forces full scale.[/]",
        soft_wrap=True,
    )


def _fail(e: ConfigInputError) -> None:
    """Print the paragraph and exit with :data:`EXIT_BAD_INPUT`."""
    console.print(
        f"[bold red]error:[/] {escape(str(e))} Nothing was run. (Set HYDRA_FULL_ERROR=1 for the full traceback.)"
    )
    sys.exit(EXIT_BAD_INPUT)


def _smoke_needed(overrides: Sequence[str], multirun: bool, config_name: str) -> bool:
    """Compose-check the command line and its run directory; decide whether the smoke scale must be appended."""
    if multirun:  # sweep syntax cannot be composed once; decide from the text (each job gets its own folder)
        chosen = any(o.lstrip("+").startswith(("scale=", "debug=")) for o in overrides)
        return not chosen and not _cuda_available()
    cfg = compose_checked(config_name, overrides, keep_hydra=True)
    smoke = "scale" not in cfg.hydra.runtime.choices and not _cuda_available()
    # The run directory is judged with the config that will run, without the hydra node (its sweep paths only
    # resolve inside a running job)
    cfg = compose_checked(config_name, [*overrides, SMOKE_OVERRIDE] if smoke else list(overrides))
    problem = run_dir_problem(cfg, stage_registry.STAGES)
    if problem is not None:
        raise ConfigInputError(*problem)
    return smoke


def _multirun() -> bool:
    """Whether Hydra runs this task as one job of a multirun sweep."""
    from hydra.core.hydra_config import HydraConfig
    from hydra.types import RunMode

    return HydraConfig.initialized() and HydraConfig.get().mode == RunMode.MULTIRUN


def _guarded(task: Callable[[DictConfig], int]) -> Callable[[DictConfig], None]:
    """Wrap ``task`` so config errors raised while it runs are reported like composition errors."""

    @functools.wraps(task)
    def wrapper(cfg: DictConfig) -> None:
        try:
            code = task(cfg)
        except (PipelineConfigError, OmegaConfBaseException) as e:
            if _full_error():
                raise
            _fail(ConfigInputError(getattr(e, "key", ""), str(e).splitlines()[0]))
            return
        if code and not _multirun():  # in a sweep, one job's status must not stop the others
            sys.exit(code)

    return wrapper


def hydra_entry(task: Callable[[DictConfig], int], *, config_name: str = "full_pipeline", only_stage: str = "") -> None:
    """Check the command line, then run ``task`` (returns an exit code) under ``@hydra.main``.

    Args:
        task: the workflow body; gets the composed config, returns the process exit code.
        config_name: primary config in ``conf/``.
        only_stage: run just this stage (appends ``stages=[<only_stage>]``).
    """
    argv = sys.argv[1:]
    args = get_args_parser().parse_args(argv)
    job_name = only_stage or config_name
    extra = [f"hydra.job.name={job_name}", *([f"stages=[{only_stage}]"] if only_stage else [])]
    overrides = [*args.overrides, *extra]
    if not (args.help or args.hydra_help or args.info or args.shell_completion):
        try:
            if _smoke_needed(overrides, bool(args.multirun), config_name):
                _announce_smoke()
                extra.append(SMOKE_OVERRIDE)
        except ConfigInputError as e:
            _fail(e)
    # Overrides first, options (--cfg job, --multirun, ...) last: argparse takes the positional overrides in one run.
    options = list(argv)
    for o in args.overrides:
        options.remove(o)
    sys.argv = [sys.argv[0], *args.overrides, *extra, *options]
    main = hydra.main(config_path=str(CONF_DIR), config_name=config_name, version_base="1.3")(_guarded(task))
    main()
