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


def test_wheel_leg_stands_rolls_and_squats(wheel):
    _passed(run_scenario(wheel, "stand", seconds=1.0))
    _passed(run_scenario(wheel, "roll", seconds=1.0))
    _passed(run_scenario(wheel, "squat", seconds=1.0))


def test_go2_stands():
    _passed(run_scenario("go2", "stand", seconds=1.0))


def test_tyre_lies_inside_legkins_within_the_sampling_bound(wheel):
    """MuJoCo's lowest tyre point against ground_contact on sampled leg angles: never outside legkin's tyre, at
    most R (1 - cos(phi / 2)) inside (phi: the largest angle between two cylinders), at most half the spacing
    along the ground."""
    from legkin.wheel_leg.sim import TYRE_STEP, tyre_contact_errors

    rng = np.random.default_rng(3)
    n = 24
    lq = np.column_stack([rng.uniform(np.radians(17), np.radians(160), n), rng.uniform(-np.pi, np.pi, n),
                          rng.uniform(-0.3, 0.3, n)])
    lq[: n // 2, 0] = np.radians(17)  # wheel mode: the lowest point on a pitch arc
    err = tyre_contact_errors(wheel, lq)
    R = wheel.robot.geometry.R
    phi = 2 * wheel.ground.stand_angle * 2  # the largest spacing is the upper arcs' <= step / R
    assert err[:, 0].min() > -1e-9
    assert err[:, 0].max() <= R * (1 - np.cos(max(phi, TYRE_STEP / R) / 2)) + 1e-9
    assert np.abs(err[:, 1]).max() <= TYRE_STEP / 2 + 1e-9


def test_sim_command(tmp_path, capsys):
    from legkin.__main__ import main

    code = main(["sim", "quadruped", "--scenario", "stand", "--seconds", "0.5"])
    out = capsys.readouterr().out
    assert code == 0 and "real-time factor" in out and "quadruped stand" in out
    assert main(["sim", "quadruped", "--scenario", "roll"]) != 0
    assert "quadruped has no wheels" in capsys.readouterr().err


def test_sim_html(tmp_path, capsys):
    from legkin.__main__ import main

    page = tmp_path / "stand.html"
    code = main(["sim", "quadruped", "--seconds", "0.1", "--html", str(page)])
    if "no OpenGL" in capsys.readouterr().err:
        pytest.skip("no OpenGL here")
    assert code == 1  # 0.1 s: not settled from the 1 cm drop, a row fails and the exit code says so
    assert page.read_text().count("data:image/jpeg;base64,") >= 3


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


def test_without_the_feedforward_the_legs_sag(quad, monkeypatch):
    """The feedforward matters: without it (and without the integral term) the quadruped stands mm low."""
    monkeypatch.setattr(type(quad.ground), "static_torques", lambda self, q: np.zeros(self.robot.model.nv))
    res = run_scenario(quad, "stand", seconds=1.0)
    assert not res.rows[0].passed and res.rows[0].max_error > 2e-3


def test_ground_model_needs_floating():
    with pytest.raises(legkin.errors.InvalidParameterError):
        ground_model(legkin.load("quadruped"))


def test_floating_export_has_contacts_and_a_colliding_floor(tmp_path, capsys):
    from legkin.__main__ import main

    out = tmp_path / "go2.xml"
    assert main(["mjcf", "go2", "--floating", "-o", str(out)]) == 0  # go2's .dae visuals: its collision shapes shown
    model = mujoco.MjModel.from_xml_path(str(out))
    floor = model.geom("floor")
    assert floor.conaffinity[0] == 1 and floor.contype[0] == 0
    assert model.opt.timestep == pytest.approx(1e-3)
    feet = [model.geom(f"{leg}_foot_contact") for leg in ("FL", "FR", "RL", "RR")]
    assert all(f.contype[0] == 1 and f.conaffinity[0] == 0 for f in feet)
    assert main(["export", "quadruped", "--mjcf", str(tmp_path / "q.xml")]) == 0  # fixed base: no contacts
    assert "contact" not in (tmp_path / "q.xml").read_text()


def test_static_torques_are_what_mujoco_needs(quad):
    """The feedforward of the legs (FootGround.static_torques) against MuJoCo's actuator forces after 2 s standing
    (measured: 1.3e-2 N m of 13 N m for the quadruped, 1.8e-4 of 5.5 for go2); the sign flipped is far off."""
    from legkin.mjcf.scenarios import _Runner

    run = _Runner(quad, None)
    run.start(0, 0.0)
    run.run(2.0)
    m = quad.model
    tau = quad.ground.static_torques(quad.robot.q0)[m.jnt_dofadr[m.actuator_trnid[:, 0]]]
    force = quad.data.actuator_force
    assert np.abs(tau - force).max() < 0.01 * np.abs(force).max()
    assert np.abs(-tau - force).max() > 0.5 * np.abs(force).max()


@pytest.mark.parametrize("name", ["solo12", "anymal", "anymal_c", "hyq", "go1", "a1", "b1", "laikago"])
def test_every_registry_quadruped_stands(name):
    """Generated per robot of legkin.legs: the ground model needs nothing robot-specific."""
    _passed(run_scenario(name, "stand", seconds=1.0))


def test_sim_video(tmp_path):
    """``--video``: an MP4 from MuJoCo's renderer (the ``sim`` extra, imageio-ffmpeg)."""
    pytest.importorskip("imageio_ffmpeg")
    from legkin.mjcf.sim_cli import render_frames, write_video

    mech = load_ground("quadruped")
    try:
        images = render_frames(mech, [mech.model.key_qpos[0]] * 6, width=64, height=48)
    except legkin.errors.LegkinError as exc:
        pytest.skip(f"no OpenGL here: {exc}")
    out = write_video(images, tmp_path / "stand.mp4", fps=6)
    assert out.stat().st_size > 1000 and out.read_bytes()[4:8] == b"ftyp"


def test_models_without_a_ground_model_have_no_ground_rows(monkeypatch):
    """A fixed mechanism (tripod) and a robot of legkin.legs.sim.UNSUPPORTED have no ground model: `legkin check`
    gives them no ground rows instead of failing, and the ground export says why."""
    import legkin.legs.sim as sim
    from legkin.mjcf.ground import has_ground_model
    from legkin.mjcf.scenarios import ground_rows

    monkeypatch.setattr(sim, "UNSUPPORTED", {"bolt": "a reason"})
    for name in ("tripod", "bolt"):
        assert not has_ground_model(name)
        assert ground_rows(name) == []
        with pytest.raises(legkin.errors.InvalidParameterError, match="no ground model") as exc:
            load_ground(name)
        assert ("a reason" in str(exc.value)) == (name == "bolt")


def test_bolt_stands_with_its_base_held_in_roll_and_pitch():
    """bolt on its two point feet: its base held in roll and pitch by a torque (100 m g h per rad, no force), it
    stands and squats; the contacts carry its weight; the torque is the moment of its centre of mass 19 mm behind
    its feet; without it, it falls."""
    mech = load_ground("bolt")
    assert mech.ground.held_tilt == pytest.approx(100.0 * mech.ground.toppling())
    assert "this file does not" in mech.xml
    _passed(run_scenario(mech, "stand"))  # 2 s: after 1 s the contacts carried 1.3 % less than its weight
    assert np.all(mech.data.qfrc_applied[:3] == 0.0)
    weight = -mech.model.opt.gravity[2] * mech.model.body_mass.sum()
    force, fz = np.zeros(6), 0.0
    for i in range(mech.data.ncon):
        mujoco.mj_contactForce(mech.model, mech.data, i, force)
        fz += force[0]
    assert fz == pytest.approx(weight, rel=1e-3)
    com = mech.data.subtree_com[0] - np.mean([mech.data.contact.pos[i] for i in range(mech.data.ncon)], axis=0)
    assert np.linalg.norm(mech.data.qfrc_applied[3:6]) == pytest.approx(weight * abs(com[0]), rel=0.05)
    _passed(run_scenario(mech, "squat", seconds=1.0))
    mech.ground.held_tilt = 0.0
    assert run_scenario(mech, "stand", seconds=1.0).rows[0].max_error > 0.02


# ---------------------------------------------------------------------------------------- humanoids: flat feet
def test_sole_spheres_from_the_foot_shapes(monkeypatch):
    """g1: its URDF's four 5 mm spheres; talos: four spheres inside its collision mesh's sole (0.208 x 0.124 m),
    bottoms on its lowest vertex; simple_humanoid (no foot shape): DEFAULT_SOLE; icub: its Y-up Collada foot turned
    back (long along x), sideways without."""
    import legkin.legs.sim as sim

    g1 = legkin.load("g1", floating=True)
    spheres = sim.sole_spheres(g1, "left_ankle_roll_link")
    assert len(spheres) == 4 and all(r == 0.005 for _, r in spheres)
    assert {round(c[0], 9) for c, _ in spheres} == {-0.05, 0.12}
    talos = legkin.load("talos", floating=True)
    c = np.array([c for c, _ in sim.sole_spheres(talos, "left_sole_link")])
    size = c[:, :2].max(axis=0) - c[:, :2].min(axis=0) + 2 * sim.SOLE_RADIUS
    assert size == pytest.approx([0.208, 0.124], abs=1e-3)
    assert np.ptp(c[:, 2]) == 0.0 and abs(c[0, 2] - sim.SOLE_RADIUS) < 1e-3  # the sole frame is on the sole
    simple = legkin.load("simple_humanoid", floating=True)  # no foot shape: DEFAULT_SOLE
    c = np.array([c for c, _ in sim.sole_spheres(simple, "l_ankle")])
    x0, x1, y0, y1, z = sim.DEFAULT_SOLE
    np.testing.assert_allclose(c.min(axis=0), [x0 + 0.005, y0 + 0.005, z + 0.005], atol=1e-15)
    np.testing.assert_allclose(c.max(axis=0), [x1 - 0.005, y1 - 0.005, z + 0.005], atol=1e-15)
    icub = legkin.load("icub", floating=True)
    for turned in (True, False):
        monkeypatch.setattr(sim, "_y_up", lambda path, turned=turned: turned and str(path).endswith(".dae"))
        c = np.array([c for c, _ in sim.sole_spheres(icub, "l_sole")])
        length, width = c[:, :2].max(axis=0) - c[:, :2].min(axis=0)
        assert (length > 2 * width) == turned


def test_flat_feet_are_levelled():
    """icub's half_sitting pitches its soles 0.063 rad (9 mm from toe to heel): the ground model's pose levels them
    by Leg6.ik, the joints other than the legs' untouched."""
    robot = legkin.load("icub", floating=True)
    ground = ground_model(robot)
    before, q = ground.contacts(robot.q0)[:, 2], ground.pose(robot.q0)
    after = ground.contacts(q)[:, 2]
    for leg in ground.legs:
        rows = [k for k, f in enumerate(ground.feet) if f.leg == leg]
        assert np.ptp(before[rows]) > 5e-3 and np.ptp(after[rows]) < 1e-9
    legs = sorted({i for f in ground.feet for i in f.idx_q})
    others = np.setdiff1d(np.arange(7, robot.model.nq), legs)
    np.testing.assert_array_equal(q[others], robot.q0[others])


@pytest.mark.parametrize("name", ["talos", "icub", "alexander"])
def test_humanoids_stand(name):
    _passed(run_scenario(name, "stand", seconds=1.0))


def test_humanoids_squat():
    """talos from half_sitting; g1 (no SRDF: straight knees) from 2 cm below its zero pose."""
    _passed(run_scenario("talos", "squat", seconds=1.0))
    _passed(run_scenario("g1", "squat", seconds=1.0))


def test_simple_humanoid_stands_on_straight_legs():
    """Its SRDF half_sitting lies outside its URDF limits (ankle pitch -0.419 rad, range [0, 2.618]): it stands on
    straight legs, inside them, soles level; its base's test capsule (1 m) is left out; it has no squat. Standing in
    its half_sitting instead (soles levelled, the stance emptied), MuJoCo's joint limits leave its base 8 cm from
    legkin's height."""
    mech = load_ground("simple_humanoid")
    robot, ground = mech.robot, mech.ground
    q, legs = ground.pose(robot.q0), sorted(ground.stance)
    lo, hi = robot.model.lowerPositionLimit[legs], robot.model.upperPositionLimit[legs]
    assert len(legs) == 12 and np.all((lo <= q[legs]) & (q[legs] <= hi))
    assert not np.all((lo <= robot.q0[legs]) & (robot.q0[legs] <= hi))
    assert np.ptp(ground.contacts(q)[:, 2]) < 1e-12
    names = [mech.model.geom(i).name for i in range(mech.model.ngeom) if mech.model.geom_contype[i]]
    assert len(names) == 8 and all("_sole" in n for n in names)
    _passed(run_scenario(mech, "stand", seconds=1.0))
    with pytest.raises(legkin.errors.InvalidParameterError, match="simple_humanoid does not squat"):
        run_scenario(mech, "squat")
    ground.stance = {}
    res = run_scenario(mech, "stand", seconds=1.0)
    assert res.rows[0].max_error > 0.02


def test_romeo_has_no_squat():
    mech = load_ground("romeo")
    assert mech.ground.no_squat and "joint limits" in mech.ground.no_squat
    with pytest.raises(legkin.errors.InvalidParameterError, match="romeo does not squat"):
        run_scenario(mech, "squat")


def test_without_the_stiffness_floor_g1_topples(monkeypatch):
    """The legs' gains >= 2 m g h matter: with the export's own (g1's ankle 98.7 N m / rad, from its foot's inertia)
    g1 pitches forwards and is mm low after 2 s; with them it stands (test_humanoids_squat)."""
    from legkin.mjcf.ground import FootGround

    monkeypatch.setattr(FootGround, "stiffness", lambda self: {})
    res = run_scenario("g1", "stand")
    assert not res.rows[0].passed and res.rows[0].max_error > 2e-3


def test_ascii_stl_is_left_out():
    """simple_humanoid's box.stl is ASCII, which MuJoCo does not read; talos's binary STL is kept."""
    from legkin.legs.erd import erd_files
    from legkin.mjcf.floating import _ascii_stl

    root = erd_files("simple_humanoid")[0].parents[1]
    assert _ascii_stl(str(root / "meshes" / "box.stl"))
    mesh = legkin.load("talos").collision_model.geometryObjects[0].meshPath
    assert mesh.lower().endswith(".stl") and not _ascii_stl(mesh)


# ------------------------------------------------------------------------------------ the hybrid leg: a fixed leg
def test_hybrid_leg_presses_its_foot_on_the_floor():
    """A fixed mechanism: its foot sphere alone on a floor put under it, the IK target 5 mm into the floor; the
    floating scenarios are refused. Without the contact the foot goes through and the row fails."""
    mech = load_ground("hybrid_leg")
    assert not mech.robot.floating and mech.ground.fixed_base
    names = [mech.model.geom(i).name for i in range(mech.model.ngeom) if mech.model.geom_contype[i]]
    assert names == ["foot_contact"]
    assert mech.model.geom("floor").pos[2] == pytest.approx(-0.041, abs=1e-12)  # FCS z - 0.018 at q0
    _passed(run_scenario(mech, "press", seconds=0.5))
    with pytest.raises(legkin.errors.InvalidParameterError, match="for a floating robot"):
        run_scenario(mech, "stand")
    mech.model.geom("foot_contact").contype[0] = 0
    res = run_scenario(mech, "press", seconds=0.5)
    assert not res.rows[0].passed
