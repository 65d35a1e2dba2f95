"""6-DOF legs (issue 26): the subproblems alone, leg discovery on example-robot-data's legged robots, FK and
Jacobian against Pinocchio, the closed-form IK (every sampled configuration among ik_all's solutions), the contract."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from legkin import legs
from legkin.errors import (
    InvalidArgumentError,
    InvalidInputError,
    JointLimitError,
    LegStructureError,
    UnreachableError,
)
from legkin.legs.checks6 import C_AMONG, TOL6
from legkin.legs.sixdof import Leg6

# The erd robots with legs: URDF relative to example-robot-data's robots/, expected structure and foot frames.
HUMANOIDS = {
    "talos": ("talos_data/robots/talos_reduced.urdf", "6R-spherical-hip", ("left_sole_link", "right_sole_link")),
    "romeo": ("romeo_description/urdf/romeo.urdf", "6R-spherical-hip", ("l_sole", "r_sole")),
    "icub": ("icub_description/robots/icub_reduced.urdf", "6R-spherical-hip", ("l_sole", "r_sole")),
    "simple_humanoid": ("simple_humanoid_description/urdf/simple_humanoid.urdf", "6R-spherical-hip",
                        ("l_ankle", "r_ankle")),
    "alexander": ("alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf", "6R-three-parallel",
                  ("LEFT_FOOT", "RIGHT_FOOT")),
    "g1": ("g1_description/urdf/g1_29dof_rev_1_0.urdf", "6R-offset-hip",
           ("left_ankle_roll_link", "right_ankle_roll_link")),
}
CLOSED = [n for n, (_, s, _) in HUMANOIDS.items() if s != "6R-general"]
#: FK and Jacobian agree with Pinocchio to this (measured: <= 1.1e-15 on 2000 configurations per leg).
TOL_FK = 1e-12
#: IK round trip (position m, rotation matrix entries); measured <= 5e-15.
TOL_IK = 1e-12


def _robots_dir():
    import importlib.metadata as md

    try:
        files = md.files("example-robot-data") or ()
    except md.PackageNotFoundError:
        pytest.skip("example-robot-data not installed")
    for f in files:
        s = str(f).replace("\\", "/")
        if s.endswith("talos_data/robots/talos_reduced.urdf"):
            return f.locate().resolve().parents[2]
    pytest.skip("example-robot-data's robots not found")


@pytest.fixture(scope="module")
def humanoids():
    root = _robots_dir()
    out = {}
    for name, (rel, _, _) in HUMANOIDS.items():
        model = pin.buildModelFromUrdf(str(root / rel))
        out[name] = (model, legs.from_model(model))
    return out


def _rand_unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def _rot(k, t, p):
    k, p = np.asarray(k), np.asarray(p)
    return math.cos(t) * p + math.sin(t) * np.cross(k, p) + (1 - math.cos(t)) * (k @ p) * k


# ------------------------------------------------------------------------------------------- subproblems alone
def test_subproblems_find_the_angles_they_were_built_from():
    """SP1-SP4 on random data built from known angles: the known angle is among the returned ones, and every
    returned angle satisfies its equation (to 1e-12)."""
    from legkin.legs import subproblems as sp

    rng = np.random.default_rng(7)
    for _ in range(200):
        k, k2, h = _rand_unit(rng), _rand_unit(rng), _rand_unit(rng)
        p1, p2 = rng.normal(size=3), rng.normal(size=3)
        t, t2 = rng.uniform(-math.pi, math.pi, 2)
        # SP1: R(k, t) p1 = q
        got = sp.sp1(tuple(p1), tuple(_rot(k, t, p1)), tuple(k))
        assert abs(math.remainder(got - t, 2 * math.pi)) < 1e-10
        # SP4: h . R(k, t) p1 = d
        d = h @ _rot(k, t, p1)
        n, ta, tb, miss = sp.sp4(tuple(h), tuple(p1), tuple(k), d)
        assert n == 2 and miss == 0.0
        assert min(abs(math.remainder(x - t, 2 * math.pi)) for x in (ta, tb)) < 1e-7
        for x in (ta, tb):
            assert abs(h @ _rot(k, x, p1) - d) < 1e-12
        # SP3: |R(k, t) p1 - p2| = d
        d = float(np.linalg.norm(_rot(k, t, p1) - p2))
        n, ta, tb, miss = sp.sp3(tuple(p1), tuple(p2), tuple(k), d)
        assert n == 2 and min(abs(math.remainder(x - t, 2 * math.pi)) for x in (ta, tb)) < 1e-7
        for x in (ta, tb):
            assert abs(np.linalg.norm(_rot(k, x, p1) - p2) - d) < 1e-12
        # SP2: R(k, t) p1 = R(k2, t2) p2 with p2 := R(k2, -t2) R(k, t) p1
        q2 = _rot(k2, -t2, _rot(k, t, p1))
        n, a1, a2, b1, b2, miss = sp.sp2(tuple(p1), tuple(q2), tuple(k), tuple(k2))
        assert n == 2 and miss < 1e-12
        pairs = [(a1, a2), (b1, b2)]
        assert min(abs(math.remainder(x - t, 2 * math.pi)) + abs(math.remainder(y - t2, 2 * math.pi))
                   for x, y in pairs) < 1e-6
        for x, y in pairs:
            assert np.abs(_rot(k, x, p1) - _rot(k2, y, q2)).max() < 1e-12


def test_subproblems_say_when_there_is_no_solution():
    from legkin.legs import subproblems as sp

    n, ta, tb, miss = sp.sp4((0.0, 0.0, 1.0), (1.0, 0.0, 0.5), (0.0, 0.0, 1.0), 0.7)  # h.p fixed at 0.5
    assert n == 0 and miss == pytest.approx(0.2)
    n, ta, tb, miss = sp.sp3((1.0, 0.0, 0.0), (3.0, 0.0, 0.0), (0.0, 0.0, 1.0), 0.5)  # circle r=1, sphere at 3
    assert n == 0 and miss > 0 and abs(math.remainder(ta, 2 * math.pi)) < 1e-12  # closest angle: 0
    # cones of directions z . x = 0.8 and x . x = 0.8: x_x^2 + x_z^2 = 1.28 > 1, they miss
    n, *_, miss = sp.sp2((0.6, 0.0, 0.8), (0.8, 0.0, 0.6), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0))
    assert n == 0 and miss > 0
    n, *_, miss = sp.sp2((1.0, 0.0, 0.0), (0.9, 0.0, 0.1), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0))  # |p1| != |p2|
    assert n == 2 and miss == pytest.approx(1.0 - math.hypot(0.9, 0.1))



def test_subproblems_near_the_axis():
    """A vector within ``beta`` (1e-12 to 1e-6 rad) of the rotation axis: SP1's angle to ``c eps / beta`` (the
    conditioning: the projections are ``beta`` long) and SP2's two sides equal to 1e-14 (a narrow cone). The former
    formulas (``p1 . p2 - (k . p1)(k . p2)``, ``1 - a^2 - b^2``) lost both below ``beta ~ 1e-8``: SP1 returned
    +-pi/2 and SP2's sides differed by ~1e-16 / beta."""
    from legkin.legs import subproblems as sp

    rng = np.random.default_rng(8)
    for _ in range(200):
        k, k1 = _rand_unit(rng), _rand_unit(rng)
        beta, t, t1 = 10 ** rng.uniform(-12, -6), rng.uniform(-math.pi, math.pi), rng.uniform(-math.pi, math.pi)
        side = np.cross(k, _rand_unit(rng))
        p = k + beta * side / np.linalg.norm(side)  # |p x k| = beta |p|, to rounding
        got = sp.sp1(tuple(p), tuple(_rot(k, t, p)), tuple(k))
        assert abs(math.remainder(got - t, 2 * math.pi)) < 1e-14 / beta
        # SP2 on the narrow cone of p about k: R(k1, t1) p1 = R(k, t) p with p1 := R(k1, -t1) R(k, t) p
        p1 = _rot(k1, -t1, _rot(k, t, p))
        n, a1, a2, b1, b2, miss = sp.sp2(tuple(p1), tuple(p), tuple(k1), tuple(k))
        assert n == 2 and miss < 1e-14
        for x, y in ((a1, a2), (b1, b2)):
            assert np.abs(_rot(k1, x, p1) - _rot(k, y, p)).max() < 1e-14

# ------------------------------------------------------------------------------------------- discovery
def test_every_erd_legged_robot_has_its_legs(humanoids):
    for name, (_, structure, feet) in HUMANOIDS.items():
        found = humanoids[name][1]
        assert len(found) == 2, name
        assert tuple(leg.foot_frame for leg in found.values()) == feet, name
        for leg in found.values():
            assert isinstance(leg, Leg6) and leg.dof == 6 and leg.structure == structure, (name, leg)
            assert leg.n_solutions == (8 if structure == "6R-spherical-hip" else 16)
    bolt = legs.from_urdf(_robots_dir() / "bolt_description/robots/bolt.urdf")
    assert list(bolt) == ["FL", "FR"] and all(leg.dof == 3 and leg.structure == "HAA-HFE-KFE" for leg in bolt.values())
    g1 = humanoids["g1"][1]
    assert list(g1) == ["left", "right"]
    assert g1["left"].hip_gap > 0.01  # g1's hip axes do not meet


def test_foot_frames_choose_and_errors(humanoids):
    model = humanoids["icub"][0]
    chosen = legs.from_model(model, foot_frames=["l_foot"])
    assert list(chosen.values())[0].foot_frame == "l_foot"
    with pytest.raises(LegStructureError, match=r"hangs from 5 joints.*l_ankle_pitch.*three revolute joints") as info:
        legs.from_model(model, foot_frames=["l_ankle_1"])  # the link between the ankle's pitch and roll
    assert info.value.expected and info.value.found


def _two_legs_without_prefix() -> pin.Model:
    """Two 6R legs with joint names sharing no prefix, hips at y = +-0.1 (the right leg first)."""
    model = pin.Model()
    axes = [pin.JointModelRZ(), pin.JointModelRX(), pin.JointModelRY(), pin.JointModelRY(), pin.JointModelRY(),
            pin.JointModelRX()]
    drops = [0.0, 0.0, 0.0, 0.3, 0.3, 0.0]
    k = 0
    for y in (-0.1, 0.1):
        parent = 0
        for j, (jm, dz) in enumerate(zip(axes, drops)):
            place = pin.SE3(np.eye(3), np.array([0.0, y if j == 0 else 0.0, -0.1 if j == 0 else -dz]))
            parent = model.addJoint(parent, jm, place, f"j{k}")
            model.addJointFrame(parent, -1)
            k += 1
        model.addFrame(pin.Frame(f"sole{y}", parent, 0, pin.SE3(np.eye(3), np.array([0.0, 0, -0.05])),
                                 pin.FrameType.OP_FRAME))
    return model


def test_legs_named_by_hip_position_when_names_share_no_prefix():
    found = legs.from_model(_two_legs_without_prefix())
    assert list(found) == ["right", "left"]
    assert found["left"].hip_centre[1] == pytest.approx(0.1) and found["left"].structure == "6R-spherical-hip"


# ------------------------------------------------------------------------------------------- against Pinocchio
def _pin_feet(model, leg, qs):
    data = model.createData()
    q = pin.neutral(model)
    fid = model.getFrameId(leg.foot_frame)
    poses, jacs = [], []
    for row in qs:
        q[list(leg.idx_q)] = row
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        poses.append(data.oMf[fid].homogeneous.copy())
        jacs.append(pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)[:, list(leg.idx_v)])
    return np.array(poses), np.array(jacs)


@pytest.mark.parametrize("name", list(HUMANOIDS))
def test_fk_and_jacobian_equal_pinocchio(humanoids, name):
    model, found = humanoids[name]
    rng = np.random.default_rng(26)
    for leg in found.values():
        qs = rng.uniform(leg.lower, leg.upper, (1000, 6))
        poses, jacs = _pin_feet(model, leg, qs)
        assert np.abs(leg.fk(qs) - poses).max() <= TOL_FK
        assert np.abs(leg.jacobian(qs) - jacs).max() <= TOL_FK
        np.testing.assert_array_equal(leg.fk(qs[3]), leg.fk(qs)[3])
        np.testing.assert_array_equal(leg.jacobian(qs[3]), leg.jacobian(qs)[3])


@pytest.mark.parametrize("name", CLOSED)
def test_ik_round_trip_and_every_sample_among_ik_all(humanoids, name):
    """2000 random in-limit configurations per leg (300 for alexander's and g1's search): every foot pose solved
    inside the limits, reproduced by Pinocchio to 1e-12; the sampled configuration is one of ik_all's rows (mod
    2 pi, to 1e-9 rad). (10^4 per leg: ``legkin check NAME --samples 10000``, docs/legs.md.)"""
    model, found = humanoids[name]
    rng = np.random.default_rng(2026)
    for leg in found.values():
        qs = rng.uniform(leg.lower, leg.upper, (2000 if leg.structure == "6R-spherical-hip" else 300, 6))
        poses, _ = _pin_feet(model, leg, qs)
        q, ok = leg.ik(poses, return_mask=True)
        assert ok.all() and leg.within_limits(q).all()
        back, _ = _pin_feet(model, leg, q)
        assert np.abs(back - poses).max() <= TOL_IK
        q_all, mask = leg.ik_all(poses, return_mask=True)
        gap = np.abs(np.angle(np.exp(1j * (q_all - qs[:, None])))).max(axis=-1)
        assert (np.nanmin(gap, axis=-1) < 1e-9).all(), f"{name} {leg.name}: {np.nanmax(np.nanmin(gap, axis=-1))}"
        assert q_all.shape[1] == leg.n_solutions
        rows = np.where(mask[..., None, None], leg.fk(np.where(mask[..., None], q_all, 0.0)), poses[:, None])
        assert np.abs(rows - poses[:, None]).max() <= TOL_IK


# Configurations of g1 whose pose the former search (values only; a dip searched only between three residuals of one
# sign; the cell next to a fold not searched as a fold piece) answered without them: (leg, q). Found among 1.2x10^6
# random in-limit samples (scripts/legs6_completeness.py, seeds 0-5): three roots of one branch within one or two
# grid cells (1.288, 1.338, 1.365 rad: the last two in a cell of equal signs next to a sign change), two roots next
# to a fold (-1.240, -1.192; the fold at -1.168) and, with the former fold pieces, a root pair just past a fold.
G1_HARD = [
    ("left", [1.3648258323893483, 1.421952643219817, 0.4300868859217344, 2.632745498827542, 0.393850636540216,
              -0.020157748549864296]),
    ("right", [1.4661079196463827, -1.9082633162269853, 2.7285233572745495, 2.634336126574655, 0.2943024216509683,
               -0.21571087280510182]),
    ("right", [2.747426697948167, -1.830275914370432, -0.40725328490809076, 2.5304646095900143, 0.3155722681704579,
               -0.009786902743819326]),
    ("right", [-0.5170864344997868, -2.7665777409890695, -0.07233502268122516, 2.3154546876764464, 0.4789473329076407,
               -0.03867249761789343]),
    ("right", [1.13788017089421, -0.41949789105806623, -0.09492911900820689, 2.840274346860594, 0.250065673994064,
               -0.09208924841430435]),
    ("right", [-0.9711568520925855, -1.6623347430354476, -0.13444482386886802, 2.0334889490046484,
               -0.8563088158761342, -0.1933749588269979]),
    ("right", [2.6928105652606047, 0.3412900896066948, 0.878334822765229, 2.407743788321199, 0.37201802336963874,
               0.11414204990341104]),
    ("left", [-1.1916899743019733, 1.7408105423760278, -1.7986324639164648, 0.13558160546371673, -0.3530828301160487,
              -0.1416325713490228]),
    ("left", [-0.01921321306382584, 1.5040716039226432, -2.6923048815584725, 2.5956774959491726, 0.4293418236666998,
              -0.08734179870004388]),
    ("left", [-2.4999678154930685, -0.2928376190676771, -0.41147713973934774, 0.011422869883202347,
              0.1391632551670895, 0.1739386418697555]),
    # near singular (the Jacobian's least singular value 2e-7, 2e-6): two solutions 3e-5 rad apart
    ("left", [-0.02624886536105242, 2.4351251129488793, 1.8680943856213847, 0.09678172566167552, 0.10908418989719015,
              -0.21852707772341645]),
    ("right", [0.22600143078079737, -1.6166417231176768, 0.8544492797391552, -0.06052979403473048,
               0.4330837294403024, 0.0704642424477297]),
]


def test_g1_search_finds_the_hard_configurations(humanoids):
    """Each of G1_HARD is among ik_all's rows: within 1e-9 rad, or within 1e-12 / sigma_min where the foot
    Jacobian's least singular value sigma_min says that the pose fixes the joints no better; every row reproduces the
    pose (Pinocchio) to 1e-12. And 3000 more random configurations per leg, the same."""
    model, found = humanoids["g1"]
    rng = np.random.default_rng(126)
    for name, leg in found.items():
        hard = np.array([q for n, q in G1_HARD if n == name])
        qs = np.vstack([hard, rng.uniform(leg.lower, leg.upper, (3000, 6))])
        poses, _ = _pin_feet(model, leg, qs)
        q_all, mask = leg.ik_all(poses, return_mask=True)
        gap = np.where(mask, np.abs(np.angle(np.exp(1j * (q_all - qs[:, None])))).max(axis=-1), np.inf).min(axis=-1)
        sigma = np.linalg.svd(leg.jacobian(qs), compute_uv=False)[:, -1]
        assert (gap <= np.maximum(1e-9, 1e-12 / sigma)).all(), (name, np.nonzero(gap > 1e-9)[0], gap.max())
        rows = np.where(mask[..., None, None], leg.fk(np.where(mask[..., None], q_all, 0.0)), poses[:, None])
        assert np.abs(rows - poses[:, None]).max() <= TOL_IK



def _onto_singular(leg, q, j, offset):
    """``q`` with joint ``j`` at the first sign change of ``det J`` over its range (bisection to rounding) plus
    ``offset`` (rad), or None where ``det J`` keeps its sign or the result leaves the limits."""
    ts = np.linspace(leg.lower[j], leg.upper[j], 65)
    qs = np.tile(q, (65, 1))
    qs[:, j] = ts
    det = np.linalg.det(leg.jacobian(qs))
    change = np.nonzero(np.sign(det[:-1]) != np.sign(det[1:]))[0]
    if not change.size:
        return None
    lo, hi, x = ts[change[0]], ts[change[0] + 1], q.copy()
    sign_lo = np.sign(det[change[0]])
    for _ in range(60):
        x[j] = 0.5 * (lo + hi)
        lo, hi = (x[j], hi) if np.sign(np.linalg.det(leg.jacobian(x))) == sign_lo else (lo, x[j])
    x[j] += offset
    return x if leg.lower[j] <= x[j] <= leg.upper[j] else None


# talos's right leg at `legkin check talos --random-seed 12 --samples 100000` (sample 11128): the foot Jacobian's
# least singular value 1.7e-7 (the hip centre near the ankle roll axis); the closed form landed 3e-5 rad off with
# the foot 2.4e-11 m off, and the polish refused the Newton step that raised |e| on its way to 1e-16.
TALOS_SEED12 = [-0.7362212244992524, 0.0737359027533665, -1.5476233002060773, 2.2934093908788378,
                0.25298900946910985, -0.432198460183028]


@pytest.mark.parametrize("name", ["talos", "simple_humanoid"])
def test_near_singular_poses_pass_every_check_row(humanoids, name):
    """The ``legkin check`` IK rows (checks6) on configurations 1e-9 to 1e-6 rad from a singular one (``det J``
    changes sign as the ankle pitch moves: the hip centre on the ankle roll axis; the knee: straight), least
    singular values down to ~1e-10: every pose solved to 1e-12 (measured <= 1.1e-15), the sampled configuration
    among ik_all's rows within the conditioning bound of checks6.C_AMONG. Failed before the subproblems' fix (talos:
    23 of 600 such poses unsolved, rows 5.7e-9 m off; the seed-12 sample 2.4e-11 m off)."""
    from legkin.legs._reference import pinocchio_poses
    from legkin.legs.checks6 import _ik_rows

    model, found = humanoids[name]
    rng = np.random.default_rng(25)
    qleg = np.stack([rng.uniform(leg.lower, leg.upper, (40, 6)) for leg in found.values()], axis=1)
    for i in range(qleg.shape[0]):
        for k, leg in enumerate(found.values()):
            near = _onto_singular(leg, qleg[i, k], 4 if i % 2 else 3, rng.choice([-1, 1]) * 10 ** rng.uniform(-9, -6))
            qleg[i, k] = qleg[i, k] if near is None else near
    if name == "talos":
        qleg[0, 1] = TALOS_SEED12
    sigma = np.linalg.svd(np.stack([leg.jacobian(qleg[:, k]) for k, leg in enumerate(found.values())]),
                          compute_uv=False)[..., -1]
    assert (sigma < 1e-6).sum() >= 20  # the set is near singular
    qs = np.tile(pin.neutral(model), (qleg.shape[0], 1))
    for k, leg in enumerate(found.values()):
        qs[:, list(leg.idx_q)] = qleg[:, k]
    poses, _ = pinocchio_poses(model, found, qs, False)
    for row in _ik_rows(model, found, qleg, poses):
        assert row.passed, row

# ------------------------------------------------------------------------------------------- contract
@pytest.fixture(scope="module")
def talos_left(humanoids):
    return humanoids["talos"][1]["leg_left"]


def test_single_batch_mask_and_shapes(talos_left):
    leg = talos_left
    rng = np.random.default_rng(3)
    qs = rng.uniform(leg.lower, leg.upper, (60, 6))
    poses = leg.fk(qs)
    poses[::5, 2, 3] -= 2.0  # 2 m lower: out of reach
    q, ok = leg.ik(poses.reshape(6, 10, 4, 4), return_mask=True)
    assert q.shape == (6, 10, 6) and ok.shape == (6, 10)
    ok = ok.ravel()
    assert not ok[::5].any() and ok.sum() == 48 and np.isnan(q.reshape(60, 6)[::5]).all()
    q_all = leg.ik_all(poses)
    assert q_all.shape == (60, 8, 6) and np.isnan(q_all[::5]).all()
    for i in (1, 2, 7):
        np.testing.assert_array_equal(leg.ik(poses[i]), q.reshape(60, 6)[i])
        np.testing.assert_array_equal(leg.ik_all(poses[i]), q_all[i])
        np.testing.assert_array_equal(leg.ik(poses[i], q_near=qs[i]), leg.ik(poses, q_near=qs)[i])
    with pytest.raises(UnreachableError, match="out of reach") as info:
        leg.ik(poses[0])
    assert info.value.distance > 1.0
    with pytest.raises(UnreachableError):
        leg.ik_all(poses[0])
    one, m1 = leg.ik(poses[1], return_mask=True)
    assert one.shape == (6,) and bool(m1)


def test_q_near_picks_the_solution_and_joint_limit_error(talos_left):
    leg = talos_left
    rng = np.random.default_rng(4)
    q = rng.uniform(leg.lower, leg.upper, 6)
    q_all, mask = leg.ik_all(leg.fk(q), return_mask=True)
    inside = [b for b in range(8) if mask[b] and leg.within_limits(q_all[b])]
    for b in inside:
        np.testing.assert_allclose(leg.ik(leg.fk(q), q_near=q_all[b] + 1e-3), q_all[b], atol=1e-9)
    # a pose from joints outside the limits, reachable only outside them
    bad = np.array([0.0, 0.0, -0.3, -1.0, 0.2, 0.0])  # knee bent backwards: the knee's lower limit is 0
    sols = leg.ik_all(leg.fk(bad))
    if not any(leg.within_limits(s) for s in sols if np.isfinite(s).all()):
        with pytest.raises(JointLimitError, match="only outside the joint limits"):
            leg.ik(leg.fk(bad))


def _in_limit_rows(leg, q_all, mask, near):
    """Each row of ``q_all`` (n, K, 6) with each angle at its 2 pi representative inside the limits nearest ``near``
    (n, 6), the cost ``|x - near|^2`` of each row (inf when an angle has none) and how far (rad) each row lies
    outside the limits at least."""
    x = q_all[..., None] + 2.0 * np.pi * np.arange(-1, 2)  # (n, K, 6, 3)
    lo, hi = leg.lower[:, None], leg.upper[:, None]
    out = np.maximum(np.maximum(lo - x, x - hi), 0.0).min(-1).max(-1)
    d = np.where((x >= lo) & (x <= hi), np.abs(x - near[:, None, :, None]), np.inf)
    rep = np.take_along_axis(x, d.argmin(-1)[..., None], -1)[..., 0]
    cost = np.where(np.isfinite(d.min(-1)).all(-1) & mask, ((rep - near[:, None]) ** 2).sum(-1), np.inf)
    return rep, cost, np.where(mask, out, np.inf)


@pytest.mark.parametrize("name", ["talos", "romeo", "icub", "simple_humanoid"])
def test_ik_is_the_in_limit_row_of_ik_all_nearest_q_near(humanoids, name):
    """``ik`` builds only the closed form's branches inside the limits (a branch dropped at its first joint outside)
    and checks the cheapest first: its answer is the row of ``ik_all`` moved inside the limits nearest ``q_near``
    (least sum of squares), on 600 targets per leg (half from joints inside the limits, half from up to 0.5 rad
    outside them), with ``q_near`` random inside them; a target whose every row lies 1e-3 rad or more outside the
    limits is refused."""
    _, found = humanoids[name]
    rng = np.random.default_rng(11)
    for leg in found.values():
        wide = np.repeat([[0.0], [0.5]], 300, axis=0)  # half from joints inside the limits, half from up to 0.5 out
        qs = rng.uniform(leg.lower - wide, leg.upper + wide, (600, 6))
        near = rng.uniform(leg.lower, leg.upper, (600, 6))
        poses = leg.fk(qs)
        q, ok = leg.ik(poses, q_near=near, return_mask=True)
        q_all, mask = leg.ik_all(poses, return_mask=True)
        rep, cost, out = _in_limit_rows(leg, q_all, mask, near)
        two = np.sort(cost, axis=-1)[:, :2]
        clear = np.isfinite(two[:, 0]) & ~(two[:, 1] <= two[:, 0] + 1e-6)  # one nearest row, not a tie
        far = mask.any(-1) & (out >= 1e-3).all(-1)
        assert clear.sum() >= 250 and far.sum() >= 100, (clear.sum(), far.sum())  # measured >= 300, >= 276
        best = rep[np.arange(len(q)), cost.argmin(-1)]
        assert ok[clear].all()
        np.testing.assert_allclose(q[clear], best[clear], atol=1e-9)
        assert not ok[far].any()


def test_tol_solves_a_pose_just_out_of_reach(talos_left):
    """The default tol (IK_TOL = 1e-7) solves a pose 5e-8 beyond full stretch at its nearest pose, refuses one 1e-6
    beyond; a tighter tol refuses the first, a looser one solves the second."""
    leg = talos_left
    stretched = leg.fk(np.zeros(6))  # the straight leg: the reach boundary
    near, beyond = stretched.copy(), stretched.copy()
    near[2, 3] -= 5e-8
    beyond[2, 3] -= 1e-6  # 1 um beyond full stretch
    q = leg.ik(near)
    assert np.linalg.norm(leg.fk(q)[:3, 3] - near[:3, 3]) == pytest.approx(5e-8, rel=1e-3)
    with pytest.raises(UnreachableError):
        leg.ik(near, tol=1e-9)
    with pytest.raises(UnreachableError):
        leg.ik(beyond)
    with pytest.raises(UnreachableError):
        leg.ik_all(beyond)
    q = leg.ik(beyond, tol=1e-5)
    assert np.linalg.norm(leg.fk(q)[:3, 3] - beyond[:3, 3]) == pytest.approx(1e-6, rel=1e-3)


def test_float32_poses_are_solved_with_the_default_tol(talos_left):
    """4x4 foot poses of in-limit joints rounded to float32 (position and rotation block): every one solved with the
    default tol, the answer within IK_TOL of the rounded pose (the bound of legs._layout.IK_TOL: <= 8.2e-8)."""
    leg = talos_left
    rng = np.random.default_rng(33)
    t32 = leg.fk(rng.uniform(leg.lower, leg.upper, (2000, 6))).astype(np.float32).astype(float)
    q, ok = leg.ik(t32, return_mask=True)
    assert ok.all()
    back = leg.fk(q)
    assert np.linalg.norm(back[:, :3, 3] - t32[:, :3, 3], axis=-1).max() <= legs.kinematics.IK_TOL
    assert np.abs(back[:, :3, :3] - t32[:, :3, :3]).max() <= legs.kinematics.IK_TOL


@pytest.mark.parametrize("bad, match", [
    (np.eye(3), r"shape \(\.\.\., 4, 4\)"),
    (np.full((4, 4), np.nan), "finite"),
    (np.diag([1.0, 1.0, 2.0, 1.0]), "homogeneous"),
    (np.vstack([np.eye(4)[:3], [0.0, 0.0, 1.0, 1.0]]), "homogeneous"),
    ("T", "numeric"),
])
@pytest.mark.parametrize("method", ["ik", "ik_all"])
def test_bad_targets_raise_legkin_errors(talos_left, bad, match, method):
    with pytest.raises(InvalidInputError, match=match):
        getattr(talos_left, method)(bad)


def test_bad_options_and_no_closed_form(talos_left, humanoids):
    t = talos_left.fk(np.zeros(6))
    with pytest.raises(InvalidArgumentError, match="tol"):
        talos_left.ik(t, tol=0.0)
    with pytest.raises(InvalidArgumentError, match="return_mask"):
        talos_left.ik_all(t, return_mask="yes")
    with pytest.raises(InvalidInputError, match="q"):
        talos_left.fk([0.0] * 5)
    with pytest.raises(InvalidInputError, match="q_near"):
        talos_left.ik(t, q_near=[0.0] * 3)
    rng = np.random.default_rng(8)  # six skew axes: no structure legkin solves
    general = Leg6.from_geometry("X", [f"j{i}" for i in range(6)], "foot", rng.normal(size=(6, 3)),
                                 rng.normal(size=(6, 3)), np.eye(4), -np.ones(6), np.ones(6))
    assert general.structure == "6R-general" and general.n_solutions == 0
    with pytest.raises(LegStructureError, match="no IK for its structure") as info:
        general.ik(general.fk(np.zeros(6)))
    assert info.value.found == "6R-general"


# ------------------------------------------------------------------------------------------- the squat clip
@pytest.mark.parametrize("name, deep", [("talos", True), ("g1", True), ("romeo", False), ("simple_humanoid", False)])
def test_squat_keeps_the_soles_on_the_floor(name, deep):
    """``legkin view NAME --animate squat --floating``: the pelvis goes squat_depth down and back (SQUAT_DEPTH where
    the legs can; romeo and simple_humanoid stand near their limits: less, but some), every sole stays flat where it
    was (Pinocchio's oMf, 1e-9), every frame inside the joint limits."""
    import legkin
    from legkin.legs.clips import SQUAT_DEPTH, squat, squat_depth

    robot = legkin.load(name, floating=True)
    depth = squat_depth(robot)
    assert (depth == SQUAT_DEPTH) == deep and depth >= SQUAT_DEPTH / 4
    qs = np.array(squat(robot))
    data = robot.model.createData()
    soles = []
    for q in qs:
        pin.framesForwardKinematics(robot.model, data, q)
        soles.append([data.oMf[robot.model.getFrameId(leg.foot_frame)].homogeneous.copy()
                      for leg in robot.geometry.values()])
    soles = np.array(soles)
    assert np.abs(soles - soles[0]).max() <= 1e-9
    assert abs(soles[0, :, 2, 3].min()) <= 1e-12  # the lowest sole on the floor
    assert qs[0, 2] - qs[:, 2].min() == pytest.approx(depth, rel=1e-3)
    assert all(leg.within_limits(qs[:, list(leg.idx_q)]).all() for leg in robot.geometry.values())


#: g1 configurations near its singular poses (``sigma_min`` 2e-5 to 2e-4) whose solution the search missed, from
#: ``scripts/check_sweep.py g1 --sizes 100000`` (seed, leg, sample): a pair of roots 1e-3 to 1e-2 rad apart in one
#: cell of equal signs, next to a fold, settled as empty by the curvature bound (docs/legs.md: ``DOUBT``).
G1_NEAR_SINGULAR = {
    "seed10-right-52108": ("right", [-0.4708061459872095, -2.6792596632099066, -0.08803088448631424,
                                     2.5658381763361047, 0.3586799140289244, -0.12171823946636393]),
    "seed15-left-77844": ("left", [1.0359140685471755, -0.44394727450113936, -0.12678564108442636,
                                   2.732228581934333, 0.2935541820372122, -0.06130810766009231]),
    "seed16-right-48801": ("right", [-1.4930337583698596, -1.6539886248438063, -0.01513341255087086,
                                     2.784339035106442, 0.26776232440908776, -0.00558007000458272]),
    "seed19-left-54107": ("left", [-0.06180974889635049, 2.8375129912270967, 0.14080683878461864,
                                   2.4090013945978104, 0.4341763716595738, 0.16126967674642362]),
    "seed19-left-98538": ("left", [-1.0622088788833608, 2.598281362685622, 0.28145932803413576,
                                   2.3737128383516586, 0.4510226309844406, -0.08442099868805683]),
    "seed19-right-56788": ("right", [2.544362993695828, -1.7474332779590753, 1.9854445967387608,
                                     0.20996556862923282, -0.5215367570965774, 0.2216784969569356]),
}


@pytest.mark.parametrize("case", list(G1_NEAR_SINGULAR))
def test_g1_near_singular_solutions_are_found(humanoids, case):
    """Each configuration's pose: ``ik`` solves it, and the configuration is among ``ik_all``'s rows by the check's
    criterion (``gap * sigma_min <= C_AMONG * TOL6``; each was 2e-6 to 2e-4 before ``DOUBT``)."""
    model, found = humanoids["g1"]
    side, q = G1_NEAR_SINGULAR[case]
    leg, q = found[side], np.array(q)
    pose, _ = _pin_feet(model, leg, q[None])
    q_all, mask = leg.ik_all(pose[0], return_mask=True)
    gap = np.where(mask, np.abs(np.angle(np.exp(1j * (q_all - q)))).max(axis=-1), np.inf).min()
    assert gap * np.linalg.svd(leg.jacobian(q), compute_uv=False)[-1] <= C_AMONG * TOL6
    back, _ = _pin_feet(model, leg, leg.ik(pose[0])[None])
    assert np.abs(back[0] - pose[0]).max() <= TOL6


def test_an_approximate_row_is_dropped_when_the_pose_is_reached_exactly(humanoids):
    """alexander's left leg at ``legkin check alexander --random-seed 17 --samples 100000`` (sample 52919): beside
    its two exact solutions, the search's stretched-knee candidate polishes to a least-squares point of its branch
    (knee 1e-16 rad, ``sigma_min`` 5e-17) that reproduces the pose to 7.7e-9 only, within ``IK_TOL``. The pose is
    reached exactly, so that row is not a solution: ``ik_all`` lists only rows that reproduce it to ``TOL6``, and
    the sampled configuration is among them (the check's "IK all solutions" row failed at 7.7e-9)."""
    model, found = humanoids["alexander"]
    leg = found["LEFT"]
    q = np.array([0.13357090545303052, 0.01863643929939512, -0.9046069022273362, 1.0630389338814212,
                  -0.00654516423748386, -0.2550224657563013])
    pose, _ = _pin_feet(model, leg, q[None])
    q_all, mask = leg.ik_all(pose[0], return_mask=True)
    back, _ = _pin_feet(model, leg, q_all[mask])
    assert np.abs(back - pose[0]).max() <= TOL6
    gap = np.where(mask, np.abs(np.angle(np.exp(1j * (q_all - q)))).max(axis=-1), np.inf).min()
    assert gap * np.linalg.svd(leg.jacobian(q), compute_uv=False)[-1] <= C_AMONG * TOL6


def test_g1_seventeenth_candidate_is_kept(humanoids):
    """g1's left leg at ``legkin check g1 --random-seed 7 --samples 100000`` (sample 83926): its pose has 16
    solutions, and the search finds one of them twice (two candidates 1e-10 apart that polish to one row), so a list
    of 16 candidates lost the 17th candidate, the sampled configuration (the nearest row was 1.47 rad away,
    sigma_min 0.019). Found by ``scripts/check_sweep.py`` at 10^5 samples (seeds 10, 15, 16, 19 failed too). The
    candidates now have room for twice K, and a row polished onto an earlier one is dropped."""
    model, found = humanoids["g1"]
    leg = found["left"]
    q = np.array([2.5902614147125917, 0.0353202021090927, 0.021342084094692737, 2.8377100853976733,
                  0.012355532885298115, -0.13981258397011176])
    pose, _ = _pin_feet(model, leg, q[None])
    q_all, mask = leg.ik_all(pose[0], return_mask=True)
    gap = np.where(mask, np.abs(np.angle(np.exp(1j * (q_all - q)))).max(axis=-1), np.inf).min()
    assert gap * np.linalg.svd(leg.jacobian(q), compute_uv=False)[-1] <= 3e-12
    rows = q_all[mask]
    apart = np.abs(np.angle(np.exp(1j * (rows[:, None] - rows[None])))).max(axis=-1)
    assert (apart[~np.eye(len(rows), dtype=bool)] > 1e-9).all()  # no solution listed twice
