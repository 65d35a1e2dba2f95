"""The memory and CPU time of every batch fk / ik / ik_all / jacobian (issue 25): bytes per target against the
answer's.

For each function it makes ``--n`` valid inputs (ik targets from fk of joints drawn in range), calls it once on a
small batch (compiled or loaded from numba's cache), then measures one call on the ``--n`` inputs: its peak memory
(``tracemalloc``, numpy's and numba's arrays both traced, answer included, inputs not) and its CPU time
(``time.process_time``, every thread counted, best of ``--repeats``). It prints per target: the peak bytes, the
answer's bytes (values and mask) and the extra bytes (peak - answer), which chunking keeps below the answer's.

    python scripts/batch_memory.py --n 1000000
    python scripts/batch_memory.py --n 1000000 tripod.ik go2.ik
"""

from __future__ import annotations

import argparse
import inspect
import sys
import time
import tracemalloc
from typing import Any, Callable

import numpy as np


def _joint_box(n: int, lo: Any, hi: Any, rng: np.random.Generator) -> np.ndarray:
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return lo + (hi - lo) * rng.random((n, lo.size))


def cases(n: int, rng: np.random.Generator) -> dict[str, Callable[[int], Callable[[], Any]]]:
    """``{name: make}``: ``make(k)`` returns the call on k inputs (inputs built once, outside the measurement)."""
    from legkin import hybrid_leg, legs, quadruped, tripod, wheel_leg

    def mech(fun: Callable[..., Any], inputs: np.ndarray, **kw: Any) -> Callable[[int], Callable[[], Any]]:
        # Leg.fk and Leg.jacobian have no mask
        keywords = dict(kw)
        if "return_mask" in inspect.signature(fun).parameters:
            keywords["return_mask"] = True
        return lambda k: (lambda x=inputs[:k]: fun(x, **keywords))

    out: dict[str, Callable[[int], Callable[[], Any]]] = {}

    def four(prefix: str, m: Any, q: np.ndarray, x: np.ndarray, **kw: Any) -> None:
        """fk and jacobian on the joints ``q``, ik and ik_all on the targets ``x``, of ``m`` (a module or a leg)."""
        for fun, inputs in (("fk", q), ("ik", x), ("ik_all", x), ("jacobian", q)):
            out[f"{prefix}.{fun}"] = mech(getattr(m, fun), inputs, **kw)

    t_q = tripod.ik(np.stack([rng.uniform(-0.5, 0.5, n), rng.uniform(-1.0, 1.0, n)], axis=-1))
    t_x = tripod.fk(t_q)
    four("tripod", tripod, t_q, t_x)
    out["tripod.jacobian"] = mech(tripod.jacobian, t_x)  # the tripod's A_u takes the orientation
    w_q = _joint_box(n, [0.9, -0.3, -0.3], [1.5, 0.3, 0.3], rng)
    four("wheel_leg", wheel_leg, w_q, wheel_leg.fk(w_q, "FL"), leg="FL")
    h_q = _joint_box(n, [-0.2, -0.2, 2.8], [0.2, 0.2, 3.2], rng)
    four("hybrid_leg", hybrid_leg, h_q, hybrid_leg.fk(h_q))
    q_q = _joint_box(n, [-0.3, 0.5, 1.0], [0.3, 1.0, 1.5], rng)
    four("quadruped", quadruped, q_q, quadruped.fk(q_q, "LF"), leg="LF")
    for robot in ("go2", "talos"):
        leg = next(iter(legs.from_model(legs.load_erd(robot)[0]).values()))
        lo, hi = np.asarray(leg.lower, float), np.asarray(leg.upper, float)
        mid, half = (lo + hi) / 2, (hi - lo) / 2
        q = _joint_box(n, mid - 0.3 * half, mid + 0.3 * half, rng)
        four(robot, leg, q, leg.fk(q))
    return out


def measure(make: Callable[[int], Callable[[], Any]], n: int, repeats: int) -> tuple[float, float, float]:
    """(peak bytes per target, answer bytes per target, best CPU seconds per target) of one call on ``n`` inputs."""
    make(16)()  # compiled or loaded
    call = make(n)
    tracemalloc.start()
    try:
        answer = call()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    size = sum(np.asarray(a).nbytes for a in (answer if isinstance(answer, tuple) else (answer,)))
    del answer
    best = float("inf")
    for _ in range(repeats):
        t0 = time.process_time()
        call()
        best = min(best, time.process_time() - t0)
    return peak / n, size / n, best / n


def main(argv: list[str] | None = None) -> int:
    """Print one line per batch function."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("names", nargs="*", help="functions (default: all), e.g. tripod.ik go2.fk")
    p.add_argument("--n", type=int, default=1_000_000)
    p.add_argument("--repeats", type=int, default=3)
    args = p.parse_args(argv)
    table = cases(args.n, np.random.default_rng(0))
    print(f"{'function':<22} {'targets':>8} {'peak B/t':>9} {'answer B/t':>10} {'extra B/t':>9}  {'CPU/target':>10}")
    worse = 0
    for name in args.names or table:
        peak, size, cpu = measure(table[name], args.n, args.repeats)
        worse += peak - size > size
        print(f"{name:<22} {args.n:>8} {peak:>9.0f} {size:>10.0f} {peak - size:>9.0f}  {cpu * 1e9:>8.0f} ns"
              f"{'  extra > answer' if peak - size > size else ''}", flush=True)
    return 1 if worse else 0


if __name__ == "__main__":
    sys.exit(main())
