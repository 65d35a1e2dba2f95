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
