"""legkin 0.1's call forms of :func:`~legkin.wheel_leg.ik`, kept for one release (each warns)."""

from __future__ import annotations

import dataclasses
import warnings
from typing import Any

import numpy as np

#: legkin 0.1's method names -> today's.
OLD_METHODS = {"seed": "gauss_newton_fd"}
_OLD_KEYWORDS = ("q0", "tol", "max_iter", "delta")


def method_name(method: object, stacklevel: int = 3) -> object:
    """``method`` with legkin 0.1's ``"seed"`` renamed (DeprecationWarning); checked by the caller."""
    if type(method) is str and method in OLD_METHODS:
        new = OLD_METHODS[method]
        warnings.warn(f"method={method!r} is deprecated; use method={new!r} (the seed's Gauss-Newton with a "
                      "forward-difference Jacobian)", DeprecationWarning, stacklevel=stacklevel)
        return new
    return method


def _is_leg(x: object) -> bool:
    return isinstance(x, str) or (isinstance(x, (int, np.integer)) and not isinstance(x, (bool, np.bool_)))


def legacy_ik_call(leg: Any, args: tuple, deprecated: dict[str, Any], *, alpha: Any, w: Any, q_near: Any,
                   q_start: Any, method: Any, options: Any) -> tuple[Any, Any, Any, Any, Any, Any]:
    """Map a call of ``ik`` that is not of today's form onto today's arguments.

    legkin 0.1: ``ik(target, alpha=0.0, w=0.0, leg="FL", q0=None, *, tol=1e-12, max_iter=None, delta=1e-6,
    ...)``. Returns ``(leg, alpha, w, q_near, q_start, options)``.

    Raises:
        TypeError: an unknown keyword, or too many positional arguments.
    """
    from .inverse import IKOptions  # (import cycle)

    unknown = [k for k in deprecated if k not in _OLD_KEYWORDS and k != "leg"]
    if unknown:
        raise TypeError(f"ik() got an unexpected keyword argument {unknown[0]!r}")
    old: list[str] = []
    if isinstance(leg, str) and args:
        raise TypeError(f"ik() takes 2 positional arguments (target, leg), {2 + len(args)} given; pass alpha=, w= "
                        "and the rest as keywords")
    if leg is not None and not (_is_leg(leg) and not args):  # a number second: ik(target, alpha, w, leg, q0)
        if len(args) > 3:
            raise TypeError(f"ik() takes at most 5 positional arguments ({2 + len(args)} given)")
        alpha, rest = leg, list(args) + [None] * (3 - len(args))
        w = rest[0] if len(args) >= 1 else w
        leg = rest[1] if len(args) >= 2 else deprecated.get("leg")
        if len(args) >= 3:
            deprecated = {**deprecated, "q0": rest[2]}
        old.append("ik(target, alpha, w, leg, ...) with positional alpha/w")
    elif leg is None:
        leg = deprecated.get("leg")
    if leg is None:
        leg = "FL"
        old.append("ik() without leg (it was 'FL' by default)")
    if "q0" in deprecated and deprecated["q0"] is not None:
        q0 = deprecated["q0"]
        iterative = isinstance(method, str) and method != "radial"
        if iterative:
            q_start = q0
        else:
            q_near = q0
        old.append(f"q0= (now {'q_start' if iterative else 'q_near'}=)")
    tuning = {k: deprecated[k] for k in ("tol", "max_iter", "delta") if k in deprecated}
    if tuning:
        base = options if isinstance(options, IKOptions) else IKOptions()
        options = dataclasses.replace(base, **tuning)
        old.append(f"{', '.join(k + '=' for k in tuning)} (now options=IKOptions(...))")
    if old:
        warnings.warn("legkin 0.1 call of wheel_leg.ik is deprecated: " + "; ".join(old)
                      + "; use ik(target, leg, alpha=..., w=..., q_near=..., options=IKOptions(...))",
                      DeprecationWarning, stacklevel=3)
    return leg, alpha, w, q_near, q_start, options
