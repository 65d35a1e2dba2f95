"""Ground scenarios of the floating MuJoCo exports (legkin.mjcf.floating, legkin.mjcf.scenarios): issue 28."""

from __future__ import annotations

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

import legkin  # noqa: E402
from legkin.mjcf.floating import load_ground  # noqa: E402
from legkin.mjcf.ground import ground_model  # noqa: E402
from legkin.mjcf.scenarios import run_scenario  # noqa: E402


@pytest.fixture(scope="module")
def wheel():
    return load_ground("wheel_leg")


@pytest.fixture(scope="module")
def quad():
    return load_ground("quadruped")


def _passed(result):
    for row in result.rows:
        assert row.passed, row
    assert result.rtf > 0


def test_keyframe_stands_at_legkins_height(quad, wheel):
    for mech in (quad, wheel):
        mujoco.mj_resetDataKeyframe(mech.model, mech.data, 0)
        assert mech.data.qpos[2] == pytest.approx(mech.height, abs=1e-12)
        lowest = mech.ground.contacts(mech.robot.q0)[:, 2] + mech.height
        assert np.abs(lowest).max() < 1e-9  # every contact of the symmetric pose on the floor


def test_tyre_cylinders_lie_on_the_pitch_circle(wheel):
    """In wheel mode every tyre cylinder axis is at the pitch radius R from the wheel centre (U = L)."""
    data = wheel.robot.model.createData()
    import pinocchio as pin

    pin.framesForwardKinematics(wheel.robot.model, data, wheel.robot.q0)
    centre = data.oMf[wheel.robot.model.getFrameId("FL_U_L")].translation
    geoms = [g for g in wheel.ground.geoms() if g.name.startswith("FL_")]
    dist = [np.linalg.norm(data.oMi[g.joint].act(g.placement.translation) - centre) for g in geoms]
    np.testing.assert_allclose(dist, wheel.robot.geometry.R, atol=1e-12)


def test_quadruped_stands(quad):
    _passed(run_scenario(quad, "stand", seconds=1.0))


def test_quadruped_squats(quad):
    _passed(run_scenario(quad, "squat", seconds=1.0))


def test_wheel_leg_stands_and_rolls(wheel):
    _passed(run_scenario(wheel, "stand", seconds=1.0))
    _passed(run_scenario(wheel, "roll", seconds=1.0))


def test_without_contacts_it_falls_through(quad):
    """A check that can fail: the same model with its contact geoms disabled falls through the floor."""
    xml = quad.xml.replace('contype="1" conaffinity="0" group="3"', 'contype="0" conaffinity="0" group="3"')
    assert xml != quad.xml
    from legkin.mjcf.mechanism import load_mujoco

    broken = load_mujoco(quad.robot, xml=xml)
    broken.__class__ = type(quad)
    broken.ground, broken.height = quad.ground, quad.height
    res = run_scenario(broken, "stand", seconds=0.3)
    assert not res.rows[0].passed and res.rows[0].max_error > 0.05


def test_ground_model_needs_floating():
    with pytest.raises(legkin.errors.InvalidParameterError):
        ground_model(legkin.load("quadruped"))
