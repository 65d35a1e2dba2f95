"""Shared fixtures."""

from __future__ import annotations

import numpy as np
import pytest

import legkin


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
