"""The pictures of docs/legs.md: robots whose feet trace circles solved by :meth:`Leg.ik` (``feet_circles``), and
humanoids doing the ``squat`` clip solved by :meth:`Leg6.ik` (:func:`render_squat`).

``python -m legkin.legs.figures [out.png]`` renders, with legkin's viewer (meshcat pages, headless Chromium),
the robots of :data:`ROBOTS` side by side (a column each), a row per frame of :data:`FRAMES` of the
``feet_circles`` clip, with
the feet's circles (Pinocchio's feet over the whole clip) drawn as blue dots; pillow combines the shots.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["ROBOTS", "FRAMES", "SHOT", "render", "render_squat", "foot_paths", "SQUAT_ROBOTS", "SQUAT_FRAMES"]

#: The robots shown (one column each) and the clip frames shown (one row each).
ROBOTS = ("go2", "anymal_c")
FRAMES = (0, 20, 40)
#: The humanoids of the squat picture (floating base, one column each) and the frames shown (one row each).
SQUAT_ROBOTS = ("talos", "g1")
SQUAT_FRAMES = (0, 30)
#: Size (px) of one shot, and the rows cropped off its top (meshcat's "Open Controls" bar).
SHOT = (520, 360)
CROP_TOP = 24


def foot_paths(robot, qs) -> np.ndarray:
    """Pinocchio's feet (frames, legs, 3) in the world frame along the configurations ``qs``."""
    import pinocchio as pin

    model, data = robot.model, robot.model.createData()
    fids = [model.getFrameId(leg.foot_frame) for leg in robot.geometry.values()]
    out = np.empty((len(qs), len(fids), 3))
    for i, q in enumerate(qs):
        pin.framesForwardKinematics(model, data, np.asarray(q, dtype=float))
        out[i] = [data.oMf[f].translation for f in fids]
    return out


def _page(robot, q, paths: np.ndarray, camera, path: Path, shift: float | None = None) -> None:
    """A static meshcat page of ``robot`` at ``q`` with blue dots on the foot paths; the scene moved up by ``shift``
    (m; default 0.3 times the lowest foot's depth), the camera looking at the origin."""
    import meshcat.geometry as mg
    import meshcat.transformations as mt

    from ..viewer import open_viewer

    with open_viewer(robot, camera=camera) as viz:
        viz.display(robot.check_q(q))
        viewer = viz.viewer
        viewer["/Grid"].set_property("visible", False)
        viewer["/Axes"].set_property("visible", False)
        viewer["/Background"].set_property("top_color", [1.0, 1.0, 1.0])
        viewer["/Background"].set_property("bottom_color", [0.85, 0.88, 0.92])
        # lift the robot towards the middle between its base and its feet (the camera looks at the origin)
        up = -0.3 * float(paths[..., 2].min()) if shift is None else shift
        viewer.set_transform(mt.translation_matrix([0.0, 0.0, up]))
        viewer["/legkin"].set_transform(mt.translation_matrix([0.0, 0.0, up]))  # the ground with the robot
        dot, blue = mg.Sphere(0.0055), mg.MeshLambertMaterial(color=0x1565C0)
        for k in range(paths.shape[1]):
            for i in range(0, len(paths), 2):
                node = viz.viewer[f"foot_paths/{k}/{i}"]
                node.set_object(dot, blue)
                node.set_transform(mt.translation_matrix(paths[i, k]))
        path.write_text(viz.viewer.static_html())


def _camera(paths: np.ndarray) -> tuple[float, float, float]:
    """A view from the robot's left-front, slightly above, far enough for the whole robot (meshcat's y-up
    camera frame: (x, up, -y))."""
    s = 1.75 * float(np.abs(paths).max())
    return (0.35 * s, 0.25 * s, 1.0 * s)


def _sheet(columns, frames, out: str | Path, label) -> Path:
    """Shots of ``columns`` (``[(name, robot, qs, paths, camera, shift)]``) at ``frames``, a column per robot and a row
    per frame, labelled ``label(name, frame, count)``, saved as a palette PNG into ``out``."""
    from PIL import Image, ImageDraw

    from ..viewer import screenshot

    w, h = SHOT
    label_h = 22
    sheet = Image.new("RGB", (w * len(columns), (h + label_h) * len(frames)), "white")
    draw = ImageDraw.Draw(sheet)
    with tempfile.TemporaryDirectory(prefix="legkin-legs-fig-") as tmp:
        for c, (name, robot, qs, paths, cam, shift) in enumerate(columns):
            for r, f in enumerate(frames):
                page, png = Path(tmp) / f"{name}_{f}.html", Path(tmp) / f"{name}_{f}.png"
                _page(robot, qs[f], paths, cam, page, shift)
                screenshot(page, png, size=(w, h + CROP_TOP))
                with Image.open(png) as shot:
                    img = shot.convert("RGB").crop((0, CROP_TOP, w, h + CROP_TOP))
                    sheet.paste(img, (c * w, r * (h + label_h) + label_h))
                draw.text((c * w + 8, r * (h + label_h) + 5), label(name, f, len(qs)), fill="black")
    out = Path(out)
    sheet.quantize(colors=128, method=Image.Quantize.MEDIANCUT).save(out, optimize=True)
    return out


def render(out: str | Path = "docs/img/legs_go2_anymal_c.png", robots=ROBOTS, frames=FRAMES) -> Path:
    """Render the feet-circles picture into ``out`` (PNG, palette-quantized) and return its path."""
    from .. import load
    from .clips import feet_circles

    columns = []
    for name in robots:
        robot = load(name)
        qs = feet_circles(robot)
        paths = foot_paths(robot, qs)
        columns.append((name, robot, qs, paths, _camera(paths), None))
    return _sheet(columns, frames, out, lambda n, f, k: f"{n}  frame {f}/{k}  (Leg.ik, q_near = previous frame)")


def render_squat(out: str | Path = "docs/img/legs_squat_talos_g1.png", robots=SQUAT_ROBOTS,
                 frames=SQUAT_FRAMES) -> Path:
    """Render the humanoids' squat (floating base: the pelvis goes down, the soles stay on the floor; the blue dots
    are Pinocchio's soles over the whole clip) into ``out`` and return its path."""
    from .. import load
    from .clips import squat

    columns = []
    for name in robots:
        robot = load(name, floating=True)
        qs = squat(robot)
        paths = foot_paths(robot, qs)
        height = float(qs[0][2] - paths[..., 2].min())  # base above the soles (m)
        s = 1.2 * height + 0.3
        columns.append((name, robot, qs, paths, (0.55 * s, 0.2 * s, 1.0 * s), -0.55 * height))
    return _sheet(columns, frames, out, lambda n, f, k: f"{n}  squat frame {f}/{k}  (Leg6.ik, feet fixed)")


if __name__ == "__main__":  # pragma: no cover
    print(render_squat(*sys.argv[2:3]) if sys.argv[1:2] == ["squat"] else render(*sys.argv[1:2]))
