"""Registry descriptions of the example-robot-data legged robots (for ``legkin.load``, ``legkin check``, the bench)."""

from __future__ import annotations

from .erd import _robot, erd_files

__all__ = ["erd_spec"]


def erd_spec(name: str) -> dict:
    """How to load the example-robot-data robot ``name``.

    Returns:
        ``{"name", "title", "urdf" (absolute path, str), "srdf" (str or None), "reference_pose" (str or None),
        "package_dirs" (list of str: the mesh search paths for ``package://example-robot-data/...``),
        "free_flyer" (bool), "checks" ("legkin.legs.checks": its ``run(robot_name, samples, rng)``),
        "source" ("example-robot-data")}``.

    Raises:
        UnknownModelError: ``name`` not in :data:`legkin.legs.ERD_ALL`.
    """
    robot = _robot(name)
    urdf, srdf, dirs = erd_files(name)
    return {
        "name": robot.name,
        "title": robot.title,
        "urdf": str(urdf),
        "srdf": None if srdf is None else str(srdf),
        "reference_pose": robot.reference_pose if srdf is not None else None,
        "package_dirs": list(dirs),
        "free_flyer": robot.free_flyer,
        "checks": "legkin.legs.checks",
        "source": "example-robot-data",
    }

