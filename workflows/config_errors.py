# SPDX-License-Identifier: Apache-2.0
"""Turn Hydra / OmegaConf composition errors into one clear paragraph that names the key and the choices."""

from __future__ import annotations

import difflib
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from hydra.errors import ConfigCompositionException, MissingConfigException, OverrideParseException
from omegaconf import DictConfig, OmegaConf
from omegaconf.errors import OmegaConfBaseException

from workflows.schemas import REPO_ROOT, PipelineCfg

__all__ = [
    "CONF_DIR",
    "ConfigInputError",
    "default_groups",
    "explain",
    "group_options",
    "groups",
    "unknown_key_error",
]

CONF_DIR = REPO_ROOT / "conf"
"""Hydra config root."""


class ConfigInputError(ValueError):
    """Bad command-line or config input; ``str(self)`` is the paragraph shown to the user."""

    def __init__(self, key: str, message: str) -> None:
        """Store the offending key and the message."""
        self.key = key
        super().__init__(message)


def groups(conf_dir: Path = CONF_DIR) -> list[str]:
    """User-selectable config groups: folders under ``conf/`` holding YAML (``a/b`` when nested), not ``hydra``."""
    found = {p.parent.relative_to(conf_dir).as_posix() for p in conf_dir.rglob("*.yaml") if p.parent != conf_dir}
    return sorted(g for g in found if g.split("/")[0] not in ("hydra", "local"))


def group_options(group: str, conf_dir: Path = CONF_DIR) -> list[str]:
    """YAML options of ``group``."""
    return sorted(p.stem for p in (conf_dir / group).glob("*.yaml"))


def _did_you_mean(word: str, choices: Sequence[str]) -> str:
    """`` (did you mean 'x'?)`` for the closest choice, or ''."""
    close = difflib.get_close_matches(word, list(choices), n=2, cutoff=0.6)
    return f" (did you mean {' or '.join(repr(c) for c in close)}?)" if close else ""


def _choices(items: Sequence[str]) -> str:
    """Comma-separated list."""
    return ", ".join(items) if items else "(none)"


def unknown_key_error(key: str, override: str) -> ConfigInputError:
    """Explain an unknown dotted ``key``: list the valid keys at the level where it goes wrong."""
    node: Any = OmegaConf.structured(PipelineCfg)
    parts = key.split(".")
    for depth, part in enumerate(parts):
        where = ".".join(parts[:depth]) or "the top level"
        if not isinstance(node, DictConfig):
            return ConfigInputError(
                key, f"'{where}' is a value, not a section, so '{key}' (in '{override}') is invalid."
            )
        if part not in node:
            keys = [str(k) for k in node]
            extra = f" Config groups (select with +<group>=<option>): {_choices(groups())}." if depth == 0 else ""
            msg = f"unknown config key '{key}' in '{override}'. Valid keys under {where}: {_choices(keys)}"
            return ConfigInputError(key, f"{msg}{_did_you_mean(part, keys)}.{extra}")
        node = node._get_node(part)  # keep nodes (not values) so nested configs stay DictConfig
        if isinstance(node, DictConfig) and node._is_none() and isinstance(node._metadata.ref_type, type):
            node = OmegaConf.structured(node._metadata.ref_type)  # an optional section left unset: its schema's keys
    return ConfigInputError(key, f"invalid override '{override}'.")


def default_groups(conf_dir: Path = CONF_DIR) -> list[str]:
    """Groups in the primary config's defaults list (``paths``, ``contact``, ...): chosen without ``+``."""
    primary = OmegaConf.load(conf_dir / "full_pipeline.yaml")
    assert isinstance(primary, DictConfig)
    entries = [next(iter(d)) for d in primary.get("defaults", []) if isinstance(d, DictConfig)]
    return sorted(str(k).removeprefix("optional ") for k in entries if str(k).removeprefix("optional ") in groups())


def _choose(group: str) -> str:
    """How the command line chooses an option of ``group``: ``contact=<option>`` or ``+exp=<option>``."""
    return f"{'' if group in default_groups() else '+'}{group}=<option>"


def _missing_group(e: MissingConfigException, overrides: Sequence[str]) -> ConfigInputError:
    """Unknown option of a config group, e.g. ``+exp=gm_lco`` or ``contact=rft4d``."""
    missing = e.missing_cfg_file or ""
    group, _, choice = missing.rpartition("/")
    if group and group in groups():
        options = list(e.options or group_options(group))
        given = next((o for o in overrides if o.lstrip("+").split("=", 1)[0] == group), f"{group}={choice}")
        msg = f"unknown {group} '{choice}' (from '{given}'). Valid choices for '{group}': {_choices(options)}"
        return ConfigInputError(group, f"{msg}{_did_you_mean(choice, options)}.")
    return ConfigInputError(missing, f"cannot find config '{missing}'. Config groups: {_choices(groups())}.")


def _null_group(overrides: Sequence[str]) -> ConfigInputError | None:
    """A config group given ``null`` on the command line (``contact=null``), which Hydra cannot take; else None."""
    given = next((o for o in overrides if o.endswith("=null") and o.lstrip("+").split("=")[0] in groups()), None)
    if given is None:
        return None
    group = given.lstrip("+").split("=")[0]
    return ConfigInputError(
        group,
        f"'{given}' cannot unset the config group '{group}': leave it out of the command, or choose one with "
        f"{_choose(group)}. Valid choices: {_choices(group_options(group))}.",
    )


def _composition(e: ConfigCompositionException, overrides: Sequence[str]) -> ConfigInputError:
    """Typos in overrides, wrong types, a group given without '+'."""
    msg = str(e)
    m = re.search(r"Could not override '([^']+)'", msg)
    if m and "No match in the defaults list" in msg:
        group = m.group(1)
        options = group_options(group) if group in groups() else []
        return ConfigInputError(
            group,
            f"'{group}' is not selected by default: append it with +{group}=<option>. Valid choices: {_choices(options)}.",
        )
    if m:
        key = m.group(1)
        return unknown_key_error(key, next((o for o in overrides if key in o), key))
    m = re.search(r"An item is already at '([^']+)'", msg)
    if m:
        key = m.group(1)
        return ConfigInputError(key, f"'{key}' already exists: override it without the '+', e.g. {key}=<value>.")
    m = re.search(r"Multiple values for ([\w/]+)\.", msg) or re.search(r"([\w/]+) appears more than once in", msg)
    if m:
        group = m.group(1)
        return ConfigInputError(
            group,
            f"config group '{group}' is chosen more than once: choose it once, as {_choose(group)}. "
            f"Valid choices: {_choices(group_options(group))}.",
        )
    m = re.search(r"Error merging override (\S+)", msg)
    cause = e.__cause__
    if m and isinstance(cause, OmegaConfBaseException):
        key = str(getattr(cause, "full_key", "") or m.group(1).split("=")[0])
        first = str(cause).splitlines()[0]
        return ConfigInputError(key, f"bad value for '{key}' in '{m.group(1)}': {first}.")
    return ConfigInputError("", msg.splitlines()[0])


def explain(e: Exception, overrides: Sequence[str]) -> ConfigInputError:
    """Map a composition exception to a :class:`ConfigInputError` (others are re-raised by the caller)."""
    if isinstance(e, ConfigInputError):
        return e
    if isinstance(e, MissingConfigException):
        return _missing_group(e, overrides)
    if isinstance(e, ConfigCompositionException):
        return _composition(e, overrides)
    if isinstance(e, OverrideParseException):
        first = str(e).splitlines()[0]
        return ConfigInputError("", f"{first}. Overrides look like key=value, +group=option or ~key.")
    if isinstance(e, OmegaConfBaseException):
        key = str(getattr(e, "full_key", "") or "")
        return ConfigInputError(key, f"config error at '{key}': {str(e).splitlines()[0]}.")
    if isinstance(e, ValueError) and (null := _null_group(overrides)) is not None:
        return null  # Hydra's "Config group override must be a string or a list. Got NoneType"
    raise e
