# SPDX-License-Identifier: Apache-2.0
"""Per-term verdicts: which extension terms the held-out split of a calibration dataset supports; bad input exits 2.

The fit with every candidate term is repeated with each term dropped and with each term alone (the fits of
:func:`gmloco.eval.calibration.fit.fit_extensions`, on the fit split). A term is kept when dropping it raises the
held-out RMS force error by at least ``min_change`` (relative) and ``min_change_n`` (absolute); otherwise, or when
its fitted value sits at a bound of :data:`~gmloco.eval.calibration.fit.FIT_BOUNDS` other than its off value, it is
rejected, with the reason.

python -m gmloco.eval.calibration.verdicts --dataset results/sand_calibration/dataset/dry_sand.npz
        --out results/sand_calibration/verdicts_dry_sand.json
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Literal

from gmloco.contact import RftExtensionsCfg
from gmloco.deploy.atomic_io import atomic_write_json
from gmloco.eval.calibration.dataset import CalibrationDataset, ContractError, file_sha256, load_dataset
from gmloco.eval.calibration.fit import FIT_BOUNDS, FIT_INVERTED, SandFitCfg, SandFitResult, fit_extensions

__all__ = ["TERMS", "TermVerdictCfg", "term_verdicts"]

TERMS: dict[str, tuple[str, ...]] = {
    "depth_law": ("depth_exponent", "depth_ref", "depth_saturation"),
    "lateral_scale": ("lateral_scale",),
    "plastic_unloading": (),
    "overburden": ("overburden",),
    "added_mass": ("added_mass",),
}
"""Candidate terms ((a)-(e) of ``RftExtensionsCfg``) and their fitted values; plastic unloading is on or off."""


@dataclass(frozen=True)
class TermVerdictCfg:
    """Which terms to judge and the thresholds of a verdict."""

    terms: tuple[str, ...] = tuple(TERMS)
    """Candidate terms (keys of :data:`TERMS`)."""
    min_change: float = 0.02
    """Smallest relative rise of the held-out force error when a term is dropped for it to be kept [-]."""
    min_change_n: float = 0.1
    """Smallest absolute rise of the held-out force error [N] that counts (0.1 N: 0.03 % of the G1 weight)."""
    bound_tol: float = 1.0e-3
    """Share of a value's range within which a fitted value counts as at its bound [-]."""
    fit: SandFitCfg = field(default_factory=SandFitCfg)
    """Fit settings; ``params`` and ``plastic_unloading`` are set per variant from its terms."""


PlasticMode = Literal["off", "on", "both"]


def _variant(ds: CalibrationDataset, cfg: TermVerdictCfg, terms: frozenset[str], plastic: PlasticMode) -> SandFitResult:
    """Fit the values of ``terms`` (the others off) with plastic unloading off, on, or the better on the fit split."""
    params = tuple(p for t in cfg.terms if t in terms for p in TERMS[t])
    return fit_extensions(ds, replace(cfg.fit, params=params, plastic_unloading=plastic))


def _fitted_value(ext: RftExtensionsCfg, param: str) -> float:
    """Return a fitted value in the coordinates of FIT_BOUNDS (the :data:`FIT_INVERTED` lengths as 1 / L [1/m])."""
    value = float(getattr(ext, param))
    if param in FIT_INVERTED:
        return 1.0 / value if value > 0.0 else 0.0
    return value


def _at_bound(ext: RftExtensionsCfg, term: str, tol: float) -> list[str]:
    """Return ``"param = value (bounds lo..hi)"`` for each value of ``term`` at a bound that is not its off value."""
    hits = []
    for p in TERMS[term]:
        lo, hi, start = FIT_BOUNDS[p]
        off = 0.0 if p in FIT_INVERTED else start  # an inverted length is off at 0 whatever its start
        v = _fitted_value(ext, p)
        if any(abs(v - b) <= tol * (hi - lo) and b != off for b in (lo, hi)):
            hits.append(f"{p} = {v:.4g} (bounds {lo:g}..{hi:g})")
    return hits


def _rel(before: float, after: float) -> float:
    """Return the relative reduction (before - after) / before [-] (0 when before is 0)."""
    return (before - after) / before if before > 0.0 else 0.0


def _verdict(row: dict[str, Any], cfg: TermVerdictCfg) -> tuple[str, str]:
    """Return (``kept`` / ``rejected``, reason) of one term from its with / without / alone errors."""
    with_, without = row["heldout_with_N"], row["heldout_without_N"]
    held = f"held-out {without:.3g} N without, {with_:.3g} N with"
    if row["heldout_change"] < cfg.min_change or without - with_ < cfg.min_change_n:
        fit_gain = row["fit_change"] >= cfg.min_change and row["fit_without_N"] - row["fit_with_N"] >= cfg.min_change_n
        if fit_gain:
            fit = f"fit {row['fit_without_N']:.3g} N without, {row['fit_with_N']:.3g} N with"
            reason = f"improves fit split only ({fit}; {held})"
        elif with_ - without >= cfg.min_change_n:
            reason = f"held-out force error is higher with it ({held})"
        else:
            floor = f"< {100 * cfg.min_change:g} % or < {cfg.min_change_n:g} N"
            reason = f"held-out force error changes {floor} when it is dropped ({held})"
        if row["alone_change"] >= cfg.min_change:
            reason += f"; alone it lowers the published model's held-out error by {100 * row['alone_change']:.1f} %"
        return "rejected", reason
    if row["at_bound"]:
        return "rejected", "fitted value at its bound: " + ", ".join(row["at_bound"])
    return "kept", f"dropping it raises the held-out force error from {with_:.3g} N to {without:.3g} N"


def term_verdicts(ds: CalibrationDataset, cfg: TermVerdictCfg) -> dict[str, Any]:
    """Fit all terms, each dropped and each alone; return the per-term errors and verdicts (JSON-ready).

    Plastic unloading is fitted off and on and the better fit-split one kept (as the fitter does) in every variant
    but its own: with it means on, without it off. Errors are RMS force errors [N] per split; ``heldout_change`` is
    (without - with) / without [-].
    """
    unknown = set(cfg.terms) - set(TERMS)
    if unknown or not cfg.terms:
        raise ValueError(f"unknown or no terms {sorted(unknown)}: choose from {list(TERMS)}")
    judge_plastic = "plastic_unloading" in cfg.terms
    values = frozenset(t for t in cfg.terms if t != "plastic_unloading")
    free: PlasticMode = "both" if judge_plastic else "off"
    cache: dict[tuple[frozenset[str], PlasticMode], SandFitResult] = {}

    def fit(terms: frozenset[str], plastic: PlasticMode) -> SandFitResult:
        """Return the (cached) fit of one variant."""
        if (terms, plastic) not in cache:
            cache[terms, plastic] = _variant(ds, cfg, terms, plastic)
        return cache[terms, plastic]

    full = fit(values, free)
    published = dict(full.error_before_aligned or full.error_before)  # at its own datum when the datum is fitted

    def errors(terms: frozenset[str], plastic: PlasticMode) -> tuple[dict[str, float], RftExtensionsCfg]:
        """Return the RMS force error [N] per split and the terms of a variant (the published model if none)."""
        if not terms and plastic == "off":
            return published, RftExtensionsCfg()
        return fit(terms, plastic).error_after, fit(terms, plastic).extensions

    rows = {}
    for term in cfg.terms:
        if term == "plastic_unloading":
            (with_, ext), (without, _) = errors(values, "on"), errors(values, "off")
            alone = errors(frozenset(), "on")[0]
        else:
            (with_, ext), (without, _) = errors(values, free), errors(values - {term}, free)
            alone = errors(frozenset({term}), "off")[0]
        row = {"values": {p: getattr(ext, p) for p in TERMS[term]},
               "heldout_with_N": with_["heldout"], "heldout_without_N": without["heldout"],
               "fit_with_N": with_["fit"], "fit_without_N": without["fit"], "heldout_alone_N": alone["heldout"],
               "heldout_change": _rel(without["heldout"], with_["heldout"]),
               "fit_change": _rel(without["fit"], with_["fit"]),
               "alone_change": _rel(published["heldout"], alone["heldout"]),
               "at_bound": _at_bound(ext, term, cfg.bound_tol)}  # fmt: skip
        row["verdict"], row["reason"] = _verdict(row, cfg)
        rows[term] = row
    kept = [t for t in cfg.terms if rows[t]["verdict"] == "kept"]
    params = [p for t in kept for p in TERMS[t]]
    return {
        "material": ds.material,
        "source": ds.source,
        "published": published,
        "all_terms": {"force_error": full.error_after, "extensions": asdict(full.extensions)},
        "terms": rows,
        "kept": kept,
        "fit_cli_args": (["--params", *params] if params else [])
        + ["--plastic-unloading", "on" if "plastic_unloading" in kept else "off"],
        "min_change": cfg.min_change,
        "min_change_N": cfg.min_change_n,
        "fit": asdict(cfg.fit),
    }


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    """Parse the command line."""
    p = argparse.ArgumentParser(
        prog="python -m gmloco.eval.calibration.verdicts", description=(__doc__ or "").splitlines()[0]
    )
    p.add_argument("--dataset", required=True, help="<material>.npz from python -m gmloco.eval.calibration")
    p.add_argument("--out", required=True, help="verdicts JSON, e.g. results/sand_calibration/verdicts_dry_sand.json")
    p.add_argument("--terms", nargs="+", default=list(TERMS), choices=list(TERMS))
    p.add_argument("--min-change", type=float, default=0.02, help="held-out error rise that keeps a term [-]")
    p.add_argument("--min-change-n", type=float, default=0.1, help="held-out error rise [N] that counts")
    p.add_argument("--robot", default="g1")
    p.add_argument("--rate-hz", type=float, default=None, help="expected recording rate [Hz]")
    p.add_argument("--at-rest", choices=["none", "unloading"], default="unloading")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Judge the terms and write the verdicts JSON; return the exit code (2: bad input)."""
    a = parse_args(argv)
    fit = SandFitCfg(robot=a.robot, rate_hz=a.rate_hz, at_rest=a.at_rest)
    try:
        if not 0.0 <= a.min_change < 1.0:
            raise ValueError(f"--min-change {a.min_change} must lie in [0, 1)")
        ds = load_dataset(a.dataset)
        body = term_verdicts(ds, TermVerdictCfg(tuple(a.terms), a.min_change, a.min_change_n, fit=fit))
    except (ContractError, FileNotFoundError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    body.update(dataset=a.dataset, dataset_sha256=file_sha256(a.dataset))
    atomic_write_json(a.out, body)
    for term, row in body["terms"].items():
        print(f"{term:18s} {row['verdict']:8s} {row['reason']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
