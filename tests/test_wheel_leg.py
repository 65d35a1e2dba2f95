"""wheel_leg: closed-form linkage vs Pinocchio, rim contact point, contact Jacobian, IK and error paths."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import legkin
from legkin import _generate
from legkin.analytic import wheel_leg as wl
from legkin.checks import wheel_leg as checks
from legkin.models.wheel_leg import SPEC, annular_sector, rim_meshes

DEG = math.pi / 180
GEO = wl.Geometry()


@pytest.fixture(scope="module")
def robot():
    return legkin.load("wheel_leg")


# ---------------------------------------------------------------- checks and model
def test_check_rows_pass():
    rows = checks.run(40, np.random.default_rng(7))
    assert len(rows) >= 13
    failed = [(r.name, r.max_error, r.tolerance) for r in rows if not r.passed]
    assert not failed, failed


def test_model_structure(robot):
    # 4 legs x (ABAD + 10 tree joints), 4 loops per leg, all point closures
    assert robot.model.nq == 44 and len(robot.loops) == 16
    assert all(lp.type == "point" for lp in robot.loops)
    for leg in wl.LEGS:
        movable = [j for j in robot.joint_names if j.startswith(leg + "_") and j != f"{leg}_abad"]
        assert len(movable) == 10
        assert sum(lp.name.startswith(leg) for lp in robot.loops) == 4
    assert set(SPEC.actuated_joints) == {f"{leg}_{j}" for leg in wl.LEGS for j in ("abad", "phi_L", "phi_R")}
    assert robot.q0 is not None and np.allclose(robot.q0, robot.poses["wheel"])


@pytest.mark.parametrize("pose, theta", [("wheel", 17 * DEG), ("leg", 160 * DEG)])
def test_srdf_poses_are_the_closed_form(robot, pose, theta):
    q = robot.poses[pose]
    assert np.linalg.norm(robot.constraint_residual(q)) <= 1e-12
    expected = checks.configuration(robot, np.tile([theta, 0.0, 0.0], (4, 1)))
    assert np.abs(q - expected).max() <= 1e-12
    assert robot.mobility(q) == 12


def test_mobility_per_leg_is_two_plus_abad(robot):
    q = robot.poses["leg"]
    others = [j for leg in ("FR", "RR", "RL") for j in checks.leg_joint_names(leg)]
    assert robot.mobility(q, locked=others) == 3
    assert robot.mobility(q, locked=others + ["FL_abad"]) == 2
    assert robot.mobility(q, locked=others + ["FL_abad", "FL_phi_L"]) == 1
    assert robot.mobility(q, locked=others + ["FL_abad", "FL_phi_L", "FL_phi_R"]) == 0


def test_floating_base(robot):
    fl = legkin.load("wheel_leg", floating=True)
    assert fl.model.nq == robot.model.nq + 7
    assert np.linalg.norm(fl.constraint_residual(fl.poses["leg"])) <= 1e-12


def test_meshes_generated_deterministic_and_loaded(robot):
    args = {k: p.default for k, p in SPEC.params.items()}
    a, b = rim_meshes(args), rim_meshes(dict(args))
    assert a == b and set(a) == {"meshes/wheel_leg_rim_upper.stl", "meshes/wheel_leg_rim_lower.stl"}
    for rel, content in a.items():
        assert (robot.urdf_path.parent / rel).read_bytes() == content
        n = int.from_bytes(content[80:84], "little")
        assert len(content) == 84 + 50 * n
    meshes = [g for g in robot.visual_model.geometryObjects if g.meshPath.endswith(".stl")]
    assert len(meshes) == 16
    for g in meshes:
        assert g.geometry.num_vertices > 8  # the BVH built from the STL
    assert _generate.check_all(["wheel_leg"]) == []


def test_rim_mesh_is_closed_sector():
    import trimesh

    tri = annular_sector(0.09, 0.135, 65 * DEG, 0.04, 52)
    mesh = trimesh.Trimesh(vertices=tri.reshape(-1, 3), faces=np.arange(tri.shape[0] * 3).reshape(-1, 3))
    mesh.merge_vertices()
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    exact = 65 * DEG * (0.135**2 - 0.09**2) * 0.04  # polygonal sector is slightly smaller
    assert exact * 0.995 < mesh.volume < exact


def test_yourdfpy_loads_with_meshes(robot):
    yourdfpy = pytest.importorskip("yourdfpy")
    urdf = yourdfpy.URDF.load(str(robot.urdf_path), load_meshes=True, build_scene_graph=True)
    assert "FL_rim_upper_L" in urdf.link_map
    geoms = [g for g in urdf.scene.geometry.values() if len(g.vertices) > 8]
    assert len(geoms) >= 2


def test_non_default_radius_closes_loops(tmp_path, monkeypatch):
    monkeypatch.setenv("LEGKIN_CACHE", str(tmp_path))
    r = legkin.load("wheel_leg", R=0.12, T=0.05)
    assert tmp_path in r.urdf_path.parents and (r.urdf_path.parent / "meshes/wheel_leg_rim_upper.stl").exists()
    geo = wl.Geometry.from_params(r.params)
    for pose in ("wheel", "leg"):
        assert np.linalg.norm(r.constraint_residual(r.poses[pose])) <= 1e-12
    q = checks.configuration(r, np.tile([1.2, 0.3, 0.1], (4, 1)))
    assert np.linalg.norm(r.constraint_residual(q)) <= 1e-12
    g = r.frame_placement(q, "FL_G").translation
    ana = wl.leg_frame_to_robot(wl.linkage_points(1.2, 0.3, geometry=geo)["G"], 0.1, "FL", geometry=geo)
    assert np.abs(g - ana).max() <= 1e-12


def test_bad_params_refused_before_writing(tmp_path, monkeypatch):
    monkeypatch.setenv("LEGKIN_CACHE", str(tmp_path))
    for bad in ({"R": -0.1}, {"T": 0.0}, {"d_wheel": float("nan")}, {"wheel_radius": 0.1}):
        with pytest.raises(legkin.InvalidParameterError):
            legkin.load("wheel_leg", **bad)
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- closed form facts
def test_linkage_facts():
    c = wl.linkage_constants()
    assert c["l4"] == pytest.approx(0.0882966335, abs=1e-11)  # the design notes' 0.882966335 R
    th = np.array([17, 90, 160]) * DEG
    p = wl.linkage_points(th)
    assert np.linalg.norm(p["G"], axis=-1) == pytest.approx([0.100, 0.229, 0.343], abs=1e-3)
    for a, b in (("U_L", "B_L"), ("U_L", "C_L"), ("U_L", "H_L"), ("U_L", "F_L"), ("L_R", "F_R"), ("L_R", "G")):
        assert np.abs(np.linalg.norm(p[a] - p[b], axis=-1) - 0.1).max() < 1e-15
    w = wl.linkage_points(17 * DEG, 0.4)
    for k in ("U_L", "U_R", "L_L", "L_R", "O_r"):
        assert np.abs(w[k]).max() < 1e-15  # wheel mode: every rim centre on the motor axis
    ang = wl.passive_angles(17 * DEG, 0.7)
    assert ang["phi_L"] == pytest.approx(0.7) and ang["phi_R"] == pytest.approx(0.7)
    assert all(abs(ang[k]) < 1e-15 for k in ang if k.startswith("hinge"))


@given(st.floats(17 * DEG, 160 * DEG), st.floats(-4.0, 4.0))
@settings(max_examples=60, deadline=None)
def test_motor_mapping_round_trip(theta, beta):
    phi_l, phi_r = wl.motor_angles(theta, beta)
    th, be = wl.theta_beta(phi_l, phi_r)
    assert th == pytest.approx(theta, abs=1e-14) and be == pytest.approx(beta, abs=1e-14)
    ang = wl.passive_angles(theta, beta)
    assert ang["phi_L"] == pytest.approx(phi_l, abs=1e-15) and ang["phi_R"] == pytest.approx(phi_r, abs=1e-15)
    for h in "ABDF":
        assert ang[f"hinge_{h}_L"] == -ang[f"hinge_{h}_R"]


# ---------------------------------------------------------------- rim
@given(st.floats(-math.pi, math.pi), st.floats(-3.0, 3.0))
@settings(max_examples=60, deadline=None)
def test_wheel_mode_rim_is_the_wheel(alpha, beta):
    p = wl.rim_point(17 * DEG, beta, alpha, 0.0)
    z = 0.1 * np.exp(1j * (beta + math.pi / 2 + math.pi + alpha))
    assert np.abs(p - [z.real, z.imag, 0.0]).max() < 1e-15
    # the seed formula is the same circle, at the foot radius, in wheel mode
    ps = wl.rim_point_seed(17 * DEG, beta, alpha, 0.0)
    zs = (0.1 + wl.FOOT_OFFSET) * np.exp(1j * (beta + math.pi / 2 + math.pi + alpha))
    assert np.abs(ps - [zs.real, zs.imag, 0.0]).max() < 1e-15


@given(st.floats(17 * DEG, 160 * DEG), st.sampled_from([-50 * DEG, 0.0, 50 * DEG, -40 * DEG, 40 * DEG]))
@settings(max_examples=80, deadline=None)
def test_rim_point_is_continuous(theta, a0):
    eps = 1e-9
    p = wl.rim_point(theta, 0.2, np.array([a0 - eps, a0, a0 + eps]), 0.01)
    assert np.abs(p[1] - p[0]).max() < 0.2 * eps and np.abs(p[2] - p[1]).max() < 0.2 * eps


def test_seed_rim_jump_matches_reference():
    th = np.array([17, 30, 90, 160]) * DEG
    jump = wl.rim_jump_seed(th)
    assert jump[0] < 1e-15
    assert jump[1:] == pytest.approx([0.011, 0.069, 0.091], abs=1e-3)
    # the jump is real: the two sides of alpha = psi_FG are far apart, unlike rim_point's
    a = wl.PSI_FG
    p = wl.rim_point_seed(90 * DEG, 0.0, np.array([a, np.nextafter(a, 4)]))
    assert np.linalg.norm(p[1] - p[0]) == pytest.approx(jump[2], abs=1e-15)


@given(st.floats(17 * DEG, 160 * DEG), st.floats(-math.pi, math.pi), st.floats(-0.6, 0.6),
       st.floats(-math.pi, math.pi), st.floats(-0.02, 0.02), st.sampled_from(wl.LEGS), st.sampled_from(["continuous", "seed"]))
@settings(max_examples=60, deadline=None)
def test_contact_jacobian_matches_central_differences(theta, beta, gamma, alpha, w, leg, rim):
    q = np.array([theta, beta, gamma])
    J = wl.contact_jacobian(q, alpha, w, leg, rim=rim)
    h = 1e-6
    for k in range(3):
        dq = np.zeros(3)
        dq[k] = h
        lo, hi = q - dq, q + dq
        lo[0], hi[0] = max(lo[0], wl.THETA_MIN), min(hi[0], wl.THETA_MAX)
        fd = (wl.contact_point(hi, alpha, w, leg, rim=rim) - wl.contact_point(lo, alpha, w, leg, rim=rim)) / (hi[k] - lo[k])
        assert np.abs(fd - J[:, k]).max() < (1e-8 if hi[0] - lo[0] == 2 * h or k else 1e-5)


def test_frame_conventions():
    # at gamma = 0 every leg has x_L = -x_R, y_L = +z_R, z_L = +y_R
    for leg in wl.LEGS:
        o = wl.leg_frame_to_robot([0.0, 0.0, 0.0], 0.0, leg)
        for e, expect in (([1, 0, 0], [-1, 0, 0]), ([0, 1, 0], [0, 0, 1]), ([0, 0, 1], [0, 1, 0])):
            assert np.allclose(wl.leg_frame_to_robot(e, 0.0, leg) - o, expect, atol=1e-15)
        q = np.array([90 * DEG, 0.0, 0.0])
        toe = wl.contact_point(q, 0.0, 0.0, leg)
        back = wl.contact_point(q + [0, 0.1, 0], 0.0, 0.0, leg)
        out = wl.contact_point(q + [0, 0, 0.1], 0.0, 0.0, leg)
        side = 1.0 if leg in ("FL", "RL") else -1.0
        assert back[0] < toe[0]  # beta > 0 moves the foot backward
        assert side * (out[1] - toe[1]) > 0  # gamma > 0 swings the foot outward
        assert toe[2] < -0.15


# ---------------------------------------------------------------- IK
@given(st.floats(17 * DEG, 160 * DEG), st.floats(-math.pi, math.pi), st.floats(-0.6, 0.6),
       st.one_of(st.floats(-math.pi, math.pi), st.sampled_from([-math.pi, -50 * DEG, 0.0, 50 * DEG, math.pi])),
       st.one_of(st.floats(-0.02, 0.02), st.sampled_from([-0.02, 0.02])), st.sampled_from(wl.LEGS))
@settings(max_examples=80, deadline=None)
def test_ik_round_trip(theta, beta, gamma, alpha, w, leg):
    target = wl.contact_point([theta, beta, gamma], alpha, w, leg)
    q, info = wl.ik(target, alpha, w, leg, return_info=True)
    assert wl.THETA_MIN <= q[0] <= wl.THETA_MAX
    assert np.linalg.norm(wl.contact_point(q, alpha, w, leg) - target) <= 1e-12
    assert info.iterations <= 200


@pytest.mark.parametrize("theta", [17 * DEG, 160 * DEG])
def test_ik_at_the_theta_bounds(theta):
    target = wl.contact_point([theta, 0.3, -0.2], 0.0, 0.01, "RR")
    q = wl.ik(target, 0.0, 0.01, "RR")
    assert q[0] == pytest.approx(theta, abs=1e-9)
    q_seed = wl.ik(target, 0.0, 0.01, "RR", method="seed", rim="continuous")
    assert np.linalg.norm(wl.contact_point(q_seed, 0.0, 0.01, "RR") - target) <= 1e-12


def test_ik_batch_and_methods():
    rng = np.random.default_rng(3)
    q = checks.sample_leg_q(200, rng)
    alpha = rng.uniform(-math.pi, math.pi, 200)
    for rim in ("continuous", "seed"):
        t = wl.contact_point(q, alpha, 0.0, "FR", rim=rim)
        for method in ("damped", "seed"):
            qs, ok, info = wl.ik(t, alpha, 0.0, "FR", method=method, rim=rim, return_mask=True, return_info=True)
            assert qs.shape == (200, 3) and ok.shape == (200,) and info.iterations.shape == (200,)
            assert np.all(np.isnan(qs[~ok]))
            assert ok.mean() > (0.999 if method == "damped" else 0.95)
            err = np.linalg.norm(wl.contact_point(qs[ok], alpha[ok], 0.0, "FR", rim=rim) - t[ok], axis=-1)
            assert err.max() <= 1e-12


def test_ik_unreachable():
    far = np.array([0.3, 0.2, -0.6])  # 0.65 m below the FL hip: the leg reaches at most ~0.35 m
    with pytest.raises(legkin.UnreachableError) as info:
        wl.ik(far, 0.0, 0.0, "FL")
    assert info.value.closest is not None and np.linalg.norm(info.value.closest - far) > 0.2
    assert "closest" in str(info.value)
    inside = wl.contact_point([1.0, 0.1, 0.0], 0.0, 0.0, "FL")
    qs, ok = wl.ik(np.stack([far, inside]), 0.0, 0.0, "FL", return_mask=True)
    assert ok.tolist() == [False, True] and np.all(np.isnan(qs[0])) and np.all(np.isfinite(qs[1]))
    with pytest.raises(legkin.UnreachableError):
        wl.ik(far, 0.0, 0.0, "FL", method="seed")
    # too close to the motor axis: inside the wheel radius
    near = wl.leg_frame_to_robot([0.0, -0.03, 0.0], 0.0, "FL")
    with pytest.raises(legkin.UnreachableError):
        wl.ik(near, 0.0, 0.0, "FL")


# ---------------------------------------------------------------- input errors
@pytest.mark.parametrize(
    "call",
    [
        lambda: wl.linkage_points(16 * DEG),
        lambda: wl.linkage_points(161 * DEG),
        lambda: wl.passive_angles(np.array([1.0, 3.0])),
        lambda: wl.rim_point(1.0, 0.0, 0.0, 0.03),
        lambda: wl.rim_point(1.0, 0.0, 3.2, 0.0),
        lambda: wl.rim_point_seed(0.1, 0.0, 0.0, 0.0),
        lambda: wl.contact_point([1.0, 0.0, 0.0], 0.0, -0.021, "FL"),
        lambda: wl.contact_point([0.2, 0.0, 0.0], 0.0, 0.0, "FL"),
        lambda: wl.contact_jacobian([1.0, 0.0], 0.0, 0.0, "FL"),
        lambda: wl.contact_point([1.0, np.nan, 0.0], 0.0, 0.0, "FL"),
        lambda: wl.contact_point(np.ones((2, 3)), np.zeros(3), 0.0, "FL"),
        lambda: wl.ik([0.1, np.inf, 0.0], 0.0, 0.0, "FL"),
        lambda: wl.ik([0.1, 0.1], 0.0, 0.0, "FL"),
        lambda: wl.ik([0.1, 0.1, -0.2], 0.0, 0.05, "FL"),
        lambda: wl.ik([0.1, 0.1, -0.2], 0.0, 0.0, "FL", q0=[0.1, 0.0, 0.0]),
        lambda: wl.rim_jump_seed(np.nan),
    ],
)
def test_invalid_inputs(call):
    with pytest.raises(legkin.InvalidInputError) as info:
        call()
    assert isinstance(info.value, ValueError)


def test_invalid_choices():
    for call in (
        lambda: wl.contact_point([1.0, 0.0, 0.0], 0.0, 0.0, "XX"),
        lambda: wl.contact_point([1.0, 0.0, 0.0], 0.0, 0.0, 4),
        lambda: wl.contact_point([1.0, 0.0, 0.0], 0.0, 0.0, "FL", rim="five_arcs"),
        lambda: wl.ik([0.1, 0.1, -0.2], 0.0, 0.0, "FL", method="newton"),
    ):
        with pytest.raises(legkin.InvalidParameterError):
            call()
    with pytest.raises(legkin.InvalidInputError, match=r"\[-T/2, T/2\]"):
        wl.rim_point(1.0, 0.0, 0.0, 0.5)
    with pytest.raises(legkin.InvalidInputError, match="17 deg to 160 deg"):
        wl.linkage_points(3.0)
