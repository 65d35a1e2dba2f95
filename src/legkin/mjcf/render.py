"""Pictures of the MuJoCo models from MuJoCo's own renderer (:func:`render_png`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Sequence

import numpy as np

from .._batch import check_integer
from ..errors import LegkinError
from ._base import _mujoco
from .mechanism import MujocoMechanism

if TYPE_CHECKING:  # pragma: no cover
    pass


# ------------------------------------------------------------------------------------------ pictures
def render_png(
    mech: MujocoMechanism,
    path: str | Path,
    q: np.ndarray | None = None,
    *,
    width: int = 800,
    height: int = 600,
    azimuth: float = 135.0,
    elevation: float = -20.0,
    zoom: float = 1.0,
    lookat: Sequence[float] | None = None,
) -> Path:
    """Render configuration ``q`` (default: the current ``data``) with MuJoCo's own renderer to a PNG.

    Headless machines need ``MUJOCO_GL=egl`` (or ``osmesa``) in the environment before ``import mujoco``.
    The camera looks at ``lookat`` (default: the centre of the model's visuals) from ``azimuth``/``elevation``
    (degrees), at a distance 1.6 times the visuals' extent divided by ``zoom``.

    Raises:
        LegkinError: no OpenGL context (the message says which ``MUJOCO_GL`` to try), or Pillow missing.
    """
    mujoco = _mujoco()
    try:
        from PIL import Image
    except ImportError:
        raise LegkinError("render_png needs Pillow: pip install pillow") from None
    width, height = check_integer(width, "width", 1), check_integer(height, "height", 1)
    if q is not None:
        mech.set_configuration(q, forward=False)
    mujoco.mj_forward(mech.model, mech.data)
    geoms = [g for g in range(mech.model.ngeom) if mech.model.geom_type[g] != mujoco.mjtGeom.mjGEOM_PLANE]
    pts = mech.data.geom_xpos[geoms] if geoms else mech.data.xpos
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    cam = mujoco.MjvCamera()
    cam.lookat[:] = 0.5 * (lo + hi) if lookat is None else np.asarray(lookat, dtype=float)
    cam.distance = 1.6 * max(float(np.linalg.norm(hi - lo)), 0.05) / zoom
    cam.azimuth, cam.elevation = azimuth, elevation
    try:
        renderer = mujoco.Renderer(mech.model, height, width)
    except Exception as exc:  # noqa: BLE001 - MuJoCo raises several kinds when there is no GL context
        raise LegkinError(f"no OpenGL context for MuJoCo's renderer ({exc}); try MUJOCO_GL=egl or osmesa") from None
    try:
        renderer.update_scene(mech.data, camera=cam)
        pixels = renderer.render()
    finally:
        renderer.close()
    path = Path(path)
    Image.fromarray(pixels).save(path)
    return path
