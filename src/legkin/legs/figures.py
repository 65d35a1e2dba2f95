"""The picture of docs/legs.md: robots whose feet trace circles solved by :meth:`Leg.ik` (``feet_circles``).

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

__all__ = ["ROBOTS", "FRAMES", "SHOT", "render", "foot_paths"]

#: The robots shown (one column each) and the clip frames shown (one row each).
ROBOTS = ("go2", "anymal_c")
FRAMES = (0, 20, 40)
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


def _page(robot, q, paths: np.ndarray, camera, path: Path) -> None:
    """A static meshcat page of ``robot`` at ``q`` with blue dots on the foot paths."""
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
        viewer.set_transform(mt.translation_matrix([0.0, 0.0, -0.3 * float(paths[..., 2].min())]))
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


def render(out: str | Path = "docs/img/legs_go2_anymal_c.png", robots=ROBOTS, frames=FRAMES) -> Path:
    """Render the picture into ``out`` (PNG, palette-quantized) and return its path."""
    from PIL import Image, ImageDraw

    from ..robot import load
    from ..viewer import screenshot
    from .clips import feet_circles

    w, h = SHOT
    label_h = 22
    sheet = Image.new("RGB", (w * len(robots), (h + label_h) * len(frames)), "white")
    draw = ImageDraw.Draw(sheet)
    with tempfile.TemporaryDirectory(prefix="legkin-legs-fig-") as tmp:
        for c, name in enumerate(robots):
            robot = load(name)
            qs = feet_circles(robot)
            paths = foot_paths(robot, qs)
            cam = _camera(paths)
            for r, f in enumerate(frames):
                page, png = Path(tmp) / f"{name}_{f}.html", Path(tmp) / f"{name}_{f}.png"
                _page(robot, qs[f], paths, cam, page)
                screenshot(page, png, size=(w, h + CROP_TOP))
                with Image.open(png) as shot:
                    img = shot.convert("RGB").crop((0, CROP_TOP, w, h + CROP_TOP))
                    sheet.paste(img, (c * w, r * (h + label_h) + label_h))
                draw.text((c * w + 8, r * (h + label_h) + 5),
                          f"{name}  frame {f}/{len(qs)}  (Leg.ik, q_near = previous frame)", fill="black")
    out = Path(out)
    sheet.quantize(colors=128, method=Image.Quantize.MEDIANCUT).save(out, optimize=True)
    return out


if __name__ == "__main__":  # pragma: no cover
    print(render(*sys.argv[1:2]))
