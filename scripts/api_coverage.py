"""How much of legkin's public API is typed and documented: every public function and method of the modules users
import (``legkin``, each mechanism's ``kinematics``, ``legkin.legs``, ``legkin.robot``, ``legkin.errors``), with
its annotations (every parameter and the return) and its Google-style docstring sections (Args, Returns) and units.

    python scripts/api_coverage.py            # the summary
    python scripts/api_coverage.py --list     # and every function that misses something
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import re
from typing import Any, Callable, Iterator

#: A unit named in a docstring: SI symbols as legkin writes them (m, rad, s, N, ...), or "unitless"/"dimensionless".
UNITS = re.compile(r"\b(m|rad|s|us|ns|ms|N|Nm|m/s|rad/s|m\^2|m\^3|deg|metres|radians|seconds|unitless|dimensionless)\b")


def public_modules() -> list[str]:
    """The modules whose ``__all__`` is legkin's public API."""
    from legkin._registry import list_models

    names = ["legkin", "legkin.errors", "legkin.robot", "legkin.legs"]
    names += [f"legkin.{m}.kinematics" for m in list_models("legkin")]
    return names


def public_functions() -> Iterator[tuple[str, Callable[..., Any]]]:
    """``(qualified name, function)`` of every public function and public method of a public class."""
    seen: set[int] = set()
    for modname in public_modules():
        module = importlib.import_module(modname)
        for name in getattr(module, "__all__", []):
            obj = getattr(module, name, None)
            if inspect.isclass(obj):
                members = [(f"{name}.{m}", f) for m, f in vars(obj).items()
                           if not m.startswith("_") and inspect.isfunction(f)]
            elif callable(obj) and not inspect.ismodule(obj):
                members = [(name, obj)]
            else:
                members = []
            for qual, func in members:
                func = inspect.unwrap(getattr(func, "py_func", func))
                if id(func) not in seen and inspect.isfunction(func):
                    seen.add(id(func))
                    yield f"{modname}.{qual}", func


def audit(func: Callable[..., Any]) -> dict[str, bool]:
    """What ``func`` has: full annotations, Args and Returns sections (where it has parameters / a result), a unit."""
    sig = inspect.signature(func)
    params = [p for n, p in sig.parameters.items() if n not in ("self", "cls")]
    typed = all(p.annotation is not inspect.Parameter.empty for p in params)
    typed &= sig.return_annotation is not inspect.Signature.empty or func.__name__ == "__init__"
    doc = inspect.getdoc(func) or ""
    returns_none = sig.return_annotation in (None, "None")
    return {
        "typed": typed,
        "args": not params or "Args:" in doc,
        "returns": returns_none or "Returns:" in doc or "Yields:" in doc,
        "unit": bool(UNITS.search(doc)),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", action="store_true", help="list every function that misses something")
    args = parser.parse_args()
    rows = [(name, audit(f)) for name, f in public_functions()]
    n = len(rows)
    for key in ("typed", "args", "returns", "unit"):
        k = sum(r[key] for _, r in rows)
        print(f"{key:8s} {k:4d} / {n} = {100 * k / n:5.1f} %")
    if args.list:
        for name, r in rows:
            missing = [k for k, v in r.items() if not v]
            if missing:
                print(f"  {name}: no {', '.join(missing)}")


if __name__ == "__main__":
    main()
