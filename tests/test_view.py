"""The meshcat pages render in a real browser (headless Chromium) and show the mechanism."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from conftest import shot

import legkin
from legkin.viewer import chromium_path, write_html

CHROMIUM = chromium_path()

# Only the browser tests need Chromium; the server life-cycle tests below run everywhere.
needs_chromium = pytest.mark.skipif(
    CHROMIUM is None and not os.environ.get("CI"),
    reason="headless Chromium not installed (apt-get install chromium); required on CI",
)


def assert_shows_something(img: np.ndarray, empty: np.ndarray) -> None:
    assert img.std() > 5, "blank page"
    changed = np.abs(img - empty).max(axis=-1) > 30
    assert changed.mean() > 0.01, f"only {changed.mean():.2%} of the pixels differ from the empty scene"


@needs_chromium
@pytest.mark.parametrize("name", [*legkin.list_models("legkin"), "go2"])
def test_model_page_renders(name, tmp_path, empty_scene):
    robot = legkin.load(name)
    page = write_html(robot, robot.q0, tmp_path / f"{name}.html")
    assert page.stat().st_size > 10_000
    img = shot(page, tmp_path / f"{name}.png")
    assert_shows_something(img, empty_scene)


@needs_chromium
def test_animation_page_renders(tmp_path, empty_scene):
    from legkin.__main__ import main

    page = tmp_path / "anim.html"
    assert main(["view", "quadruped", "--animate", "foot_circles", "--html", str(page)]) == 0
    img = shot(page, tmp_path / "anim.png")
    assert_shows_something(img, empty_scene)


def _children(pid: int) -> set[int]:
    """Direct child processes of ``pid`` (Linux /proc)."""
    out = set()
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            out |= {int(c) for c in (task / "children").read_text().split()}
        except OSError:
            pass
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_html_export_leaves_no_server(tmp_path):
    import os

    from legkin.__main__ import main

    before = _children(os.getpid())
    assert main(["view", "quadruped", "--pose", "crouching", "--html", str(tmp_path / "p.html")]) == 0
    assert {p for p in _children(os.getpid()) - before if _alive(p)} == set()


@pytest.mark.parametrize("model, sig", [("quadruped", "SIGINT"), ("tripod", "SIGTERM")])
def test_live_view_serves_until_stopped(model, sig):
    """``legkin view`` serves until Ctrl-C (SIGINT) or SIGTERM, and stops its meshcat server either way."""
    import signal
    import subprocess
    import sys
    import time

    proc = subprocess.Popen(
        [sys.executable, "-m", "legkin", "view", model], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    servers: set[int] = set()
    try:
        line = proc.stdout.readline()
        assert "http://127.0.0.1:" in line
        servers = _children(proc.pid)
        assert servers, "the viewer runs a meshcat server process"
        assert all("meshcat" in Path(f"/proc/{p}/cmdline").read_text() for p in servers)
        proc.send_signal(getattr(signal, sig))
        assert proc.wait(timeout=30) == 128 + getattr(signal, sig)  # 130 / 143: the shell's code of the signal
        assert "Traceback" not in proc.stderr.read()
    finally:
        if proc.poll() is None:
            proc.kill()
        deadline = time.time() + 10
        while any(_alive(p) for p in servers) and time.time() < deadline:
            time.sleep(0.2)
        leaked = {p for p in servers if _alive(p)}
        for p in leaked:  # do not leave a server behind even when the test fails
            os.kill(p, signal.SIGKILL)
    assert not leaked, f"meshcat server(s) {leaked} still running after {sig}"


@needs_chromium
def test_ground_plane_is_drawn_under_a_walking_robot(tmp_path):
    from legkin.viewer import ground_height

    robot = legkin.load("quadruped", floating=True)
    assert ground_height(robot) == 0.0 and ground_height(legkin.load("tripod")) is None
    with_ground = shot(write_html(robot, robot.q0, tmp_path / "g.html"), tmp_path / "g.png")
    without = shot(write_html(robot, robot.q0, tmp_path / "n.html", ground=False), tmp_path / "n.png")
    assert (np.abs(with_ground - without).max(axis=-1) > 30).mean() > 0.05, "no ground plane drawn"
