"""legkin.legs: closed-form HAA-HFE-KFE leg IK measured from any URDF (issue 13)."""

from __future__ import annotations

import importlib.metadata
import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import assume, example, given
from hypothesis import strategies as st

from legkin import errors, legs
from legkin._registry import get_spec
from legkin.errors import (
    InvalidInputError,
    InvalidParameterError,
    JointLimitError,
    LegkinError,
    UnknownModelError,
    UnreachableError,
)
from legkin.legs import LegStructureError

ROBOTS = tuple(legs.ERD_ROBOTS)
TOL = 1e-12


@pytest.fixture(scope="module")
def erd():
    """``{robot: (model, {leg: Leg})}`` for the nine example-robot-data quadrupeds."""
    out = {}
    for name in ROBOTS:
        model = legs.load_erd(name)[0]
        out[name] = (model, legs.from_model(model))
    return out


def pin_feet(model, found: dict, qleg: np.ndarray) -> np.ndarray:
    """Pinocchio's feet (N, L, 3) (world = root frame: the base at its neutral pose) for leg joints (N, L, 3)."""
    data = model.createData()
    fids = [model.getFrameId(leg.foot_frame) for leg in found.values()]
    idx = [list(leg.idx_q) for leg in found.values()]
    q = pin.neutral(model)
    out = np.empty(qleg.shape)
    for i in range(len(qleg)):
        for k, ix in enumerate(idx):
            q[ix] = qleg[i, k]
        pin.forwardKinematics(model, data, q)
        for k, fid in enumerate(fids):
            out[i, k] = pin.updateFramePlacement(model, data, fid).translation
    return out


def random_in_limits(found: dict, n: int, rng) -> np.ndarray:
    return np.stack([rng.uniform(leg.lower, leg.upper, (n, 3)) for leg in found.values()], axis=1)


# ------------------------------------------------------------------------------------------- the nine robots
def test_erd_files_come_from_the_installed_distribution():
    dist = importlib.metadata.distribution("example-robot-data")
    base = Path(dist.locate_file("")).resolve()
    assert len(ROBOTS) == 9
    assert set(ROBOTS) == {"solo12", "anymal", "anymal_c", "hyq", "go1", "go2", "a1", "b1", "laikago"}
    assert set(ROBOTS) < set(legs.ERD_ALL) and all(get_spec(n).package == "legkin.legs" for n in legs.ERD_ALL)
    for name in ROBOTS:
        spec = get_spec(name)  # a first-class registry entry of the shared package legkin.legs
        assert spec.package == "legkin.legs" and spec.shared_package and not spec.generated
        urdf, srdf, package_dirs = spec.locate(name)
        assert (urdf, srdf, package_dirs) == legs.erd_files(name)
        assert urdf.is_file() and base in urdf.parents
        assert (srdf is None) == (name == "laikago")
        if srdf is not None:
            assert srdf.is_file()
            assert spec.reference_pose == "standing"
        # package://example-robot-data/... resolves in the first package dir
        assert (Path(package_dirs[0]) / "example-robot-data" / "robots").is_dir()
        model, path, dirs = legs.load_erd(name)
        assert isinstance(model, pin.Model) and Path(path) == urdf and dirs == package_dirs
        q = legs.reference_configuration(model, name)
        assert q.shape == (model.nq,)
    with pytest.raises(UnknownModelError, match="known: solo12"):
        legs.load_erd("spot")


@pytest.mark.parametrize("name", ROBOTS)
def test_four_legs_and_fk_jacobian_match_pinocchio(erd, name):
    model, found = erd[name]
    assert len(found) == 4
    assert len({leg.foot_frame for leg in found.values()}) == 4
    for leg in found.values():
        assert all(model.existJointName(j) for j in leg.joint_names)
        assert model.existFrame(leg.foot_frame)
        assert leg.idx_q == tuple(model.joints[model.getJointId(j)].idx_q for j in leg.joint_names)
    rng = np.random.default_rng(1)
    qleg = random_in_limits(found, 300, rng)
    feet = pin_feet(model, found, qleg)
    data = model.createData()
    q = pin.neutral(model)
    for k, leg in enumerate(found.values()):
        assert np.abs(leg.fk(qleg[:, k]) - feet[:, k]).max() <= TOL
        jac = leg.jacobian(qleg[:, k])
        fid = model.getFrameId(leg.foot_frame)
        for i in range(0, 300, 10):
            q[list(leg.idx_q)] = qleg[i, k]
            pin.computeJointJacobians(model, data, q)
            pin.updateFramePlacements(model, data)
            ref = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)[:3, list(leg.idx_v)]
            assert np.abs(jac[i] - ref).max() <= TOL


@pytest.mark.parametrize("name", ROBOTS)
def test_ik_round_trip_10k_per_robot(erd, name):
    """Every foot of 10^4 random in-limit configurations is solved inside the URDF limits, and Pinocchio's FK of
    the answer reproduces it to 1e-12 m; every branch of ik_all reproduces it too."""
    model, found = erd[name]
    rng = np.random.default_rng(2024)
    qleg = random_in_limits(found, 10_000, rng)
    feet = pin_feet(model, found, qleg)
    answers = np.empty_like(qleg)
    for k, leg in enumerate(found.values()):
        q, ok = leg.ik(feet[:, k], return_mask=True)
        assert ok.all(), f"{name} {leg.name}: {int((~ok).sum())} targets unsolved"
        assert np.all((q >= leg.lower) & (q <= leg.upper))
        answers[:, k] = q
        q_all, mask = leg.ik_all(feet[:300, k], return_mask=True)
        assert mask.any(axis=-1).all()
        for b in range(4):
            rows = mask[:, b]
            assert np.abs(leg.fk(q_all[rows, b]) - feet[:300][rows, k]).max(initial=0.0) <= TOL
    back = pin_feet(model, found, answers)
    err = np.linalg.norm(back - feet, axis=-1)
    assert err.max() <= TOL, f"{name}: max IK round-trip error {err.max():.3g} m"


def test_extracted_geometry_of_known_robots(erd):
    _, go2 = erd["go2"]
    fl = go2["FL"]
    assert fl.joint_names == ("FL_hip_joint", "FL_thigh_joint", "FL_calf_joint") and fl.foot_frame == "FL_foot"
    assert fl.axis_labels == ("+x", "+y", "+y") and fl.knee_sign == 1.0
    assert fl.lateral_offset == pytest.approx(0.0955, abs=1e-12)
    assert fl.thigh_length == pytest.approx(0.213) and fl.shank_length == pytest.approx(0.213)
    assert go2["FR"].lateral_offset == pytest.approx(-0.0955, abs=1e-12)
    hyq = erd["hyq"][1]
    assert hyq["lf"].axis_labels == ("-x", "+y", "+y")  # a rotated joint frame: the HAA axis points backwards
    assert hyq["lf"].joint_names[0] == "lf_haa_joint"
    anymal_c = erd["anymal_c"][1]
    assert anymal_c["LF"].axis_labels[1] == "+y"  # its HFE is an RX joint in a rotated frame
    assert erd["anymal"][1]["LF"].foot_frame == "LF_FOOT"  # BODY frame preferred over LF_ADAPTER_TO_FOOT
    for name in ROBOTS:
        for leg in erd[name][1].values():
            s = leg.summary()
            assert s["thigh_length"] > 0.1 and s["shank_length"] > 0.1
            assert abs(leg.frame @ leg.frame.T - np.eye(3)).max() < 1e-15


def test_named_leg_and_from_urdf(erd):
    model, found = erd["go1"]
    leg = legs.from_model(model, "RR")
    assert isinstance(leg, legs.Leg) and leg.joint_names == found["RR"].joint_names
    assert legs.from_model(model, "RR_hip_joint").name == "RR"
    assert legs.from_model(model, "RR_foot").name == "RR"
    with pytest.raises(InvalidParameterError, match="no leg 'XX'.*FL"):
        legs.from_model(model, "XX")
    urdf = legs.erd_files("go1")[0]
    fixed = legs.from_urdf(urdf)
    assert list(fixed) == list(found)
    p = found["FL"].fk(np.array([0.1, 0.7, -1.5]))
    np.testing.assert_allclose(fixed["FL"].fk(np.array([0.1, 0.7, -1.5])), p, atol=1e-15)
    assert fixed["FL"].idx_q == (0, 1, 2)
    by_frame = legs.from_model(model, foot_frames=["FL_foot_fixed"])
    assert list(by_frame) == ["FL"] and by_frame["FL"].foot_frame == "FL_foot_fixed"
    with pytest.raises(InvalidParameterError, match="nope"):
        legs.from_model(model, foot_frames=["nope"])
    with pytest.raises(LegStructureError, match="three revolute joints"):
        legs.from_model(model, foot_frames=["FL_thigh"])  # hangs from only two joints
    with pytest.raises(InvalidParameterError, match="does not exist"):
        legs.from_urdf("/nonexistent/robot.urdf")
    with pytest.raises(InvalidParameterError, match="pinocchio.Model"):
        legs.from_model("go1")


# ------------------------------------------------------------------------------------------- synthetic legs
def _rot(rpy) -> np.ndarray:
    return pin.rpy.rpyToMatrix(*map(float, rpy))


def build_leg(
    rpy=((0.0, 0.0, 0.0),) * 3,
    t=((0.2, 0.1, 0.0), (0.05, 0.08, -0.02), (0.01, 0.02, -0.25)),
    foot=(0.02, -0.01, -0.24),
    a1=(1.0, 0.0, 0.0),
    perp=0.3,
    s3=1.0,
    tilt_hfe_deg=0.0,
    tilt_kfe_deg=0.0,
    limits=(-math.pi, math.pi),
    floating=False,
):
    """A one-leg Pinocchio model: three RevoluteUnaligned joints in rotated frames (rpy, t relative to the parent),
    root-frame axes a1, a2 (perpendicular to a1, at angle ``perp`` about it), a3 = s3 a2; ``tilt_*`` tilts the
    HFE axis off perpendicular / the KFE axis off parallel by that many degrees."""
    model = pin.Model()
    parent = 0
    if floating:
        parent = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")
    a1 = np.asarray(a1, float) / np.linalg.norm(a1)
    helper = np.array([0.0, 0.0, 1.0]) if abs(a1[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    b = np.cross(a1, helper)
    b /= np.linalg.norm(b)
    c = np.cross(a1, b)
    a2 = math.cos(perp) * b + math.sin(perp) * c
    a2t = math.cos(math.radians(tilt_hfe_deg)) * a2 + math.sin(math.radians(tilt_hfe_deg)) * a1
    other = np.cross(a1, a2)
    a3 = s3 * (math.cos(math.radians(tilt_kfe_deg)) * a2t + math.sin(math.radians(tilt_kfe_deg)) * other)
    rots = [_rot(r) for r in rpy]
    world = np.eye(3)
    ids = []
    for k, (axis, name) in enumerate(zip((a1, a2t, a3), ("X_HAA", "X_HFE", "X_KFE"))):
        world = world @ rots[k]
        local = world.T @ axis
        jm = pin.JointModelRevoluteUnaligned(local / np.linalg.norm(local))
        parent = model.addJoint(parent, jm, pin.SE3(rots[k], np.asarray(t[k], float)), name)
        model.addJointFrame(parent, -1)
        ids.append(parent)
    model.addFrame(pin.Frame("X_FOOT", parent, pin.SE3(np.eye(3), np.asarray(foot, float)), pin.FrameType.OP_FRAME))
    lo = model.lowerPositionLimit.copy()
    hi = model.upperPositionLimit.copy()
    for j in ids:
        lo[model.joints[j].idx_q], hi[model.joints[j].idx_q] = limits
    model.lowerPositionLimit, model.upperPositionLimit = lo, hi
    return model


def test_tilted_pitch_axis_raises_clear_error():
    with pytest.raises(LegStructureError, match=r"HFE axis \(X_HFE.*is 0\.3 deg off parallel to the KFE axis"):
        legs.from_model(build_leg(tilt_kfe_deg=0.3))
    with pytest.raises(LegStructureError, match=r"HAA axis \(X_HAA.*is 2 deg off perpendicular to the HFE axis"):
        legs.from_model(build_leg(tilt_hfe_deg=2.0))
    with pytest.raises(LegStructureError, match="off parallel"):
        legs.from_model(build_leg(tilt_kfe_deg=1e-6))  # 1.7e-8 rad > 1e-9
    assert LegStructureError is errors.LegStructureError and issubclass(LegStructureError, (LegkinError, ValueError))
    legs.from_model(build_leg(tilt_kfe_deg=1e-9))  # 1.7e-11 rad: within the 1e-9 tolerance
    with pytest.raises(LegStructureError, match="foot.*lies on the KFE axis"):
        legs.from_model(build_leg(foot=(0.0, 0.0, 0.0), t=((0.2, 0.1, 0.0), (0.05, 0.08, -0.02), (0.0, 0.0, -0.25))))


def test_no_leg_found():
    model = pin.Model()
    j = model.addJoint(0, pin.JointModelRY(), pin.SE3.Identity(), "only")
    model.addJointFrame(j, -1)
    with pytest.raises(LegStructureError, match=r"no leg found.*Found: only \(RY\): 1 joints.*Supported: HAA") as info:
        legs.from_model(model)
    assert info.value.found == ["only (RY): 1 joints, ends at a leaf, foot frame 'only'"]
    assert any("HAA-HFE-KFE" in e for e in info.value.expected) and any("6R" in e for e in info.value.expected)


angles = st.floats(-math.pi, math.pi, allow_nan=False)
offsets = st.floats(-0.25, 0.25, allow_nan=False)


@given(
    rpy=st.tuples(*[st.tuples(angles, angles, angles)] * 3),
    t=st.tuples(st.tuples(offsets, offsets, offsets), st.tuples(offsets, offsets, offsets),
                st.tuples(offsets, offsets, offsets)),
    foot=st.tuples(offsets, offsets, offsets),
    a1=st.tuples(offsets, offsets, offsets),
    perp=angles,
    s3=st.sampled_from([-1.0, 1.0]),
    floating=st.booleans(),
    tilt=st.tuples(st.floats(-5e-8, 5e-8), st.floats(-5e-8, 5e-8)),
    seed=st.integers(0, 2**32 - 1),
)
@example(rpy=((0.0, 0.0, 0.0),) * 3, t=((0.2, 0.1, 0.0), (0.05, 0.08, -0.02), (0.01, 0.02, -0.25)),
         foot=(0.02, -0.01, -0.24), a1=(1.0, 0.0, 0.0), perp=0.3, s3=-1.0, floating=True, tilt=(0.0, 0.0), seed=0)
def test_general_leg_matches_pinocchio(rpy, t, foot, a1, perp, s3, floating, tilt, seed):
    """Any geometry: rotated joint frames, HAA axis off the HFE origin, pitch-plane offsets, any axis signs, and
    axes off perpendicular / parallel by up to 5e-8 deg (8.7e-10 rad, inside the 1e-9 structure tolerance: the
    polishing steps make the IK exact on them too)."""
    assume(np.linalg.norm(a1) > 0.05)
    model = build_leg(rpy, t, foot, a1, perp, s3, tilt_hfe_deg=tilt[0], tilt_kfe_deg=tilt[1], floating=floating)
    try:
        leg = legs.from_model(model, "X")
    except LegStructureError as exc:  # only a degenerate thigh/shank may be refused
        assert "length" in str(exc) or "lies on" in str(exc)
        return
    assume(min(leg.thigh_length, leg.shank_length) > 0.02)
    rng = np.random.default_rng(seed)
    q = rng.uniform(-math.pi, math.pi, (40, 3))
    found = {"X": leg}
    feet = pin_feet(model, found, q[:, None])[:, 0]
    np.testing.assert_allclose(leg.fk(q), feet, atol=TOL, rtol=0)
    sol, ok = leg.ik(feet, return_mask=True)
    assert ok.all()
    back = pin_feet(model, found, sol[:, None])[:, 0]
    assert np.linalg.norm(back - feet, axis=-1).max() <= TOL
    q_all, mask = leg.ik_all(feet, return_mask=True)
    # the sampled q is one of the branches (mod 2 pi), unless a singularity merges them
    d = np.abs(np.angle(np.exp(1j * (q_all - q[:, None, :])))).max(axis=-1)
    assert (np.nanmin(d, axis=-1) < 1e-6).mean() > 0.9


# ------------------------------------------------------------------------------------------- the contract
@pytest.fixture(scope="module")
def fl(erd):
    return erd["go2"][1]["FL"]


BAD = [
    ([np.nan, 0.0, 0.0], "finite"),
    ([0.0, np.inf, 0.0], "finite"),
    (np.array([1 + 1j, 0, 0]), "complex"),
    ([0.1, 0.2], r"shape \(\.\.\., 3\)"),
    (np.zeros((4, 2)), r"shape \(\.\.\., 3\)"),
    (0.3, r"shape \(\.\.\., 3\)"),
    ("abc", "numeric"),
    ([[0.1, 0.2, 0.3], [0.1, 0.2]], "numeric"),
    (None, "numeric"),
    ([[0.1, 0.2, 0.3], [0.1, np.nan, 0.3]], "finite"),
]


@pytest.mark.parametrize("bad, match", BAD)
@pytest.mark.parametrize("method", ["fk", "jacobian", "ik", "ik_all"])
def test_bad_inputs_raise_legkin_errors(fl, bad, match, method):
    with pytest.raises(InvalidInputError, match=match):
        getattr(fl, method)(bad)


def test_bad_options_raise_legkin_errors(fl):
    p = fl.fk(np.array([0.0, 0.8, -1.5]))
    with pytest.raises(InvalidParameterError, match="return_mask"):
        fl.ik(p, return_mask="yes")
    with pytest.raises(InvalidInputError, match="q_near"):
        fl.ik(p, q_near=[0.0, 1.0])
    with pytest.raises(InvalidInputError, match="q_near.*finite"):
        fl.ik(p, q_near=[0.0, np.nan, 1.0])
    with pytest.raises(InvalidInputError, match="broadcast"):
        fl.ik(np.tile(p, (3, 1)), q_near=np.zeros((2, 3)))
    assert issubclass(InvalidInputError, ValueError)


@given(st.lists(st.tuples(st.floats(0, 1), st.floats(0, 1), st.floats(0, 1)), min_size=1, max_size=300),
       st.integers(0, 299), st.sampled_from(["go2", "solo12", "anymal_c", "hyq"]))
def test_single_call_equals_batch_row(erd, rows, i, name):
    leg = next(iter(erd[name][1].values()))
    u = np.array(rows)
    q = leg.lower + u * (leg.upper - leg.lower)
    p = leg.fk(q) + np.where(u > 0.9, 0.3, 0.0)  # some targets out of reach
    i = i % len(q)
    np.testing.assert_array_equal(leg.fk(q[i]), leg.fk(q)[i])
    np.testing.assert_array_equal(leg.jacobian(q[i]), leg.jacobian(q)[i])
    sol, ok = leg.ik(p, return_mask=True)
    all_b, mask = leg.ik_all(p, return_mask=True)
    if ok[i]:
        np.testing.assert_array_equal(leg.ik(p[i]), sol[i])
        np.testing.assert_array_equal(leg.ik(p[i], q_near=q[i]), leg.ik(p, q_near=q)[i])
    else:
        assert np.isnan(sol[i]).all()
        with pytest.raises(UnreachableError):
            leg.ik(p[i])
    if mask[i].any():
        one, one_mask = leg.ik_all(p[i], return_mask=True)
        np.testing.assert_array_equal(one, all_b[i])
        np.testing.assert_array_equal(one_mask, mask[i])


def test_big_batch_equals_single_calls_and_shapes(fl):
    from legkin.legs._fk_kernels import _fk_batch
    from legkin.legs._ik_kernels import _ik_batch

    rng = np.random.default_rng(3)
    n = 1000 * ((max(_ik_batch.min_parallel, _fk_batch.min_parallel) + 999) // 1000)  # the parallel loops
    q = rng.uniform(fl.lower, fl.upper, (n, 3))
    p = fl.fk(q)
    sol = fl.ik(p)
    for i in range(0, n, 397):
        np.testing.assert_array_equal(fl.ik(p[i]), sol[i])
    assert fl.fk(q[:1000].reshape(10, 100, 3)).shape == (10, 100, 3)
    assert fl.jacobian(q[:1000].reshape(10, 100, 3)).shape == (10, 100, 3, 3)
    s, ok = fl.ik(p[:1000].reshape(10, 100, 3), return_mask=True)
    assert s.shape == (10, 100, 3) and ok.shape == (10, 100)
    a, m = fl.ik_all(p[:1000].reshape(10, 100, 3), return_mask=True)
    assert a.shape == (10, 100, 4, 3) and m.shape == (10, 100, 4)
    assert fl.ik(np.empty((0, 3))).shape == (0, 3)
    one, ok1 = fl.ik(p[0], return_mask=True)
    assert one.shape == (3,) and ok1.shape == () and bool(ok1)
    # a single target with a batch of q_near is a batch
    assert fl.ik(p[0], q_near=q[:5]).shape == (5, 3)


def test_unreachable_nan_mask_and_error(fl):
    far = fl.origin + np.array([0.0, 0.0, -1.0])  # 1 m below the hip: beyond full stretch 0.426 m
    inside = fl.origin.copy()  # on the HAA axis: inside the abduction cylinder (|d| = 0.0955 m)
    good = fl.fk(np.array([0.1, 0.9, -1.6]))
    p = np.stack([good, far, inside])
    q, ok = fl.ik(p, return_mask=True)
    assert ok.tolist() == [True, False, False]
    assert np.isfinite(q[0]).all() and np.isnan(q[1:]).all()
    q_all, mask = fl.ik_all(p, return_mask=True)
    assert mask[0].any() and not mask[1:].any() and np.isnan(q_all[1:]).all()
    with pytest.raises(UnreachableError, match=r"out of reach of leg FL by 0\.5.* m: .*beyond the leg's full stretch"):
        fl.ik(far)
    with pytest.raises(UnreachableError, match=r"by 0\.0955 m: .*inside the abduction cylinder"):
        fl.ik(inside)
    with pytest.raises(UnreachableError):
        fl.ik_all(far, return_mask=True)
    try:
        fl.ik(far)
    except UnreachableError as exc:
        assert not isinstance(exc, JointLimitError)
        np.testing.assert_array_equal(exc.target, far)


def test_joint_limit_error(fl):
    rng = np.random.default_rng(5)
    q = rng.uniform(-math.pi, math.pi, (2000, 3))
    p = fl.fk(q)
    _, ok = fl.ik(p, return_mask=True)
    q_all, mask = fl.ik_all(p, return_mask=True)
    only_outside = ~ok & mask.any(axis=-1)
    assert only_outside.sum() > 10
    for i in np.flatnonzero(only_outside)[:5]:
        with pytest.raises(JointLimitError, match="reachable only outside the joint limits"):
            fl.ik(p[i])
        # every branch really is outside the limits (mod 2 pi)
        for b in np.flatnonzero(mask[i]):
            for n in (-1, 0, 1):
                assert not fl.within_limits(q_all[i, b] + 2 * math.pi * n)


def test_q_near_picks_the_branch(erd):
    leg = erd["solo12"][1]["FL"]  # limits +-10 rad: every branch is inside
    p = leg.fk(np.array([0.2, 0.7, -1.4]))
    q_all, mask = leg.ik_all(p, return_mask=True)
    assert mask.all()
    for b in range(4):
        near = q_all[b] + 0.01
        np.testing.assert_allclose(leg.ik(p, q_near=near), q_all[b], atol=1e-12)
    # far from the limits' middle: the 2 pi representative nearest q_near inside +-10
    np.testing.assert_allclose(leg.ik(p, q_near=q_all[1] + 2 * math.pi), q_all[1] + 2 * math.pi, atol=1e-12)


def _nearest_inside(q_all: np.ndarray, ref: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """The rule of ``Leg.ik`` written plainly (numpy, per target): each branch's angles at their 2 pi
    representative inside the limits nearest ``ref`` (NaN if none), the branch with the least squared distance."""
    out = np.full(ref.shape, np.nan)
    for i in range(len(ref)):
        best = math.inf
        for q in q_all[i]:
            reps = q[:, None] + 2 * math.pi * np.arange(-3, 4)[None, :]  # (3, 7) candidates per joint
            inside = (reps >= lower[:, None]) & (reps <= upper[:, None])
            if not np.isfinite(q).all() or not inside.any(axis=1).all():
                continue
            x = np.array([r[m][np.argmin(np.abs(r[m] - ref[i, j]))] for j, (r, m) in enumerate(zip(reps, inside))])
            cost = float(np.sum((x - ref[i]) ** 2))
            if cost < best:
                best, out[i] = cost, x
    return out


@pytest.mark.parametrize("name", ["go2", "solo12", "anymal"])
def test_limits_first_ik_is_the_nearest_branch_inside_the_limits(erd, name):
    """The limits-first kernel (branches pruned by the limits and the partial cost before any polish, only the
    winner polished) returns what the plain rule picks among all of ik_all's branches, for random q_near."""
    _, found = erd[name]
    rng = np.random.default_rng(7)
    for leg in found.values():
        q = rng.uniform(np.clip(leg.lower, -4, 4), np.clip(leg.upper, -4, 4), (400, 3))
        p = leg.fk(q)
        ref = q + rng.normal(0.0, 0.8, q.shape)
        got, ok = leg.ik(p, q_near=ref, return_mask=True)
        want = _nearest_inside(leg.ik_all(p, q_near=ref), ref, leg.lower, leg.upper)
        assert ok.all()
        np.testing.assert_allclose(got, want, atol=1e-9, err_msg=f"{name} {leg.name}")
        one = leg.ik(p[0], q_near=ref[0])  # the single-call fast path with q_near: the batch row
        np.testing.assert_array_equal(one, got[0])


def test_atan2_kernel_within_two_ulp_of_atan2():
    """The IK's ``_atan2_k`` (one ``atan`` of a ratio <= 1, plus ``+-pi`` or ``+-pi/2``) against numpy's ``arctan2``:
    within 2 ulp of the result (the ratio's rounding, 0.5 ulp, scaled by ``|u| / ((1 + u^2) atan u)`` <= 1; glibc's
    ``atan``, < 1 ulp; the sum with the rounded ``pi`` or ``pi/2``, 0.5 ulp; measured: 1 ulp), on magnitudes over 11
    decades in all four quadrants and next to the diagonal ``|y| = |x|`` where the two formulas meet; and the same
    value as ``math.atan2``, signed zero included, on the axes, zeros, infinities and NaN."""
    import numba

    from legkin.legs._ik_kernels import _atan2_k

    @numba.njit(error_model="numpy")
    def many(y, x, out):
        for i in range(y.shape[0]):
            out[i] = _atan2_k(y[i], x[i])

    rng = np.random.default_rng(3)
    n = 200_000
    sign = lambda: rng.choice([-1.0, 1.0], n)  # noqa: E731
    y = np.concatenate([sign() * 10.0 ** rng.uniform(-8, 3, n), rng.uniform(-1, 1, n)])
    x = np.concatenate([sign() * 10.0 ** rng.uniform(-8, 3, n), sign() * y[n:] * (1 + rng.normal(0, 1e-12, n))])
    got = np.empty(2 * n)
    many(y, x, got)
    want = np.arctan2(y, x)
    assert (np.abs(got - want) <= 2 * np.spacing(np.abs(want))).all()
    special = (0.0, -0.0, 1.0, -1.0, 1e-300, math.inf, -math.inf, math.nan)
    ys, xs = (np.array(v) for v in zip(*[(a, b) for a in special for b in special]))
    got = np.empty(ys.shape)
    many(ys, xs, got)
    want = np.array([math.atan2(a, b) for a, b in zip(ys, xs)])
    same = (got == want) & (np.signbit(got) == np.signbit(want)) | np.isnan(got) & np.isnan(want)
    assert same.all(), list(zip(ys[~same], xs[~same], got[~same], want[~same]))


def _well_conditioned_rows(leg, p: np.ndarray) -> np.ndarray:
    """(n, 4): whether each ik_all branch is away from the abduction singularity and the knee's fold by the
    factor WELL_CONDITIONED (``t >= c r``, ``|w| >= c (|k| + |l|)``), from the leg's public geometry."""
    from legkin.legs._layout import WELL_CONDITIONED as c

    e1, e2, e3 = leg.frame
    v = p - leg.origin
    x1, y, z = v @ e1, v @ e2, v @ e3
    r = np.hypot(y, z)
    t = np.sqrt(np.maximum(r * r - leg.lateral_offset**2, 0.0))
    rows = []
    for s_a in (-1.0, -1.0, 1.0, 1.0):  # BRANCHES order (s_a, s_k)
        w = np.hypot(s_a * t - leg.hip_offset[0], x1 - leg.hip_offset[1])
        rows.append((t >= c * r) & (w >= c * (leg.thigh_length + leg.shank_length)))
    return np.stack(rows, axis=-1)


@pytest.mark.parametrize("name", ["quadruped", "go2", "solo12", "anymal", "go1", "a1", "b1", "laikago"])
def test_well_conditioned_branches_are_exact_without_polish(erd, name):
    """On legs whose axes are exactly the ideal structure, a well-conditioned closed-form branch is returned without
    the Newton polish: its foot error must stay below POLISH_BELOW (what the polish would aim for), on joint
    vectors uniform in [-3.2, 3.2]^3 (every branch; every robot whose axes are exactly ideal: anymal_c's and hyq's
    are 4.9e-12 rad off and always polished); the others (polished) within REACH_TOL."""
    from legkin.legs._layout import POLISH_BELOW, REACH_TOL

    if name == "quadruped":
        from legkin.quadruped.measured import legs as popi

        found = popi()
    else:
        found = erd[name][1]
    rng = np.random.default_rng(11)
    for leg in found.values():
        assert leg.axis_deviation == (0.0, 0.0)
        p = leg.fk(rng.uniform(-3.2, 3.2, (20_000, 3)))
        q_all, mask = leg.ik_all(p, return_mask=True)
        err = np.linalg.norm(leg.fk(np.where(mask[..., None], q_all, 0.0)) - p[:, None], axis=-1)
        well = _well_conditioned_rows(leg, p) & mask
        assert well.mean() > 0.9
        assert err[well].max() <= POLISH_BELOW, f"{name} {leg.name}: {err[well].max():.3g} m unpolished"
        assert err[mask].max() <= REACH_TOL


# ------------------------------------------------------------------------------------------- legkin's POPI quadruped
def _aq():
    """legkin's own quadruped closed form, wherever it lives now: ``(fk(q, leg), ik(p, leg, q_near))``."""
    try:
        from legkin.quadruped import kinematics as aq
    except ImportError:
        from legkin.analytic import quadruped as aq
    if hasattr(aq, "fk") and hasattr(aq, "ik"):
        return aq.fk, lambda p, leg, q: aq.ik(p, leg, q_near=q)
    return aq.foot_position, lambda p, leg, q: aq.foot_ik(p, leg, q_ref=q)


def test_popi_quadruped_legs_agree_with_its_closed_form(quadruped):
    fk, ik = _aq()
    found = legs.from_model(quadruped.model)
    assert sorted(found) == ["LF", "LH", "RF", "RH"]
    rng = np.random.default_rng(7)
    for name, leg in found.items():
        assert leg.joint_names == (f"{name}_HAA", f"{name}_HFE", f"{name}_KFE") and leg.foot_frame == f"{name}_FOOT"
        q = rng.uniform(leg.lower, leg.upper, (2000, 3))
        p = fk(q, name)
        np.testing.assert_allclose(leg.fk(q), p, atol=TOL, rtol=0)
        mine = leg.ik(p, q_near=q)
        theirs = ik(p, name, q)
        assert np.abs(mine - theirs).max() < 1e-8
        assert np.linalg.norm(fk(mine, name) - p, axis=-1).max() <= TOL


# ------------------------------------------------------------------------------------------- check rows and bench
def test_checks_run_rows_pass():
    from legkin.legs import checks

    rows = checks.run("go2", 300, np.random.default_rng(0))
    assert len(rows) == 4 and all(r.passed for r in rows), [(r.name, r.max_error) for r in rows]
    assert "1200/1200 solved" in rows[2].name


def test_bench_build_quick_rows():
    from legkin import bench
    from legkin.legs.bench import build

    mb = build("go2", None, np.random.default_rng(0), True)
    results = {r.name: r for r in bench.run_model(mb, quiet=True)}
    names = [m.name for m in mb.methods]
    assert names[:3] == ["legkin Leg.ik batch (closed form; 1000 at once)", "legkin Leg.ik single calls (Python loop)",
                         "pinocchio CLIK (damped Newton, 3 leg joints)"]
    assert any("ikpy" in nm for nm in names) and any("ik_LM" in nm for nm in names)
    for nm in names[:2]:
        assert results[nm].solved == 100.0 and results[nm].max_error < 1e-12
    assert results[names[0]].targets == 1000 and results[names[2]].targets == 100
    for m in mb.methods:  # a peer is timed or skipped with its reason
        assert (m.name in results) != (m.skip is not None)
        if m.name in results:
            assert results[m.name].targets >= 1 and results[m.name].time_per_target_s > 0
    text = bench.format_table("go2", mb, list(results.values()))
    assert "time/target" in text and "FL_foot" in text


def test_bench_cli_external_robot(capsys):
    from legkin.__main__ import main

    assert main(["bench", "solo12", "--quick", "--n", "50", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "solo12" in out and "legkin Leg.ik batch" in out and "FL_FOOT" in out


# ------------------------------------------------------------------------------------------- clips
@pytest.mark.parametrize("name", ROBOTS)
def test_feet_circles_clip_traces_the_circles(name):
    import legkin
    from legkin.legs.clips import ANIMATIONS, FRAMES, RADIUS

    robot = legkin.load(name)
    assert robot.model.nq == 12
    qs = np.array(ANIMATIONS["feet_circles"](robot))
    assert qs.shape == (FRAMES, 12) and np.isfinite(qs).all()
    found = robot.geometry
    # every reference pose is in limits (laikago has no SRDF: legkin's standing pose, legs.erd.standing_pose)
    assert all(leg.within_limits(robot.q0[list(leg.idx_q)]) for leg in found.values())
    np.testing.assert_allclose(qs[0], robot.q0, atol=1e-12, rtol=0)
    data = robot.model.createData()
    fids = [robot.model.getFrameId(leg.foot_frame) for leg in found.values()]
    feet = np.empty((FRAMES, len(fids), 3))
    for i, q in enumerate(qs):
        pin.framesForwardKinematics(robot.model, data, q)
        feet[i] = [data.oMf[f].translation for f in fids]
    t = 2.0 * np.pi * np.arange(FRAMES) / FRAMES
    circle = RADIUS * np.stack([np.sin(t), 0.0 * t, 1.0 - np.cos(t)], -1)  # forward-up-back-down, from frame 0
    np.testing.assert_allclose(feet, feet[:1] + circle[:, None], atol=1e-12, rtol=0)
    for leg in found.values():
        assert leg.within_limits(qs[:, list(leg.idx_q)]).all()
    assert np.abs(np.diff(qs, axis=0)).max() < 0.2  # continuous: each frame near the previous one


def test_view_animate_feet_circles_html(tmp_path):
    from legkin.__main__ import main

    out = tmp_path / "g.html"
    assert main(["view", "go2", "--animate", "feet_circles", "--html", str(out)]) == 0
    assert out.stat().st_size > 1000


def test_quadruped_check_has_the_generic_leg_rows():
    from legkin.quadruped import checks as qc

    rows = qc.run(100, np.random.default_rng(1))
    generic = [r for r in rows if r.name.startswith("legs.Leg: ")]
    assert len(generic) == 4 and all(r.passed for r in generic), [(r.name, r.max_error) for r in generic]
    assert "400/400 solved" in generic[2].name
    assert len(rows) > len(generic)  # the quadruped's own rows are all still there


def test_ik_all_returns_solutions_and_mask_only_when_asked(fl):
    """legkin 0.2.0: ``ik_all`` returns the solutions; ``(solutions, mask)`` only with ``return_mask=True``; the
    single-target fast path gives the batch row bit for bit."""
    rng = np.random.default_rng(11)
    p = fl.fk(rng.uniform(fl.lower, fl.upper, (50, 3)))
    q_all = fl.ik_all(p)
    assert isinstance(q_all, np.ndarray) and q_all.shape == (50, 4, 3)
    both, mask = fl.ik_all(p, return_mask=True)
    np.testing.assert_array_equal(both, q_all)
    np.testing.assert_array_equal(mask, np.isfinite(q_all[..., 0]))
    for i in range(0, 50, 7):
        np.testing.assert_array_equal(fl.ik_all(p[i]), q_all[i])
        one, m1 = fl.ik_all(p[i], return_mask=True)
        assert m1.shape == (4,) and m1.dtype == bool
        np.testing.assert_array_equal(m1, mask[i])
    with pytest.raises(InvalidParameterError, match="return_mask"):
        fl.ik_all(p[0], return_mask=1)


# ------------------------------------------------------------------------------------------- issue 26: URDF gaps
def test_continuous_joints_are_legs_with_unbounded_limits(tmp_path):
    """go1's URDF with every joint ``continuous`` (as public aliengo / mini_cheetah descriptions write them): the same
    legs, infinite limits, the same forward map, and IK answers nearest q_near with no limit to respect."""
    text = legs.erd_files("go1")[0].read_text()
    urdf = tmp_path / "go1_continuous.urdf"
    urdf.write_text(text.replace('type="revolute"', 'type="continuous"'))
    cont, orig = legs.from_urdf(urdf), legs.from_urdf(legs.erd_files("go1")[0])
    assert list(cont) == list(orig)
    rng = np.random.default_rng(12)
    for name, leg in cont.items():
        assert np.isinf(leg.lower).all() and np.isinf(leg.upper).all() and (leg.q_ref == 0).all()
        q = rng.uniform(-3, 3, (200, 3))
        np.testing.assert_allclose(leg.fk(q), orig[name].fk(q), atol=1e-15, rtol=0)
        sol, ok = leg.ik(leg.fk(q), q_near=q, return_mask=True)
        assert ok.all() and np.abs(sol - q).max() < 1e-9


@pytest.mark.parametrize("name", ["go2", "anymal_c", "solo12"])
def test_float32_targets_are_solved_within_tol(erd, name):
    """Feet of in-limit joints rounded to float32 (a simulator's): none refused with the default tol (IK_TOL = 1e-7 m,
    above the rounding's sqrt(3) 2^-25 = 5.2e-8 m), each solved within 1e-7 m; a few refused with tol=1e-9 (the
    rounding pushed them out of reach by more)."""
    _, found = erd[name]
    rng = np.random.default_rng(32)
    for leg in found.values():
        q = rng.uniform(leg.lower, leg.upper, (20_000, 3))
        p32 = leg.fk(q).astype(np.float32).astype(float)
        sol, ok = leg.ik(p32, return_mask=True)
        assert ok.all(), f"{name} {leg.name}: {int((~ok).sum())} refused with the default tol"
        assert np.linalg.norm(leg.fk(sol) - p32, axis=-1).max() <= 1e-7
        _, ok9 = leg.ik(p32, tol=1e-9, return_mask=True)
        assert (~ok9).sum() <= 20, f"{name} {leg.name}: {int((~ok9).sum())} of 20000 refused with tol=1e-9"


def test_default_tol_refuses_a_target_1um_out_of_reach(erd):
    fl = erd["solo12"][1]["FL"]
    stretched = fl.fk(np.array([0.0, 0.0, 0.0]))  # knee straight: the full stretch
    unit = (stretched - fl.origin) / np.linalg.norm(stretched - fl.origin)
    with pytest.raises(UnreachableError):
        fl.ik(stretched + 1e-6 * unit)
    with pytest.raises(UnreachableError):
        fl.ik_all(stretched + 1e-6 * unit)
    q = fl.ik(stretched + 5e-8 * unit)  # within the default 1e-7 m: solved, the foot within tol of the target
    assert 1e-9 < float(np.linalg.norm(fl.fk(q) - (stretched + 5e-8 * unit))) <= legs.kinematics.IK_TOL


def test_tol_bounds_the_nearest_point_solution(erd):
    fl = erd["solo12"][1]["FL"]  # limits +-10 rad: the straight knee is inside them
    stretched = fl.fk(np.array([0.0, 0.0, 0.0]))  # knee straight: the full stretch
    out = fl.origin + 1.0000001 * (stretched - fl.origin)  # ~4e-8 m beyond
    with pytest.raises(UnreachableError):
        fl.ik(out, tol=1e-9)
    q = fl.ik(out, tol=1e-6)
    miss = float(np.linalg.norm(fl.fk(q) - out))
    assert 1e-9 < miss <= 1e-6
    with pytest.raises(InvalidParameterError, match="tol"):
        fl.ik(out, tol=-1.0)


def test_an_exact_branch_beats_a_clamped_one():
    """bolt's legs have h_X != 0, so their two abduction branches reach different sets: a target that one reaches
    exactly can lie within the default tol (1e-7 m) outside the other's reach. That branch's nearest reachable
    point (a straight knee, 9.2e-9 m off) was returned as a solution and picked by ``ik`` (``legkin check bolt
    --random-seed 12 --samples 1000``); now only exact branches are, and every row reproduces the target."""
    model = legs.load_erd("bolt")[0]
    fr = legs.from_model(model)["FR"]
    q = np.array([-2.1967784400339907, -8.031564439602102, 0.22872995395444917])
    p = fr.fk(q)
    sol, mask = fr.ik_all(p, return_mask=True)
    assert np.linalg.norm(fr.fk(sol[mask]) - p, axis=-1).max() <= TOL
    assert np.linalg.norm(fr.fk(fr.ik(p)) - p) <= TOL
    rng = np.random.default_rng(5)
    for leg in legs.from_model(model).values():
        q = rng.uniform(leg.lower, leg.upper, (50_000, 3))
        p = leg.fk(q)
        sol, mask = leg.ik_all(p, return_mask=True)
        assert np.linalg.norm(leg.fk(sol[mask]) - p[np.nonzero(mask)[0]], axis=-1).max() <= TOL
        assert np.linalg.norm(leg.fk(leg.ik(p)) - p, axis=-1).max() <= TOL


def test_polish_converges_next_to_the_abduction_singularity():
    """hyq's rf foot next to its HAA cylinder (``r ~ d``: the Jacobian's least singular value 6.8e-9, below the polish's
    damping 1e-7): with a fixed damping the steps left 2.4e-12 m (``legkin check hyq --random-seed 16 --samples
    100000``); the Levenberg-Marquardt damping reaches the target to machine precision on every branch."""
    rf = legs.from_model(legs.load_erd("hyq")[0])["rf"]
    q = np.array([-0.9957433163743001, -0.7818827155056822, -2.0389794853692838])
    p = rf.fk(q)
    assert np.linalg.svd(rf.jacobian(q), compute_uv=False).min() < 1e-7  # the case: sigma_min below the damping
    sol, mask = rf.ik_all(p, return_mask=True)
    assert mask.sum() >= 2
    assert np.linalg.norm(rf.fk(sol[mask]) - p, axis=-1).max() <= TOL


def test_quadruped_legs_named_by_hip_position_when_joint_names_share_no_prefix():
    """Joints named '0' ... '11' (no common prefix): the legs are FL, FR, RL, RR from the hips' signs of x and y."""
    model = pin.Model()
    hips = {"RR": (-0.2, -0.1), "FL": (0.2, 0.1), "RL": (-0.2, 0.1), "FR": (0.2, -0.1)}
    k = 0
    for x, y in hips.values():
        parent = 0
        for jm, place in ((pin.JointModelRX(), (x, y, 0.0)), (pin.JointModelRY(), (0.0, 0.05 * np.sign(y), 0.0)),
                          (pin.JointModelRY(), (0.0, 0.0, -0.2))):
            parent = model.addJoint(parent, jm, pin.SE3(np.eye(3), np.array(place)), str(k))
            model.addJointFrame(parent, -1)
            k += 1
        model.addFrame(pin.Frame(f"f{k}", parent, 0, pin.SE3(np.eye(3), np.array([0.0, 0.0, -0.2])),
                                 pin.FrameType.OP_FRAME))
    found = legs.from_model(model)
    assert list(found) == list(hips)
    for name, leg in found.items():
        assert np.sign(leg.origin[:2]).tolist() == np.sign(hips[name]).tolist()


def test_haa_arc_test_drops_only_angles_off_the_limits():
    """The limits-first IK skips an abduction branch when its q1 lies off the HAA limits' arc (``_on_arc_k``, two
    cross products, no atan2). It must keep every angle within CANDIDATE_SLACK of the limits (else ``ik`` would miss
    an answer the exact test keeps) and drop those beyond ARC_SLACK (else the test saves nothing): narrow, wide,
    whole-circle, infinite and one-point limits, angles uniform on the circle and at the limits."""
    import numba

    from legkin.legs._ik_kernels import _on_arc_k
    from legkin.legs._layout import _ARC, _NPARAMS, ARC_SLACK, CANDIDATE_SLACK
    from legkin.legs.kinematics import _limit_arc

    @numba.njit
    def on_arc(g, c, s):
        return _on_arc_k(g, c, s)

    rng = np.random.default_rng(7)
    two_pi = 2.0 * np.pi
    for lo, hi in [(-0.4, 0.4), (-2.0, 2.0), (0.0, 3.2), (-3.0, 3.5), (-np.inf, np.inf), (1.0, 1.0), (-4.0, -3.0)]:
        g = np.zeros(_NPARAMS)
        g[_ARC:_ARC + 5] = _limit_arc(lo, hi)
        at = [lo - CANDIDATE_SLACK, hi + CANDIDATE_SLACK, lo, hi, lo - 2 * ARC_SLACK, hi + 2 * ARC_SLACK]
        theta = np.concatenate([rng.uniform(-7.0, 7.0, 4000), [a for a in at if np.isfinite(a)]])
        for th in theta:
            r = rng.uniform(1e-3, 10.0)
            kept = on_arc(g, r * np.cos(th), r * np.sin(th))
            reps = th + two_pi * np.arange(-3, 4)
            out_by = np.min(np.maximum(np.maximum(lo - reps, reps - hi), 0.0)) if np.isfinite(lo) else 0.0
            if out_by <= CANDIDATE_SLACK:
                assert kept, (lo, hi, th, out_by)
            elif out_by > ARC_SLACK + 1e-9:
                assert not kept, (lo, hi, th, out_by)


@pytest.mark.parametrize("robot", ["quadruped", "go2", "solo12"])
def test_no_candidate_exit_gives_the_complete_paths_verdict(robot):
    """``Leg.ik`` decides a target with no candidate branch without its complete path when the verdict is beyond
    doubt (``_no_candidate_k``: the workspace study's common case), with the complete path's verdict. On targets
    in a box around each leg's hip: the rows ``ik_all`` finds out of reach (``_ik_all_core``) are exactly those
    ``ik`` finds out of reach, with the same miss and reason; on the rows ``ik`` finds reachable only outside the
    limits, every branch of ``ik_all`` is outside them and the single call's error measures by how much."""
    import legkin
    from legkin.legs._ik_kernels import _ik_all_batch, _ik_batch
    from legkin.legs._layout import _JOINT_LIMIT, _UNREACHABLE, IK_TOL

    found = legkin.quadruped.legs() if robot == "quadruped" else legs.from_model(legkin.load(robot).model)
    rng = np.random.default_rng(11)
    for leg in found.values():
        reach = leg.thigh_length + leg.shank_length + abs(leg.lateral_offset)
        p = leg.origin + rng.uniform(-1.3 * reach, 1.3 * reach, (20_000, 3))
        n = len(p)
        st, info, st_all, info_all = (np.empty(n, dtype=np.int64), np.zeros((n, 2)),
                                      np.empty(n, dtype=np.int64), np.zeros((n, 2)))
        _ik_batch(p, leg._g, leg._ref1, IK_TOL, np.empty((n, 3)), st, info)
        _ik_all_batch(p, leg._g, leg._ref1, IK_TOL, np.empty((n, 4, 3)), st_all, info_all)
        out = st_all == _UNREACHABLE
        assert out.sum() > n // 4  # the box is mostly out of reach: the exit is exercised
        np.testing.assert_array_equal(st == _UNREACHABLE, out)
        np.testing.assert_array_equal(info[out], info_all[out])
        # reachable only outside the limits (decided without the complete path when well-conditioned): every
        # branch of ik_all is outside the limits, and the single call's error measures by how much
        limit = np.flatnonzero(st == _JOINT_LIMIT)
        assert len(limit) > n // 20 or robot != "quadruped"  # POPI's limits: ~40 % of its box
        for i in limit[:: max(1, len(limit) // 200)]:
            branches = leg.ik_all(p[i])
            by = leg._least_violation(branches)[3]
            assert by > 0.0
            with pytest.raises(errors.JointLimitError) as raised:
                leg.ik(p[i])
            assert raised.value.distance == by and math.isfinite(by)
