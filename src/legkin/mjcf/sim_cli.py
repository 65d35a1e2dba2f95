"""``legkin sim MODEL --scenario stand|roll|squat|press [--video out.mp4 | --html out.html]``: run a ground scenario
(:func:`legkin.mjcf.scenarios.run_scenario`), print its figures and real-time factor, optionally record it."""

from __future__ import annotations

import base64
import io
from pathlib import Path
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from ..errors import LegkinError
from ._base import _mujoco, unavailable_reason
from .floating import GroundMechanism
from .scenarios import SCENARIOS, run_scenario

if TYPE_CHECKING:  # pragma: no cover
    import argparse

__all__ = ["add_sim_command", "run_sim", "render_frames", "write_video", "write_html"]

_FPS = 30.0


def render_frames(mech: GroundMechanism, frames: Sequence[np.ndarray], *, width: int = 640, height: int = 480,
                  azimuth: float = 135.0, elevation: float = -15.0, distance: float = 1.6) -> list[np.ndarray]:
    """RGB images (height, width, 3) of ``qpos`` frames, the camera following the base, half way down to the floor
    (a fixed mechanism: at its base) (``MUJOCO_GL=egl``)."""
    mujoco = _mujoco()
    try:
        renderer = mujoco.Renderer(mech.model, height, width)
    except Exception as exc:  # noqa: BLE001 - MuJoCo raises several kinds when there is no GL context
        raise LegkinError(f"no OpenGL context for MuJoCo's renderer ({exc}); try MUJOCO_GL=egl or osmesa") from None
    cam = mujoco.MjvCamera()
    cam.azimuth, cam.elevation, cam.distance = azimuth, elevation, distance
    out = []
    try:
        for qpos in frames:
            mech.data.qpos[:] = qpos
            mujoco.mj_forward(mech.model, mech.data)
            base = mech.data.xpos[mech.body_ids[1]]  # a fixed mechanism's qpos starts with joint angles
            cam.lookat[:] = [base[0], base[1], 0.5 * base[2]] if not mech.ground.fixed_base else base
            renderer.update_scene(mech.data, camera=cam)
            out.append(renderer.render().copy())
    finally:
        renderer.close()
    return out


def write_video(images: Sequence[np.ndarray], path: str | Path, fps: float = _FPS) -> Path:
    """Encode RGB images as an H.264 MP4 (needs ``imageio-ffmpeg``: ``pip install "legkin[sim]"``)."""
    try:
        import imageio_ffmpeg
    except ImportError:
        raise LegkinError('--video needs imageio-ffmpeg: pip install "legkin[sim]"') from None
    path = Path(path)
    h, w = images[0].shape[:2]
    writer = imageio_ffmpeg.write_frames(str(path), (w, h), fps=fps, macro_block_size=8, quality=7)
    writer.send(None)
    for im in images:
        writer.send(np.ascontiguousarray(im))
    writer.close()
    return path


def write_html(images: Sequence[np.ndarray], path: str | Path, title: str, fps: float = _FPS) -> Path:
    """A self-contained page playing the images (JPEG frames embedded, a few lines of JavaScript)."""
    from PIL import Image

    urls = []
    for im in images:
        buf = io.BytesIO()
        Image.fromarray(im).save(buf, format="JPEG", quality=80)
        urls.append("data:image/jpeg;base64," + base64.b64encode(buf.getvalue()).decode())
    frames = ",".join(f'"{u}"' for u in urls)
    path = Path(path)
    path.write_text(
        f"<!doctype html><meta charset=utf-8><title>{title}</title><h3>{title}</h3><img id=f>"
        f"<script>const F=[{frames}];let i=0;const im=document.getElementById('f');"
        f"setInterval(()=>{{im.src=F[i];i=(i+1)%F.length}},{1000.0 / fps:.1f});</script>\n"
    )
    return path


def add_sim_command(subparsers: "argparse._SubParsersAction") -> "argparse.ArgumentParser":
    """Add ``legkin sim`` to ``legkin``'s parser."""
    p = subparsers.add_parser("sim", help="run a MuJoCo ground scenario (stand, roll, squat, press) and measure it")
    p.add_argument("model")
    p.add_argument("--scenario", choices=SCENARIOS, default=None,
                   help="default: stand (press for a fixed mechanism, the hybrid leg)")
    p.add_argument("--seconds", type=float, default=2.0, help="scenario length, s (default %(default)g)")
    out = p.add_mutually_exclusive_group()
    out.add_argument("--video", metavar="PATH", help="record an MP4 (MUJOCO_GL=egl headless)")
    out.add_argument("--html", metavar="PATH", help="record a self-contained HTML page")
    p.set_defaults(func=run_sim)
    return p


def run_sim(args: "argparse.Namespace") -> int:
    """Run ``legkin sim``: the scenario's rows, its real-time factor, and the recording if asked."""
    reason = unavailable_reason()
    if reason is not None:
        raise LegkinError(reason)
    record = bool(args.video or args.html)
    from .floating import load_ground

    mech = load_ground(args.model)
    scenario = args.scenario or ("press" if mech.ground.fixed_base else "stand")
    res = run_scenario(mech, scenario, seconds=args.seconds, fps=_FPS if record else None)
    width = max(len(r.name) for r in res.rows)
    for r in res.rows:
        print(f"{r.name:<{width}}  {r.max_error:10.3e}  tol {r.tolerance:7.0e}  {'pass' if r.passed else 'FAIL'}")
    print(f"{res.simulated:.2f} s simulated in {res.wall:.2f} s of CPU: real-time factor {res.rtf:.1f} (one core)")
    if record:
        images = render_frames(mech, res.frames)
        kw: dict[str, Any] = {}
        path = write_video(images, args.video, **kw) if args.video else write_html(
            images, args.html, f"legkin {args.model}: {scenario}")
        print(f"wrote {path}")
    return 0 if all(r.passed for r in res.rows) else 1
