"""legkin.study: known answers (the planar 2-link leg), 1/sqrt(N) error bars, parameters refused before work, and
results identical bit for bit in-process, on 1 or 2 dask workers and across a killed worker."""

from __future__ import annotations

import math
import os
import signal
import threading
import time

import numpy as np
import pytest

pd = pytest.importorskip("pandas")

from legkin.errors import InvalidArgumentError, InvalidParameterError, UnknownModelError  # noqa: E402
from legkin.study import plan, study  # noqa: E402
from legkin.study.stats import HIST_STEP, wilson  # noqa: E402

L1, L2 = 0.3, 0.2
EPS = 0.01
Z_TEST = 4.5  # the intervals the known answers must fall in (the 95 % ones would miss one case in 20)


def _planar_kappa_exact(n: int = 2_000_000) -> np.ndarray:
    """kappa of the 2-link Jacobian over targets uniform in its annulus, by quadrature: r^2 = l1^2 + l2^2 +
    2 l1 l2 cos q2 is uniform over the annulus' area, so cos q2 is uniform on [-1, 1] (midpoint grid); with
    ||J||_F^2 = r^2 + l2^2 = s1^2 + s2^2 and |det J| = l1 l2 |sin q2| = s1 s2, kappa = s1 / s2."""
    c = -1.0 + (np.arange(n) + 0.5) * (2.0 / n)
    f = L1**2 + 2 * L2**2 + 2 * L1 * L2 * c
    d = L1 * L2 * np.sqrt(1 - c * c)
    big = 0.5 * (f + np.sqrt(f * f - 4 * d * d))
    return np.sqrt(big * big / (d * d))


@pytest.fixture(scope="module")
def planar() -> pd.DataFrame:
    return study("planar_2link", {"l1": [L1], "l2": [L2]}, samples=400_000, seed=3, singular_threshold=EPS)


def test_planar_reach_and_area_known_answer(planar):
    row = planar.iloc[0]
    exact = 4 * math.pi * L1 * L2 / (2 * (L1 + L2)) ** 2  # annulus area / square box area
    _, lo, hi = wilson(int(row.reached), int(row.samples), Z_TEST)
    assert lo <= exact <= hi, (row.reach_fraction, exact)
    assert row.volume == pytest.approx(row.reach_fraction * (2 * (L1 + L2)) ** 2, rel=1e-15)
    assert row.volume_lo <= 4 * math.pi * L1 * L2 * (1 + 3 * (hi - lo)) and row.volume_hi >= 4 * math.pi * L1 * L2 * (
        1 - 3 * (hi - lo))


@pytest.mark.parametrize("pc", [50, 90, 99])
def test_planar_condition_percentiles_known_answer(planar, pc):
    row = planar.iloc[0]
    exact = float(np.quantile(_planar_kappa_exact(), pc / 100))
    step = 10 ** HIST_STEP  # the histogram's bin ratio
    n = int(row.reached)
    half = Z_TEST * math.sqrt(n * pc / 100 * (1 - pc / 100))
    kap = np.sort(_planar_kappa_exact())
    lo = kap[int(max((n * pc / 100 - half) / n, 0) * kap.size)]
    hi = kap[int(min((n * pc / 100 + half) / n, 1 - 1e-9) * kap.size)]
    assert lo / step <= row[f"cond_p{pc}"] <= hi * step, (row[f"cond_p{pc}"], exact, lo, hi)


def test_planar_singular_fraction_known_answer(planar):
    row = planar.iloc[0]
    exact = float(np.mean(_planar_kappa_exact() >= 1 / EPS))
    assert exact > 1e-4  # the case has singular samples to count
    k = round(row.singular_fraction * row.reached)
    _, lo, hi = wilson(k, int(row.reached), Z_TEST)
    assert lo <= exact <= hi, (row.singular_fraction, exact)


def test_error_bars_shrink_as_one_over_sqrt_n():
    small = study("planar_2link", {"l1": [L1]}, samples=20_000, seed=5).iloc[0]
    large = study("planar_2link", {"l1": [L1]}, samples=320_000, seed=5).iloc[0]
    width = [r.reach_fraction_hi - r.reach_fraction_lo for r in (small, large)]
    assert width[0] / width[1] == pytest.approx(4.0, rel=0.05)  # 16 x the samples: 1/4 the width


def test_out_of_range_parameters_raise_before_any_work():
    class Exploding:
        def submit(self, *args, **kwargs):
            raise AssertionError("work started")

    with pytest.raises(InvalidParameterError, match="alpha=4.0 is out of range"):
        study("tripod", {"alpha": [0.5, 4.0]}, samples=10, client=Exploding())
    with pytest.raises(InvalidParameterError, match="foot_z"):
        study("quadruped", {"foot_z": np.linspace(0.0, 0.2, 3)}, samples=10, client=Exploding())
    with pytest.raises(InvalidParameterError, match="unknown parameter"):
        plan("tripod", {"beta": [1.0]}, 10)
    with pytest.raises(UnknownModelError):
        plan("nope", {"alpha": [1.0]}, 10)
    with pytest.raises(InvalidArgumentError):
        plan("quadruped", {"foot_z": [0.0]}, 10, metrics=("cv_error",))
    with pytest.raises(InvalidArgumentError):
        plan("quadruped", {"foot_z": [0.0]}, 0)


def test_tripod_and_quadruped_rows():
    tri = study("tripod", {"alpha": [0.8, 1.2]}, samples=20_000, metrics=("reach", "conditioning", "cv_error"))
    assert list(tri.alpha) == [0.8, 1.2] and (tri.reached > 0).all()
    assert (tri.volume == tri.reach_fraction * 4 * math.pi).all()
    assert (tri.cv_error_max < 1e-9).all()  # the legs' chains turn the platform without torsion
    quad = study("quadruped", {"foot_z": [-0.05, 0.05]}, samples=20_000)
    assert (quad.reach_fraction > 0.05).all() and (quad.cond_p50 >= 1).all()


def test_tripod_reach_known_answer():
    """The tripod's reachable orientations in closed form (docs/tripod.md, ``workspace``): tilt theta below
    min_K 2 asin(cos(alpha/2) / |sin(phi - eta_K)|); solid angle = integral over phi of (1 - cos theta_max)."""
    alpha = 0.8
    row = study("tripod", {"alpha": [alpha]}, samples=200_000, seed=2).iloc[0]
    m = 400_000
    phi = (np.arange(m) + 0.5) * 2 * np.pi / m
    s = np.abs(np.sin(phi[:, None] - np.array([0.0, 2 * np.pi / 3, 4 * np.pi / 3])))
    theta = (2 * np.arcsin(np.minimum(1.0, np.cos(alpha / 2) / np.maximum(s, 1e-300)))).min(1)
    exact = float(np.sum(1 - np.cos(theta)) * 2 * np.pi / m)
    _, lo, hi = wilson(int(row.reached), int(row.samples), Z_TEST)
    assert 4 * np.pi * lo <= exact <= 4 * np.pi * hi, (row.volume, exact)


def test_wheel_leg_rim_links_add_up_to_the_reach():
    """alpha is uniform on [-pi, pi], so the links carry 130, 50, 50 and 130 degrees of it: the overall reachable
    fraction is the links' fractions weighted by those shares (to the sampling error)."""
    row = study("wheel_leg", {"R": [0.1]}, samples=40_000, metrics=("reach", "rim_contact")).iloc[0]
    links, share = ("upper_L", "lower_L", "lower_R", "upper_R"), np.array([130, 50, 50, 130]) / 360
    frac = np.array([row[f"rim_contact_{k}"] for k in links])
    half = np.array([row[f"rim_contact_{k}_hi"] - row[f"rim_contact_{k}_lo"] for k in links]) / 2
    assert (frac > 0).all() and (frac < 1).all()
    assert abs(share @ frac - row.reach_fraction) <= 2 * share @ half, (share @ frac, row.reach_fraction)
    assert row.volume == pytest.approx(row.reach_fraction * (2 * (0.35 + 0.091675 + 0.02)) ** 3, rel=1e-12)


def test_chunking_does_not_change_the_result():
    args = ("planar_2link", {"l1": [0.2, 0.3], "l2": [0.25]}, 50_000)
    a = study(*args, seed=7, block_size=4096, chunk_blocks=1)
    b = study(*args, seed=7, block_size=4096, chunk_blocks=5)
    pd.testing.assert_frame_equal(a, b, check_exact=True)
    c = study(*args, seed=8, block_size=4096)
    assert not a.equals(c)


def test_cli_writes_the_table_and_the_plot(tmp_path, capsys):
    from legkin.__main__ import main

    out, png = tmp_path / "s.parquet", tmp_path / "s.png"
    pytest.importorskip("pyarrow")
    pytest.importorskip("matplotlib")
    argv = ["study", "planar_2link", "--param", "l1=0.2:0.3:2", "--param", "l2=0.1,0.2", "--samples", "5000",
            "--seed", "4", "--out", str(out), "--plot", str(png), "--quiet"]
    assert main(argv) == 0
    table = pd.read_parquet(out)
    expected = study("planar_2link", {"l1": np.linspace(0.2, 0.3, 2), "l2": [0.1, 0.2]}, samples=5000, seed=4)
    pd.testing.assert_frame_equal(table, expected, check_exact=True)
    assert png.stat().st_size > 10_000
    assert main(["study", "tripod", "--param", "alpha=0.5:3.5:3", "--out", str(tmp_path / "bad.parquet")]) == 2
    assert "alpha=3.5 is out of range" in capsys.readouterr().err
    assert not (tmp_path / "bad.parquet").exists()
    assert main(["study", "tripod", "--param", "alpha=0.5:1"]) == 2  # malformed


# ------------------------------------------------------------------ dask
@pytest.fixture(scope="module")
def cluster():
    pytest.importorskip("distributed")  # the study extra; the tests above run without it
    from legkin.study import local_cluster

    with local_cluster(2) as client:
        yield client.cluster, client


def _legkin_pool_threads() -> list[str]:
    """The threads of legkin's batch pool in this process: started by the first batch split over numba threads."""
    return [t.name for t in threading.enumerate() if t.name.startswith("legkin")]


def test_dask_task_uses_one_core(cluster):
    """A study task runs its batches on the task's thread alone (no legkin batch-pool thread started), whatever
    numba's thread count in the worker (here the machine's CPU count; an env= of the cluster would not do: dask
    applies it after the worker process has imported the parent's __main__, and with it, often, numba), and
    local_cluster's workers have dask's profiler off (legkin.study.cluster.QUIET)."""
    import dask
    import numba

    lc, client = cluster
    worker_threads = client.run(numba.get_num_threads)
    if min(worker_threads.values()) < 2:
        pytest.skip("one CPU: a batch never splits over numba threads here")
    study("planar_2link", {"l1": [0.25, 0.3]}, samples=200_000, client=client)  # blocks of 65536 >= min_parallel
    assert client.run(_legkin_pool_threads) == {w: [] for w in worker_threads}
    assert set(client.run(dask.config.get, "distributed.worker.profile.enabled").values()) == {False}


TRIPOD = ("tripod", {"alpha": [0.7, 1.1]}, 300_000)
KW = dict(seed=11, block_size=1 << 14, metrics=("reach", "conditioning", "singularity", "cv_error"))


def test_dask_identical_to_in_process_on_1_and_2_workers(cluster):
    lc, client = cluster
    local = study(*TRIPOD, **KW)
    two = study(*TRIPOD, client=client, chunk_blocks=3, **KW)
    pd.testing.assert_frame_equal(local, two, check_exact=True)
    one_worker = [min(client.ncores())]  # asked of the scheduler (scheduler_info() is a cache that can be empty)
    one = study(*TRIPOD, client=_Pinned(client, one_worker), chunk_blocks=7, **KW)
    pd.testing.assert_frame_equal(local, one, check_exact=True)


class _Pinned:
    """A client whose tasks all run on the given workers."""

    def __init__(self, client, workers):
        self.client, self.workers = client, workers

    def submit(self, *args, **kwargs):
        return self.client.submit(*args, workers=self.workers, **kwargs)

    def gather(self, futures):
        return self.client.gather(futures)


def test_dask_killed_worker_is_rerun(cluster):
    lc, client = cluster
    client.wait_for_workers(2, timeout=30)
    local = study(*TRIPOD, **KW)
    out: dict[str, object] = {}

    def run():
        out["frame"] = study(*TRIPOD, client=client, chunk_blocks=1, **KW)

    th = threading.Thread(target=run)
    th.start()
    victim, deadline = None, time.monotonic() + 20
    while victim is None and time.monotonic() < deadline:
        busy = [w for w, tasks in client.processing().items() if any("legkin-study" in str(t) for t in tasks)]
        victim = busy[0] if busy else None
        time.sleep(0.02)
    assert victim is not None, "no task started"
    pid = client.run(os.getpid, workers=[victim])[victim]
    os.kill(pid, signal.SIGKILL)  # the worker process (its nanny starts a new one)
    th.join(timeout=60)
    assert "frame" in out
    assert victim not in client.ncores()  # the worker did die (asked of the scheduler, not its cached info)
    pd.testing.assert_frame_equal(local, out["frame"], check_exact=True)


def test_cli_local_scheduler_gives_the_in_process_table(tmp_path):
    """``--scheduler local:1``: a LocalCluster of one process (one numba thread), the same table bit for bit."""
    pytest.importorskip("distributed")
    from legkin.__main__ import main

    out = tmp_path / "s.csv"
    argv = ["study", "planar_2link", "--param", "l1=0.25,0.3", "--samples", "70000", "--out", str(out), "--quiet"]
    assert main([*argv, "--scheduler", "local:1"]) == 0
    expected = study("planar_2link", {"l1": [0.25, 0.3]}, samples=70_000)
    pd.testing.assert_frame_equal(pd.read_csv(out), expected, check_exact=True)
