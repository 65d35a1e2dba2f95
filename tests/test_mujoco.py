"""MuJoCo models of the four mechanisms (legkin.mjcf): loops as equality constraints."""

from __future__ import annotations

import argparse
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

import legkin  # noqa: E402
from legkin import mjcf as mx  # noqa: E402
from legkin.errors import InvalidParameterError, LegkinError, UnknownModelError  # noqa: E402

MODELS = ["hybrid_leg", "quadruped", "tripod", "wheel_leg"]


@pytest.fixture(scope="module", params=MODELS)
def mech(request) -> mx.MujocoMechanism:
    return mx.load_mujoco(request.param)


@pytest.fixture(scope="module")
def rows(mech) -> list:
    return mx.check_rows(mech.robot.name, samples=5, rng=np.random.default_rng(1), mech=mech)


def test_one_equality_per_loop_closure(mech):
    robot = mech.robot
    assert mech.model.neq == len(robot.loops)
    want = {"point": mujoco.mjtEq.mjEQ_CONNECT, "frame": mujoco.mjtEq.mjEQ_WELD}
    for k, lp in enumerate(robot.loops):
        assert mujoco.mj_id2name(mech.model, mujoco.mjtObj.mjOBJ_EQUALITY, k) == lp.name
        assert mech.model.eq_type[k] == want[lp.type]
        assert mech.model.eq_objtype[k] == mujoco.mjtObj.mjOBJ_SITE
    assert mech.model.nu == len(robot.actuated_joints)
    assert mech.model.nq == robot.model.nq


def test_reference_keyframe_is_q0(mech):
    robot = mech.robot
    key = mujoco.mj_name2id(mech.model, mujoco.mjtObj.mjOBJ_KEY, robot.spec.reference_pose)
    assert key == 0
    np.testing.assert_array_equal(mech.model.key_qpos[0], mech.qpos(robot.q0))
    np.testing.assert_array_equal(mech.model.key_ctrl[0], mech.ctrl(robot.q0))
    np.testing.assert_array_equal(mech.q(mech.qpos(robot.q0)), robot.q0)


def test_the_four_checks_pass(mech, rows):
    robot = mech.robot
    assert len(rows) == (5 if robot.loops else 2)  # with the MJCF round trip row (issue 27)
    for row in rows:
        assert row.passed, f"{robot.name}: {row}"
        assert row.samples > 0


def test_inertias_are_consistent_and_massless_links_made_tiny(mech):
    m = mech.model
    for b in range(1, m.nbody):
        i = np.sort(m.body_inertia[b])
        assert m.body_mass[b] > 0 and i[0] > 0 and i[0] + i[1] >= i[2] * (1 - 1e-9)
    if mech.robot.name == "hybrid_leg":
        sph = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "Sph_1_1_a")
        assert m.body_mass[sph] == mx.DEFAULTS["min_mass"]


def test_removing_an_equality_breaks_the_checks():
    """A check that can fail: the hybrid leg's MJCF without its first <connect> (rod_1)."""
    mech = mx.load_mujoco("hybrid_leg")
    xml, n = re.subn(r"\s*<connect name=\"rod_1\"[^>]*/>", "", mech.xml)
    assert n == 1
    broken = mx.load_mujoco(mech.robot, xml=xml)
    assert broken.model.neq == 1
    qs = mx.closed_configurations(broken.robot, 2, np.random.default_rng(0))
    assert np.all(np.isnan(mx.equality_errors(broken, qs)))  # a missing row is a failure
    hold = mx.hold_under_gravity(broken, 0.5)
    assert np.nanmax(hold["loop"][:, 0]) > 1e2 * mx.TOL_GRAVITY  # rod_1 falls open
    assert np.nanmax(hold["loop"][:, 1]) < mx.TOL_GRAVITY  # rod_2 still holds


def test_loop_residual_grows_with_a_soft_constraint():
    """Check (3) measures something: a 10x softer equality leaves a 10x-100x larger residual."""
    stiff = mx.hold_under_gravity(mx.load_mujoco("tripod"), 0.3)["loop"]
    soft = mx.hold_under_gravity(mx.load_mujoco("tripod", eq_solimp=(0.99, 0.99, 0.001)), 0.3)["loop"]
    assert np.nanmax(soft) > 10 * np.nanmax(stiff)


def test_floating_base():
    robot = legkin.load("quadruped", floating=True)
    mech = mx.load_mujoco(robot)
    assert mech.model.nq == robot.model.nq == 19 and mech.model.njnt == 13
    q = robot.q0.copy()
    q[:3] = [0.1, -0.2, 0.5]
    q[3:7] = np.array([0.1, 0.2, 0.3, 0.9]) / np.linalg.norm([0.1, 0.2, 0.3, 0.9])
    np.testing.assert_allclose(mech.q(mech.qpos(q)), q, atol=1e-15)
    assert mx.placement_errors(mech, [q])[0] < 1e-12


def test_options_and_errors():
    with pytest.raises(InvalidParameterError, match="unknown parameter"):
        mx.to_mjcf("tripod", time_step=1e-3)  # with a name, other keywords are xacro arguments
    with pytest.raises(InvalidParameterError, match="unknown MJCF option"):
        mx.to_mjcf(legkin.load("tripod"), time_step=1e-3)
    with pytest.raises(InvalidParameterError):
        mx.to_mjcf("tripod", timestep=-1.0)
    with pytest.raises(InvalidParameterError, match="already loaded"):
        mx.to_mjcf(legkin.load("tripod"), d=0.1)
    d = 1.1 * legkin.load("tripod").params["d"]
    assert mx.load_mujoco("tripod", d=d, timestep=1e-3).robot.params["d"] == d  # xacro argument + option
    with pytest.raises(UnknownModelError):
        mx.to_mjcf("no_such_model")
    with pytest.raises(LegkinError, match="refused"):
        mx.load_mujoco("tripod", xml="<mujoco><worldbody><body/></worldbody>")
    root = ET.fromstring(mx.to_mjcf("tripod", timestep=1e-3, kp=3.0, kv={"A_q1": 0.5}))
    assert root.find("option").get("timestep") == "0.001"
    assert root.find("equality/weld").get("solref") == "0.002 0.7"
    acts = root.findall("actuator/position")
    assert [a.get("kp") for a in acts] == ["3", "3", "3"] and acts[0].get("kv") == "0.5"


def test_cli_functions(tmp_path):
    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers(dest="command")
    mx.add_export_command(sub)
    out = tmp_path / "tripod.xml"
    args = parser.parse_args(["mjcf", "tripod", "-o", str(out)])
    assert args.func(args) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.neq == 2


def test_unavailable_reason_is_none_here():
    assert mx.unavailable_reason() is None
