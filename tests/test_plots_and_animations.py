"""``legkin check --plots`` figures and the animation clips (every model that has them)."""

from __future__ import annotations

import numpy as np
import pytest

import legkin
from legkin import clips as animations
from legkin.__main__ import main


def test_check_plots_written(tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "plots"
    assert main(["check", "quadruped", "--samples", "50", "--plots", str(out)]) == 0
    pngs = sorted(p.name for p in out.glob("*.png"))
    assert "check_quadruped.png" in pngs and "quadruped_workspace.png" in pngs
    from PIL import Image

    for p in out.glob("*.png"):
        img = np.asarray(Image.open(p).convert("L"), dtype=float)
        assert img.std() > 5, p


@pytest.mark.parametrize("name", legkin.list_models("legkin"))
def test_animation_clips_are_valid_configurations(name):
    robot = legkin.load(name)
    for clip in animations.available(name):
        qs = animations.frames(robot, clip)
        assert len(qs) >= 10
        qs = np.array(qs)
        assert qs.shape[1] == robot.model.nq and np.all(np.isfinite(qs))
        assert np.ptp(qs, axis=0).max() > 1e-3, "the clip moves"
        for q in qs[:: max(1, len(qs) // 10)]:
            res = robot.constraint_residual(q)
            assert res.size == 0 or np.linalg.norm(res) < 1e-9


def test_unknown_animation_is_refused():
    robot = legkin.load("quadruped")
    with pytest.raises(legkin.LegkinError, match="foot_circles"):
        animations.frames(robot, "moonwalk")
