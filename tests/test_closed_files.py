"""Robots from their own files (issue 27): Gepetto's example-parallel-robots (URDF + robot.yaml), URDF
``<loop_closure>``, xacro, MJCF equalities; closing from neutral; closed_fk / closed_jacobian / closed_ik."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import legkin
from legkin.closing import CLOSED_TOL, loop_errors
from legkin.errors import InvalidInputError, LoopClosureError
from legkin.loaders import load_file
from legkin.loaders.checks import determined_frames, jacobian_fd_error, reachable_motors
from legkin.mjcf.roundtrip import mjcf_round_trip_error

DATA = Path(__file__).parent / "data" / "example-parallel-robots"
CLOSING = ["5bar_linkage", "5bar_linkage_iso3d", "cassie_like", "digit_like", "digit_like_2legs", "disney_like",
           "robot_delta", "talos_like", "wl16_like"]
#: Measured (scripts/closed_loop_report.py): mobility (all joints free) and idle mobility (motors held) at q0.
MOBILITY = {"5bar_linkage": (3, 1), "5bar_linkage_iso3d": (2, 0), "cassie_like": (7, 2), "digit_like": (9, 3),
            "digit_like_2legs": (12, 0), "disney_like": (9, 3), "robot_delta": (5, 3), "talos_like": (7, 1),
            "wl16_like": (12, 6)}
SAMPLES = 20


def _worst(robot, q) -> float:
    return max(e.worst for e in loop_errors(robot.model, robot.data, robot.loops, q))


@pytest.fixture(scope="module", params=CLOSING)
def robot(request):
    return legkin.load(str(DATA / request.param / "robot.urdf"))


def test_loads_and_closes_from_neutral(robot):
    assert isinstance(robot, legkin.Robot)
    assert robot.actuated and robot.actuated == tuple(robot.actuated_joints)
    q = robot.solve_loops()  # from neutral
    assert _worst(robot, q) <= CLOSED_TOL
    assert np.max(np.abs(robot.constraint_residual(q))) <= CLOSED_TOL  # Pinocchio's residual agrees
    assert _worst(robot, robot.q0) <= CLOSED_TOL
    mob, idle = MOBILITY[robot.name]
    assert (robot.mobility(robot.q0), robot.idle_mobility()) == (mob, idle)
    assert robot.load_seconds < 1.0


def test_closed_fk_jacobian_ik(robot):
    rng = np.random.default_rng(1)
    motors, qs = reachable_motors(robot, SAMPLES, rng)
    iq, _ = robot._motor_index()
    for m in motors:
        q = robot.closed_fk(m)
        assert np.max(np.abs(q[iq] - m)) <= 1e-12
        assert _worst(robot, q) <= CLOSED_TOL
    frame = determined_frames(robot, robot.q0)[-1]  # not a frame on a rod spinning idly
    assert jacobian_fd_error(robot, qs[0], frame) <= 1e-6
    target = robot.frame_placement(qs[1], frame)
    qi = robot.closed_ik(frame, target)
    assert _worst(robot, qi) <= CLOSED_TOL
    # the compiled solve reaches it (the target as one more loop), not only the Levenberg-Marquardt fallback
    assert robot._ik_compiled(robot.frame_id(frame), target, target.translation, robot.q0) is not None
    assert np.linalg.norm(pin.log6(target.actInv(robot.frame_placement(qi, frame))).vector) <= CLOSED_TOL


def test_mjcf_round_trip(robot):
    assert mjcf_round_trip_error(robot) <= CLOSED_TOL


def test_closed_jacobian_shape_and_idle_motion():
    robot = legkin.load(DATA / "cassie_like" / "robot.urdf")
    jac = robot.closed_jacobian(robot.q0, "closedloop2_B")
    assert jac.shape == (6, len(robot.actuated))
    # the idle mobility (rods spinning) does not move: closed_fk at the motors of q0 returns q0 itself
    q = robot.closed_fk(robot.q0[robot._motor_index()[0]])
    assert np.max(np.abs(q - robot.q0)) <= 1e-12


def test_kangaroo_like_is_misaligned_not_a_hard_start():
    """kangaroo_like loads, but its loops do not close: LoopClosureError names each open loop with m and rad, and
    the loops whose 6d frames cannot coincide are told apart ("misaligned") from a hard start, quickly: each loop
    alone by the compiled solve, and Levenberg-Marquardt (minutes on its 63 joints) skipped once one is misaligned."""
    robot = legkin.load(DATA / "kangaroo_like" / "robot.urdf")
    assert isinstance(robot.closing, LoopClosureError)
    t0 = time.process_time()
    with pytest.raises(LoopClosureError) as info:
        robot.solve_loops()
    seconds = time.process_time() - t0
    text = str(info.value)
    open_names = [e.name for e in info.value.open_loops if e.worst > CLOSED_TOL]
    assert open_names and all(f"{n} (" in text for n in open_names)
    assert " m, " in text and " rad" in text
    assert "misaligned: its origins meet" in text and "closes alone" in text
    assert "misaligned frames, not a hard start (Levenberg-Marquardt skipped)" in text
    assert seconds < 10.0, f"{seconds:.1f} s of CPU time to give up"


def test_loop_closure_urdf_xacro_and_yaml_agree(tmp_path):
    from legkin.loaders.convert import convert

    base = legkin.load(DATA / "cassie_like" / "robot.urdf")
    urdf = convert(DATA / "cassie_like" / "robot.urdf", tmp_path / "cassie.urdf")
    xacro = tmp_path / "cassie.urdf.xacro"
    shutil.copy(urdf, xacro)
    yaml = convert(urdf, tmp_path / "loops.yaml")
    for r in (legkin.load(urdf), legkin.load(xacro), legkin.load(DATA / "cassie_like" / "robot.urdf", loops=yaml)):
        assert r.loops == base.loops and r.actuated == base.actuated
        assert _worst(r, r.q0) <= CLOSED_TOL


def test_missing_meshes_still_load(tmp_path):
    full = legkin.load(DATA / "5bar_linkage" / "robot.urdf")
    assert full.missing_meshes == [] and full.visual_model.ngeoms > 0
    shutil.copy(DATA / "5bar_linkage" / "robot.urdf", tmp_path / "robot.urdf")
    shutil.copy(DATA / "5bar_linkage" / "robot.yaml", tmp_path / "robot.yaml")
    bare = legkin.load(tmp_path / "robot.urdf")
    assert bare.missing_meshes and all(m.endswith(".stl") for m in bare.missing_meshes)
    assert np.allclose(bare.q0, full.q0, atol=1e-12)


def test_view_names_missing_meshes(tmp_path, capsys):
    from legkin.__main__ import main

    shutil.copy(DATA / "5bar_linkage" / "robot.urdf", tmp_path / "robot.urdf")
    shutil.copy(DATA / "5bar_linkage" / "robot.yaml", tmp_path / "robot.yaml")
    assert main(["view", str(tmp_path / "robot.urdf"), "--html", str(tmp_path / "v.html")]) == 0
    assert "package:///rod.stl" in capsys.readouterr().err


YAML_CASES = [
    ("closed_loop: [[a, b]\n", "not valid YAML"),
    ("closed_loop: [['closedloop1_A', 'nope']]\ntype: ['6d']\nname_mot: ['mot1']\n", "'closed_loop[0][1]'"),
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: ['6d']\nname_mot: ['mot9']\n", "'name_mot[0]'"),
    ("closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: ['4d']\nname_mot: ['mot1']\n", "'type[0]'"),
    ("closed_loop: []\nname_mot: []\njoint_name: ['mot1']\njoint_type: ['HELICAL']\n", "'joint_type[0]'"),
    ("closed_loop: []\nname_mot: []\njoint_name: ['nope']\njoint_type: ['SPHERICAL']\n", "'joint_name[0]'"),
    ("closed_loops: []\n", "'closed_loops'"),
]


@pytest.mark.parametrize("text, key", YAML_CASES)
def test_bad_yaml_names_file_key_value(tmp_path, text, key):
    yaml = tmp_path / "bad.yaml"
    yaml.write_text(text)
    with pytest.raises(InvalidInputError) as info:
        load_file(DATA / "5bar_linkage" / "robot.urdf", loops=yaml)
    assert str(yaml) in str(info.value) and key in str(info.value)


def test_mjcf_body_form_equality(tmp_path):
    """An MJCF whose equality names bodies (anchors computed by Pinocchio) and has two top-level bodies."""
    xml = tmp_path / "fourbar.xml"
    xml.write_text("""<mujoco><worldbody>
  <body name="a"><joint name="ja" type="hinge" axis="0 0 1"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
    <body name="b" pos="1 0 0"><joint name="jb" type="hinge" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></body>
  <body name="c" pos="2 0 0"><joint name="jc" type="hinge" axis="0 0 1"/>
    <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
    <body name="d" pos="0 1 0"><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></body>
</worldbody><equality><connect name="tip" body1="b" body2="c" anchor="1 0 0"/></equality>
<actuator><position joint="ja"/></actuator></mujoco>""")
    robot = legkin.load(xml)
    assert robot.actuated == ("ja",) and [lp.type for lp in robot.loops] == ["point"]
    assert robot.model.nq == 3 and _worst(robot, robot.q0) <= CLOSED_TOL


def test_single_and_batch_rule():
    robot = legkin.load(DATA / "cassie_like" / "robot.urdf")
    motors, qs = reachable_motors(robot, 3, np.random.default_rng(2))
    far = robot.q0[robot._motor_index()[0]].copy()
    far[4] += 2.0  # motor_ankle 2 rad from q0: the loops no longer close (measured: 1.5 rad still does)
    batch = np.stack([motors[0], far, motors[1]]).reshape(3, 1, -1)
    q, mask = robot.closed_fk(batch, return_mask=True)
    assert q.shape == (3, 1, robot.model.nq) and mask.tolist() == [[True], [False], [True]]
    assert np.all(np.isnan(q[1])) and np.allclose(q[0, 0], robot.closed_fk(motors[0]), atol=1e-12)
    with pytest.raises(LoopClosureError, match="closed_fk"):
        robot.closed_fk(far)
    with pytest.raises(InvalidInputError):
        robot.closed_fk(motors[0][:-1])
    for i in (0, robot._motor_index()[0][0]):  # a passive and a motor coordinate of q_near: refused, not overwritten
        near = robot.q0.copy()
        near[i] = np.inf
        with pytest.raises(InvalidInputError, match="q_near"):
            robot.closed_fk(motors[0], near)
    with pytest.raises(InvalidInputError, match="motors must be finite"):
        robot.closed_fk(np.r_[np.nan, motors[0][1:]])
    jac, ok = robot.closed_jacobian(qs[:2], "closedloop2_B", return_mask=True)
    assert jac.shape == (2, 6, len(robot.actuated)) and ok.all()
    assert np.allclose(jac[1], robot.closed_jacobian(qs[1], "closedloop2_B"))
    targets = np.array([robot.frame_placement(q, "closedloop2_B").translation for q in qs[:2]] + [[9.0, 9.0, 9.0]])
    qi, ok = robot.closed_ik("closedloop2_B", targets, return_mask=True)
    assert ok.tolist() == [True, True, False] and np.all(np.isnan(qi[2]))
    for q, t in zip(qi[:2], targets[:2]):
        assert np.linalg.norm(robot.frame_placement(q, "closedloop2_B").translation - t) <= CLOSED_TOL
    with pytest.raises(legkin.UnreachableError):
        robot.closed_ik("closedloop2_B", targets[2])


def test_cli_check_convert_export(tmp_path, capsys):
    from legkin.__main__ import main

    urdf = str(DATA / "talos_like" / "robot.urdf")
    assert main(["check", urdf, "--samples", "5"]) == 0
    out = capsys.readouterr().out
    assert "MJCF round trip" in out and "closed_fk unsolved fraction" in out and "all checks passed" in out
    assert main(["convert", urdf, str(tmp_path / "talos.urdf")]) == 0
    assert main(["convert", str(tmp_path / "talos.urdf"), str(tmp_path / "talos.yaml")]) == 0
    assert "closedloop1_B" in (tmp_path / "talos.yaml").read_text()
    assert main(["export", urdf, "--mjcf", str(tmp_path / "talos.xml")]) == 0
    assert main(["convert", str(tmp_path / "talos.xml"), str(tmp_path / "back.yaml")]) == 0
    assert main(["convert", urdf, str(tmp_path / "talos.txt")]) == 2
    assert "unknown output form '.txt'" in capsys.readouterr().err
    assert main(["convert", str(DATA / "digit_like_2legs" / "robot.urdf"), str(tmp_path / "d.urdf")]) == 2
    assert "replaces joints" in capsys.readouterr().err


@pytest.mark.parametrize("reference", ["LOCAL_WORLD_ALIGNED", "LOCAL", "WORLD"])
def test_closed_jacobian_kernel_matches_pinocchio(robot, reference):
    """The compiled closed_jacobian against the same formula on Pinocchio's frame and constraint Jacobians
    (measured: <= 2.3e-13 on these robots; tolerance 1e-11)."""
    _, qs = reachable_motors(robot, 1, np.random.default_rng(3))
    frame = robot.model.frames[robot.model.nframes - 1].name
    _, _, iv, passive = robot._compiled()
    jf, jc = robot.frame_jacobian(qs[0], frame, reference), robot.constraint_jacobian(qs[0])
    expected = jf[:, iv] - jf[:, passive] @ np.linalg.pinv(jc[:, passive], rcond=1e-10) @ jc[:, iv]
    assert np.max(np.abs(robot.closed_jacobian(qs[0], frame, reference) - expected)) <= 1e-11


@pytest.mark.parametrize("kind, flip", [("point", "0 0 0"), ("frame", "0 0 0"), ("frame", "3.141592653589793 0 0")])
def test_six_d_frames_that_cannot_coincide_are_misaligned(tmp_path, monkeypatch, kind, flip):
    """legkin's planar four-bar, cut at D: as a point loop it closes; as a 6d loop it cannot (three parallel
    revolute joints cannot bring both the origins and the orientations together: 0.1 m stays), and with one cut
    frame flipped by 180 degrees about x (its z axis against the other's) the angle left is pi: both are told
    "misaligned", not a hard start."""
    import legkin.closing as closing

    monkeypatch.setattr(closing, "RESTARTS", 2)
    text = (Path(__file__).parent / "data" / "fourbar.urdf").read_text()
    text = text.replace('type="point"', f'type="{kind}"').replace(
        '<origin xyz="0.2 0 0"/>', f'<origin xyz="0.2 0 0" rpy="{flip}"/>')
    (tmp_path / "fourbar.urdf").write_text(text)
    robot = legkin.load(tmp_path / "fourbar.urdf")
    if kind == "point":
        assert _worst(robot, robot.solve_loops()) <= CLOSED_TOL
        return
    with pytest.raises(LoopClosureError, match=r"D \(.* m, .* rad: misaligned") as info:
        robot.solve_loops()
    assert "compiled Gauss-Newton from 3 starts" in str(info.value)  # the direct start and RESTARTS = 2
    assert "misaligned frames, not a hard start (Levenberg-Marquardt skipped)" in str(info.value)
    assert info.value.open_loops[0].angle == pytest.approx(np.pi if flip != "0 0 0" else 0.0, abs=1e-6)
