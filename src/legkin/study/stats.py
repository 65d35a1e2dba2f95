"""Per-block statistics of a study, their exact merge, and the metrics with their confidence intervals.

Every block's statistics are integer counts (and maxima), so merging blocks is exact and independent of the
order: the result is the same bit for bit whatever the number of chunks or workers. The formulas are in
docs/study.md.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from ._kernels import COND_CAP, STATS
from .targets import Solved

__all__ = ["HIST_BINS", "HIST_STEP", "PERCENTILES", "Z95", "block_stats", "merge", "metrics_row", "wilson"]

#: log10(kappa) histogram: bins of HIST_STEP decades on [0, log10 COND_CAP), then one bin for kappa >= COND_CAP.
HIST_STEP = 0.005
HIST_BINS = int(round(math.log10(COND_CAP) / HIST_STEP))
#: The percentiles of kappa reported (``cond_p50``...).
PERCENTILES = (50, 90, 99)
#: The normal quantile of the two-sided 95 % intervals.
Z95 = 1.959963984540054


def block_stats(solved: Solved, n: int, threshold: float, extras: tuple[str, ...]) -> dict[str, Any]:
    """The statistics of one solved block.

    Args:
        solved: the block's :class:`~legkin.study.targets.Solved`.
        n: its sample count.
        threshold: the singularity threshold eps on 1/kappa (dimensionless).
        extras: the target's own metrics to reduce (their maxima).

    Returns:
        ``{"n", "reached", "singular", "conditioned", "hist", <extra>_max, <count>_k, <count>_n}``: counts (int),
        the (HIST_BINS + 1,) int64 histogram of log10 kappa over the reached samples, the maxima of the extras
        (float, -inf if none) and the target's own proportions (successes, trials).
    """
    m, k = solved.shape
    bins = np.empty(n, dtype=np.int64)
    singular = STATS(np.ascontiguousarray(solved.jac), m, k, np.ascontiguousarray(solved.ok), threshold, HIST_STEP,
                     HIST_BINS, bins)
    hist = np.bincount(bins, minlength=HIST_BINS + 2)[:HIST_BINS + 1]
    out: dict[str, Any] = {
        "n": int(n),
        "reached": int(np.count_nonzero(solved.ok)),
        "singular": int(singular),
        "conditioned": int(hist.sum()),
        "hist": hist.astype(np.int64),
    }
    for name, (hits, total) in solved.counts.items():
        out[f"{name}_k"], out[f"{name}_n"] = hits, total
    for name in extras:
        if name not in solved.extras:
            continue
        v = solved.extras[name][solved.ok]
        v = v[np.isfinite(v)]
        out[f"{name}_max"] = float(v.max()) if v.size else -math.inf
    return out


def merge(parts: list[dict[str, Any]]) -> dict[str, Any]:
    """Sum the counts and histograms, take the maxima: exact, and independent of the order of ``parts``."""
    out = dict(parts[0])
    for p in parts[1:]:
        for key, value in p.items():
            out[key] = max(out[key], value) if key.endswith("_max") else out[key] + value
    return out


def wilson(k: int, n: int, z: float = Z95) -> tuple[float, float, float]:
    """Wilson score interval of a binomial proportion.

    Args:
        k: successes. n: trials. z: normal quantile (1.96: 95 %).

    Returns:
        (k / n, low, high), NaN for n = 0.
    """
    if n == 0:
        return math.nan, math.nan, math.nan
    p = k / n
    d = 1.0 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return p, max(c - h, 0.0), min(c + h, 1.0)


def _bin_value(b: int) -> float:
    """kappa at the geometric middle of histogram bin b (COND_CAP for the top bin)."""
    return COND_CAP if b >= HIST_BINS else 10.0 ** ((b + 0.5) * HIST_STEP)


def _percentile(cum: np.ndarray, rank: float) -> float:
    """kappa of the sample of (1-based, real) rank ``rank`` in the histogram's cumulative counts ``cum``."""
    r = min(max(math.ceil(rank), 1), int(cum[-1]))
    return _bin_value(int(np.searchsorted(cum, r)))


def _percentiles(hist: np.ndarray) -> dict[str, float]:
    """cond_pXX and its 95 % order-statistic interval: the ranks N p -+ z sqrt(N p (1 - p))."""
    cum = np.cumsum(hist)
    n = int(cum[-1])
    out: dict[str, float] = {}
    for pc in PERCENTILES:
        p = pc / 100
        if n == 0:
            out[f"cond_p{pc}"] = out[f"cond_p{pc}_lo"] = out[f"cond_p{pc}_hi"] = math.nan
            continue
        half = Z95 * math.sqrt(n * p * (1 - p))
        out[f"cond_p{pc}"] = _percentile(cum, n * p)
        out[f"cond_p{pc}_lo"] = _percentile(cum, n * p - half)
        out[f"cond_p{pc}_hi"] = _percentile(cum, n * p + half + 1)
    return out


def metrics_row(stats: Mapping[str, Any], measure: float, metrics: tuple[str, ...]) -> dict[str, float]:
    """The metrics of one parameter point from its merged statistics (docs/study.md gives the formulas).

    Args:
        stats: the merged :func:`block_stats` of the point.
        measure: the measure of the declared target set (m^3, m^2 or sr).
        metrics: the metric groups to report: "reach", "conditioning", "singularity", and the target's extras.

    Returns:
        Column name -> value.
    """
    row: dict[str, float] = {"samples": stats["n"], "reached": stats["reached"]}
    if "reach" in metrics:
        p, lo, hi = wilson(stats["reached"], stats["n"])
        row.update(reach_fraction=p, reach_fraction_lo=lo, reach_fraction_hi=hi,
                   volume=measure * p, volume_lo=measure * lo, volume_hi=measure * hi)
    if "conditioning" in metrics:
        row.update(_percentiles(stats["hist"]))
    if "singularity" in metrics:
        p, lo, hi = wilson(stats["singular"], stats["conditioned"])
        row.update(singular_fraction=p, singular_fraction_lo=lo, singular_fraction_hi=hi)
    for key, value in stats.items():
        if key.endswith("_max") and key[:-4] in metrics:
            row[key] = value if math.isfinite(value) else math.nan
        elif key.endswith("_k"):
            p, lo, hi = wilson(value, stats[key[:-2] + "_n"])
            row.update({key[:-2]: p, key[:-2] + "_lo": lo, key[:-2] + "_hi": hi})
    return row
