"""Shared fixtures."""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

import legkin

# Property tests: reproducible on CI (derandomized: the same examples on every run, no example database,
# failures print the blob that replays them with @reproduce_failure); random exploration locally.
# Pick one with HYPOTHESIS_PROFILE=ci|dev; CI=true selects "ci". Every example that ever failed is kept
# as an explicit @example beside its test.
settings.register_profile(
    "ci", derandomize=True, database=None, print_blob=True, deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("dev", print_blob=True, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") else "dev"))


@pytest.fixture(scope="session")
def quadruped():
    return legkin.load("quadruped")


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


def shot(page, png, budget_ms: int = 15000) -> np.ndarray:
    """Render ``page`` in headless Chromium and return the screenshot as an RGB float array."""
    from PIL import Image

    from legkin.viewer import chromium_path, screenshot

    assert chromium_path() is not None, "CI must install Debian's chromium (see .ci/run)"
    screenshot(page, png, budget_ms=budget_ms)
    return np.asarray(Image.open(png).convert("RGB"), dtype=float)


@pytest.fixture(scope="session")
def empty_scene(tmp_path_factory) -> np.ndarray:
    """Screenshot of meshcat's empty scene, to tell a drawn mechanism from nothing."""
    import meshcat

    tmp = tmp_path_factory.mktemp("empty")
    vis = meshcat.Visualizer()
    try:
        html = vis.static_html()
    finally:
        vis.window.server_proc.terminate()
        vis.window.server_proc.wait(timeout=10)
    (tmp / "empty.html").write_text(html)
    return shot(tmp / "empty.html", tmp / "empty.png")
