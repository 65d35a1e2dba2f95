"""Meshcat views of legkin models through Pinocchio's ``MeshcatVisualizer`` (live or as a static page)."""

from __future__ import annotations

import contextlib
import io
import subprocess
from pathlib import Path
from typing import Any, Iterator, Sequence

import numpy as np

from ._signals import SignalInterrupt, signals_raise
from .robot import Robot

__all__ = ["open_viewer", "show", "write_html", "write_animation_html"]

#: Camera position in three.js coordinates (y up), looking at the origin.
DEFAULT_CAMERA = (1.2, 0.7, 1.2)


def _sigterm_interrupts() -> contextlib.AbstractContextManager[None]:
    """Inside the block, SIGTERM and SIGHUP (a closed terminal) raise KeyboardInterrupt (as Ctrl-C does), so that
    ``finally`` clauses run: the meshcat server, in a session of its own, would not get the terminal's SIGHUP."""
    return signals_raise(SignalInterrupt)


@contextlib.contextmanager
def open_viewer(robot: Robot, camera: Sequence[float] | None = None, ground: bool = True,
                host: str = "127.0.0.1") -> Iterator[Any]:
    """A ``pinocchio.visualize.MeshcatVisualizer`` with ``robot`` loaded; its server is always stopped.

    Args:
        robot: the model to show.
        camera: the camera position (m), looking at the origin; None fits it to the model.
        ground: a ground plane under a walking robot.
        host: the address the web page is served on: 127.0.0.1 (this machine only) unless given; ``"0.0.0.0"``
            opens it to every network interface (anyone who can reach the machine sees the scene).

    Returns:
        The visualizer, inside the ``with`` block.

    The server (meshcat's, bound to ``host``: :mod:`legkin._meshcat_server`) is a child process, and meshcat 0.3
    has no working ``close``: the context manager terminates it on exit, whatever happens inside, SIGTERM and
    SIGHUP included (they raise KeyboardInterrupt inside the block, as Ctrl-C does).
    """
    import meshcat
    from pinocchio.visualize import MeshcatVisualizer

    with _sigterm_interrupts():
        proc, zmq_url = _start_server(host)
        try:
            with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints its URL; callers decide what to show
                viewer = meshcat.Visualizer(zmq_url=zmq_url)
        except BaseException:
            _stop_process(proc)
            raise
        viewer.window.server_proc = proc
        try:
            viz = MeshcatVisualizer(robot.model, robot.collision_model, robot.visual_model)
            viz.initViewer(viewer=viewer, open=False)
            viz.loadViewerModel(rootNodeName=robot.name)
            cam = camera if camera is not None else _camera_for(robot)
            viewer["/Cameras/default/rotated/<object>"].set_property("position", list(map(float, cam)))
            if ground:
                _add_ground(viewer, robot)
            yield viz
        finally:
            _stop_server(viewer)


def _start_server(host: str) -> tuple[subprocess.Popen, str]:
    """Start meshcat's server with its web page on ``host`` (:mod:`legkin._meshcat_server`); ``(process, zmq_url)``.
    """
    import sys

    cmd = [sys.executable, "-u", "-m", "legkin._meshcat_server", "--host", host]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    line = proc.stdout.readline().decode() if proc.stdout else ""
    if not line.startswith("zmq_url="):
        err = proc.communicate(timeout=10)[1].decode().strip().splitlines()
        raise OSError(f"meshcat's server did not start on {host!r}: {err[-1] if err else 'no output'}")
    proc.stdout.readline()  # type: ignore[union-attr] # web_url=...: the viewer asks the server for it
    return proc, line.strip().split("=", 1)[1]


def _stop_server(viewer) -> None:
    """Terminate meshcat's server process (kill it if it does not stop within 10 s)."""
    _stop_process(getattr(viewer.window, "server_proc", None))


def _stop_process(proc: subprocess.Popen | None) -> None:
    """Terminate ``proc`` (kill it if it does not stop within 10 s); None: nothing."""
    if proc is None:
        return
    proc.terminate()
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(timeout=10)


#: Size (m) and thickness of the ground plane shown under a walking robot.
GROUND_SIZE = 4.0
GROUND_THICKNESS = 0.002


def ground_height(robot: Robot) -> float | None:
    """Height of the ground in the model's world frame, or None for a mechanism that does not walk.

    A floating-base robot stands on z = 0 (its SRDF poses put the base at the height where the feet touch it);
    a fixed-base model of a walking robot has its base at the origin, so the ground is the reference pose's
    base height below it (read from the SRDF's ``root_joint`` entry; None if there is none).
    """
    import xml.etree.ElementTree as ET

    if not robot.spec.floating:
        return None
    if robot.floating:
        return 0.0
    if robot.srdf_path is None:
        return None
    for state in ET.parse(robot.srdf_path).getroot().iter("group_state"):
        if state.get("name") != robot.spec.reference_pose:
            continue
        for joint in state.iter("joint"):
            if joint.get("name") == "root_joint":
                return -float(joint.get("value", "0 0 0").split()[2])
    return None


def _add_ground(viewer: Any, robot: Robot) -> None:
    """A light grey plane at :func:`ground_height` (nothing for a mechanism that does not walk)."""
    import meshcat.geometry as mg
    import meshcat.transformations as mt

    z = ground_height(robot)
    if z is None:
        return
    box = mg.Box([GROUND_SIZE, GROUND_SIZE, GROUND_THICKNESS])
    viewer["/legkin/ground"].set_object(box, mg.MeshLambertMaterial(color=0xD8D8D8, opacity=0.9))
    viewer["/legkin/ground"].set_transform(mt.translation_matrix([0.0, 0.0, z - GROUND_THICKNESS / 2]))


def _camera_for(robot: Robot) -> tuple[float, float, float]:
    """A camera distance fitted to the visual geometry at ``q0`` (the camera looks at the origin)."""
    import pinocchio as pin

    data = pin.GeometryData(robot.visual_model)
    pin.forwardKinematics(robot.model, robot.data, robot.q0)
    pin.updateGeometryPlacements(robot.model, robot.data, robot.visual_model, data)
    pts = np.array([m.translation for m in data.oMg])
    # 80th percentile, not max: a long thin part (the hybrid leg's virtual-pivot arm) must not shrink the rest
    size = float(np.percentile(np.linalg.norm(pts, axis=1), 80)) if len(pts) else 0.5
    s = max(size, 0.05) * 2.2
    return (s, 0.6 * s, s)


def write_html(robot: Robot, q: np.ndarray, path: str | Path, ground: bool = True) -> Path:
    """Write a self-contained static meshcat page showing ``robot`` at ``q``; returns the path."""
    q = robot.check_q(q)
    with open_viewer(robot, ground=ground) as viz:
        viz.display(q)
        html = viz.viewer.static_html()
    path = Path(path)
    path.write_text(html)
    return path


def _animation(robot: Robot, viz, qs: Sequence[np.ndarray], fps: int):
    """A meshcat clip moving every visual geometry through the configurations ``qs``."""
    import meshcat.animation
    import pinocchio as pin

    anim = meshcat.animation.Animation(default_framerate=fps)
    model, data = robot.model, robot.data
    for i, q in enumerate(qs):
        pin.forwardKinematics(model, data, robot.check_q(q))
        pin.updateGeometryPlacements(model, data, robot.visual_model, viz.visual_data)
        with anim.at_frame(viz.viewer, i) as frame:
            for g, geom in enumerate(robot.visual_model.geometryObjects):
                transform = viz.visual_data.oMg[g].homogeneous @ np.diag([*geom.meshScale, 1.0])
                frame[viz.getViewerNodeName(geom, pin.VISUAL)].set_transform(transform)
    return anim


def write_animation_html(
    robot: Robot, qs: Sequence[np.ndarray], path: str | Path, fps: int = 30, ground: bool = True
) -> Path:
    """Write a static page that plays a meshcat clip of ``qs`` (loops; scrub it in the Animations menu)."""
    with open_viewer(robot, ground=ground) as viz:
        viz.display(robot.check_q(qs[0]))
        # three.js setLoop(LoopRepeat, n) plays n times, then meshcat pauses and resets to frame 0:
        # repetitions=0 plays the clip ONCE; Infinity (msgpack float) loops for ever.
        viz.viewer.set_animation(_animation(robot, viz, qs, fps), play=True, repetitions=float("inf"))
        html = viz.viewer.static_html()
    path = Path(path)
    path.write_text(html)
    return path


def show(robot: Robot, q: np.ndarray, animation: Sequence[np.ndarray] | None = None, ground: bool = True,
         host: str = "127.0.0.1") -> int:
    """Serve a live meshcat view of ``robot`` at ``q`` (playing ``animation`` if given) until Ctrl-C, SIGTERM or
    SIGHUP.

    Args:
        robot: the model to show.
        q: its configuration (rad, m).
        animation: configurations (rad, m) played in a loop at 30 frames a second, or None.
        ground: a ground plane under a walking robot.
        host: the address the page is served on (127.0.0.1: this machine only; ``"0.0.0.0"``: every network
            interface, see :func:`open_viewer`).

    Returns:
        The number of the signal that stopped the viewer: 2 (SIGINT, Ctrl-C), 15 (SIGTERM) or 1 (SIGHUP); its
        server is stopped (``legkin view`` exits with 128 + that number).
    """
    import signal
    import time

    q = robot.check_q(q)
    with open_viewer(robot, ground=ground, host=host) as viz:
        viz.display(q)
        if animation is not None:
            viz.viewer.set_animation(_animation(robot, viz, animation, 30), play=True, repetitions=float("inf"))
        try:
            print(f"meshcat viewer: {viz.viewer.url()}  (Ctrl-C to stop)", flush=True)
            while True:
                time.sleep(1.0)
        except KeyboardInterrupt as exc:
            return int(getattr(exc, "signum", signal.SIGINT))


def chromium_path() -> str | None:
    """Path of a Chromium executable, or None (Debian: ``apt-get install chromium``)."""
    import shutil

    return shutil.which("chromium") or shutil.which("chromium-browser")


def screenshot(page: str | Path, png: str | Path, size: tuple[int, int] = (800, 600), budget_ms: int = 15000) -> Path:
    """Render a page with headless Chromium into a PNG (a real browser, with WebGL in software)."""
    import subprocess
    import tempfile

    exe = chromium_path()
    if exe is None:
        raise RuntimeError("headless Chromium is not installed (Debian: apt-get install chromium)")
    png = Path(png)
    with tempfile.TemporaryDirectory(prefix="legkin-chromium-") as profile:
        cmd = [
            exe, "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
            "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-quic",
            f"--user-data-dir={profile}", f"--window-size={size[0]},{size[1]}",
            f"--virtual-time-budget={budget_ms}", f"--screenshot={png.resolve()}", Path(page).resolve().as_uri(),
        ]
        subprocess.run(cmd, check=True, timeout=180, capture_output=True)
    return png
