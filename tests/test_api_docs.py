"""Every public function and method of legkin's public API (``scripts/api_coverage.py``: ``legkin``, the errors,
``Robot``, ``legkin.legs`` and each mechanism's ``kinematics``) is fully annotated and has Google-style Args and
Returns sections (CONTRIBUTING.md); the API reference of the documentation site is generated from them."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
import api_coverage  # noqa: E402

FUNCTIONS = list(api_coverage.public_functions())


def test_the_public_api_is_found() -> None:
    names = {name for name, _ in FUNCTIONS}
    assert "legkin.load" in names and "legkin.legs.Leg.ik" in names and "legkin.tripod.kinematics.ik" in names


@pytest.mark.parametrize(("name", "func"), FUNCTIONS, ids=[name for name, _ in FUNCTIONS])
def test_public_function_is_typed_and_documented(name: str, func: object) -> None:
    audit = api_coverage.audit(func)  # type: ignore[arg-type]
    missing = [key for key in ("typed", "args", "returns") if not audit[key]]
    assert not missing, f"{name}: no {', '.join(missing)} (annotations; Args:/Returns: sections)"


def test_same_signature_keeps_the_function_and_refuses_other_arguments() -> None:
    """``same_signature`` (the @overload stack written once) returns the function itself, and refuses at import
    a function whose parameters differ from its template's in name, default or annotation."""
    from legkin._batch import same_signature
    from legkin.hybrid_leg import foot

    def template(q: float, *, return_mask: bool = False) -> float:
        return q

    def same(q: float, *, return_mask: bool = False) -> float:
        return 2 * q

    assert same_signature(template)(same) is same
    assert foot.jacobian.__name__ == "jacobian"  # decorated, not wrapped
    for other in ("def f(q: float, *, return_mask: bool = True) -> float: ...",
                  "def f(x: float, *, return_mask: bool = False) -> float: ...",
                  "def f(q: int, *, return_mask: bool = False) -> float: ...",
                  "def f(q: float, return_mask: bool = False) -> float: ..."):
        scope: dict[str, object] = {}
        exec("from __future__ import annotations\n" + other, scope)
        with pytest.raises(TypeError, match=r"f must take the arguments of .*template"):
            same_signature(template)(scope["f"])  # type: ignore[arg-type]
