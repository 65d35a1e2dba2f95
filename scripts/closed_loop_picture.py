"""docs/img/closed_loop_files.png: cassie_like and digit_like (Gepetto's example-parallel-robots, with their meshes),
loaded by legkin.load, loops closed from neutral, in meshcat, rendered by headless Chromium.

    PYTHONPATH=src python scripts/closed_loop_picture.py /path/to/example-parallel-robots
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from PIL import Image

import legkin
from legkin.viewer import open_viewer, screenshot

CAMERAS = {"cassie_like": (1.0, -0.5, 0.9), "digit_like": (0.6, -0.2, 0.75)}


def main(data: Path, out: Path) -> None:
    tiles = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, camera in CAMERAS.items():
            robot = legkin.load(data / name / "robot.urdf")
            with open_viewer(robot, camera=camera, ground=False) as viz:
                viz.display(robot.q0)
                viz.viewer["/Grid"].set_property("visible", False)
                viz.viewer["/Axes"].set_property("visible", False)
                page = Path(tmp) / f"{name}.html"
                page.write_text(viz.viewer.static_html())
            png = screenshot(page, Path(tmp) / f"{name}.png", size=(420, 520))
            tiles.append(Image.open(png).convert("RGB").crop((0, 20, 420, 520)))  # the controls bar cut off
    picture = Image.new("RGB", (420 * len(tiles), 500), "white")
    for i, tile in enumerate(tiles):
        picture.paste(tile, (420 * i, 0))
    picture.save(out, optimize=True)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(__file__).parents[1] / "docs/img/closed_loop_files.png")
