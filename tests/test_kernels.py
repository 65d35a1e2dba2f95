"""legkin._kernels: the batch loops' thread chunks and the kernels' dispatcher (issue 16)."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from legkin._kernels import BatchLoop, KernelDispatcher, _njit, batch_kernel, kernel, prange  # noqa: F401


def _axis_value_py(axis, x):
    if axis == 0:
        return x
    if axis == 1:
        return 2.0 * x
    return -x


_axis_value = _njit(_axis_value_py, cache=False)  # not cached: compiled in every test run


def _calls_with_literals_py(x):
    return _axis_value(0, x) + _axis_value(1, x) + _axis_value(2, x)


_calls_with_literals = _njit(_calls_with_literals_py, cache=False)


@kernel
def _item(x, shared, out):
    out[0] = x[0] * shared[0] + x[1]
    out[1] = x[0] - x[1] * shared[1]
    return 1 if x[0] > 0.5 else 0


@batch_kernel(rows="x ref out", min_parallel=8)
def _loop(x, shared, ref, out):
    count = 0
    m = ref.shape[0]
    for i in range(x.shape[0]):
        count += _item(x[i], shared, out[i])
        out[i, 2] = ref[i if m > 1 else 0, 0]
    return count


@pytest.fixture
def two_threads():
    before = numba.get_num_threads()
    numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
    yield numba.get_num_threads()
    numba.set_num_threads(before)


def test_literal_arguments_compile_one_version():
    """Calls with the constants 0, 1, 2 share one compiled version of the callee (numba alone compiles three,
    each with its call tree): the dispatcher types calls on non-literal arguments."""
    assert isinstance(_axis_value, KernelDispatcher)
    assert _calls_with_literals(1.5) == pytest.approx(1.5 + 3.0 - 1.5)
    assert len(_axis_value.signatures) == 1
    assert _axis_value(1, 2.0) == 4.0  # the call from Python reuses it
    assert len(_axis_value.signatures) == 1


@pytest.mark.parametrize("n", [1, 7, 8, 9, 1000])
@pytest.mark.parametrize("shared_ref", [False, True])
def test_chunks_are_the_serial_loop_bit_for_bit(n, shared_ref, two_threads):
    """From min_parallel items the rows are split among the threads: the outputs are the serial loop's, bit for
    bit; the int return (a count) is summed over the chunks; a one-row argument is shared by all items."""
    rng = np.random.default_rng(n)
    x = rng.uniform(0, 1, (n, 2))
    shared = np.array([0.3, 1.7])
    ref = rng.uniform(0, 1, (1 if shared_ref else n, 1))
    out = np.full((n, 3), np.nan)
    count = _loop(x, shared, ref, out)
    serial = np.full((n, 3), np.nan)
    assert count == _loop.kernel(x, shared, ref, serial)  # the compiled loop itself: one thread
    np.testing.assert_array_equal(out, serial)
    assert count == int(np.sum(x[:, 0] > 0.5))
    np.testing.assert_array_equal(out[:, 2], np.broadcast_to(ref[:, 0], (n,)))


def test_chunks_run_on_several_threads(two_threads):
    """A large batch hands chunks to worker threads (numba's thread count): the loop runs outside the GIL."""
    if two_threads < 2:
        pytest.skip("numba has one thread here")
    import threading

    seen = set()
    real = _loop.kernel

    def spy(*args):
        seen.add(threading.get_ident())
        return real(*args)

    loop = BatchLoop(_loop.__wrapped__, "x ref out", 8)
    loop.kernel = spy
    n = 64
    loop(np.zeros((n, 2)), np.ones(2), np.zeros((n, 1)), np.empty((n, 3)))
    assert len(seen) == 2
    numba.set_num_threads(1)
    seen.clear()
    loop(np.zeros((n, 2)), np.ones(2), np.zeros((n, 1)), np.empty((n, 3)))
    assert seen == {threading.get_ident()}


def _ploop_py(x, shared, ref, out):
    count = 0
    for i in prange(x.shape[0]):
        count += _item(x[i], shared, out[i])
        out[i, 2] = ref[0, 0]
    return count


def test_parfor_loop_runs_serially_when_asked(two_threads, monkeypatch):
    """``serial_parfor_loops`` (the ``legkin check`` workers): a ``parfor`` loop runs its serial compilation and never
    compiles its parallel twin; otherwise the twin runs, on one thread too, and gives the same rows bit for bit."""
    import legkin._kernels as kernels

    loop = BatchLoop(_ploop_py, "x ref out", 8, parfor=True)
    loop.parfor = _njit(loop.parfor.py_func, cache=False, parallel=True)  # this test compiles it afresh
    x = np.random.default_rng(1).uniform(0, 1, (64, 2))
    args = (np.array([0.3, 1.7]), np.zeros((1, 1)))
    monkeypatch.setattr(kernels, "serial_parfor_loops", True)
    serial = np.empty((64, 3))
    count = loop(x, *args, serial)
    assert loop.parfor.signatures == [] and count == int(np.sum(x[:, 0] > 0.5))
    monkeypatch.setattr(kernels, "serial_parfor_loops", False)
    numba.set_num_threads(1)
    out = np.empty((64, 3))
    assert loop(x, *args, out) == count and len(loop.parfor.signatures) == 1
    np.testing.assert_array_equal(out, serial)


def test_row_names_are_checked():
    with pytest.raises(TypeError, match="no argument 'y'"):
        batch_kernel(rows="x y", min_parallel=8)(_loop.__wrapped__)


def test_parfor_twin_has_its_own_cache_files():
    """numba's cache keys on the qualified name and the signature, not on parallel=True: the serial loop and its
    parallel twin must not share cache files (a process would load whichever was cached first: the parallel loop
    for a batch of 8 cost 10 us of thread start-up)."""
    from legkin.legs._fk_kernels import _fk_batch

    assert _fk_batch.parfor is not None
    for loop in (_fk_batch.kernel, _fk_batch.parfor):
        loop.ensure_cache()  # set up on the first compile otherwise
    assert _fk_batch.kernel._cache._cache_file._index_path != _fk_batch.parfor._cache._cache_file._index_path
    assert _fk_batch.parfor.py_func.__code__ is _fk_batch.kernel.py_func.__code__


def test_batch_loop_is_the_loop_over_its_kernel_filed_under_the_kernel_module():
    """``batch_loop(name_k)``: the loop ``bad += name_k(x[i], shared, out[i]) != OK`` (each row as one kernel call,
    the count of failed rows returned), named ``name_batch``, cached under the kernel's module and source file (so
    that editing that file recompiles it); a kernel not named ``..._k`` is refused."""
    import legkin
    from legkin._kernels import batch_loop
    from legkin.legs import _fk_kernels as fk

    leg = legkin.load("go2").geometry["FL"]
    q = np.random.default_rng(3).uniform(-1.0, 1.0, (40, 3))
    q[[5, 17]] = np.nan
    out, want = np.empty((40, 3)), np.empty((40, 3))
    bad = sum(fk._fk_k(q[i], leg.params, want[i]) != 0 for i in range(40))
    assert bad == 2 and fk._fk_batch(q, leg.params, out) == bad
    np.testing.assert_array_equal(out[np.isfinite(q[:, 0])], want[np.isfinite(q[:, 0])])
    py = fk._fk_batch.kernel.py_func
    assert (py.__qualname__, py.__module__) == ("_fk_batch", "legkin.legs._fk_kernels")
    assert py.__code__.co_filename == fk._fk_k.py_func.__code__.co_filename
    fk._fk_batch.kernel.ensure_cache()
    assert "_fk_kernels._fk_batch-" in fk._fk_batch.kernel._cache._cache_file._index_path
    with pytest.raises(TypeError, match="must end in _k"):
        batch_loop(_leaf, min_parallel=8)


def _thin_py(x):
    return 3.0 * _leaf(x)


def _leaf_py(x):
    return x * x + 1.0


_leaf = _njit(_leaf_py, cache=False, entry=False)
_thin = _njit(_thin_py, cache=False, entry=False, inline="always")


def _entry_py(x):
    return _thin(x) + _leaf(x)


_entry = _njit(_entry_py, cache=False)


def test_internal_kernels_have_no_python_wrapper_and_a_python_call_compiles_a_twin():
    """A kernel only kernels call is compiled without numba's CPython wrapper; the kernel calling it works, and a
    call from Python goes to a Python-callable twin (compiled once, listed in python_twins), same result."""
    from legkin import _kernels

    assert isinstance(_leaf, _kernels.InternalKernel) and not isinstance(_entry, _kernels.InternalKernel)
    assert _leaf.targetoptions["no_cpython_wrapper"] is True
    assert "no_cpython_wrapper" not in _entry.targetoptions
    assert _entry(2.0) == 3.0 * 5.0 + 5.0
    assert len(_leaf.signatures) == 1 and len(_thin.signatures) == 0  # _thin: inlined into _entry, never compiled
    before = list(_kernels.python_twins)
    assert _leaf(2.0) == 5.0 and _leaf(3.0) == 10.0 and _thin(2.0) == 15.0
    new = _kernels.python_twins[len(before):]
    assert new == [f"{__name__}._leaf_py", f"{__name__}._thin_py"]  # one twin each, however many calls
    assert _leaf._twin is not None and _leaf._twin.py_func.__qualname__ == "_leaf_py_py"  # its own cache entry
    assert "no_cpython_wrapper" not in _leaf._twin.targetoptions and "inline" not in _thin._twin.targetoptions


def test_checks_call_no_internal_kernel_from_python():
    """Every kernel the checks (and the public functions they call) call from Python is an entry kernel or a batch
    loop: a run of every model's checks, in a fresh process, compiles no Python twin (a twin is a second compile of
    a kernel with its whole call tree)."""
    code = ("from legkin import _kernels, validation; "
            "validation.run_checks(samples=60, ik_targets=60, classify=60); print(_kernels.python_twins)")
    assert _fresh_python(code).strip().splitlines()[-1] == "[]"


def test_analytic_calls_do_not_import_pinocchio():
    """Importing legkin and calling each mechanism's analytic kinematics never imports Pinocchio (about 0.1 s of
    the first call): only ``legkin.load`` and ``legkin.Robot`` need it, and they import it on first use. The
    quadruped is the exception: its legs are :class:`legkin.legs.Leg` measured by Pinocchio from its URDF on the
    first call (``legkin.quadruped.measured``)."""
    code = (
        "import sys, numpy as np, legkin; from legkin import hybrid_leg, quadruped, tripod, wheel_leg; "
        "assert 'pinocchio' not in sys.modules, 'pinocchio imported by import legkin'; "
        "tripod.fk(tripod.ik(np.array([0.2, -0.1]))); "
        "wheel_leg.ik(wheel_leg.fk(np.array([1.2, 0.3, 0.1]), 'FL'), 'FL'); "
        "hybrid_leg.ik(hybrid_leg.fk(np.array([0.0, 0.0, 3.0]))); "
        "assert 'pinocchio' not in sys.modules, 'pinocchio imported by an analytic call'; "
        "assert {'load', 'Robot'} <= set(dir(legkin)) and 'pinocchio' not in sys.modules; "
        "assert legkin.load('tripod').model.nq == 12 and 'pinocchio' in sys.modules"
    )
    _fresh_python(code)


def test_numba_cache_is_set_up_on_first_compile_only():
    """A kernel's numba cache is set up by its first compile or cache load (``KernelDispatcher.ensure_cache``), not
    at import: importing a mechanism sets up none, a call sets up the kernels it runs, and they are numba's
    on-disk caches (a second call in a new process loads them: the read-only test of .ci/run)."""
    code = (
        "import gc, numpy as np; from numba.core.caching import FunctionCache; "
        "from legkin import _kernels, quadruped; import legkin.quadruped.kinematics; "
        "ks = lambda: [o for o in gc.get_objects() if isinstance(o, _kernels.KernelDispatcher)]; "
        "assert ks() and not [k for k in ks() if k._cache_ready], 'a cache set up at import'; "
        "quadruped.fk(np.array([0.1, 0.8, 1.2]), 'LF'); "
        "ready = [k for k in ks() if k._cache_ready]; "
        "assert ready and len(ready) < len(ks()) // 2, (len(ready), len(ks())); "
        "assert all(isinstance(k._cache, FunctionCache) for k in ready)"
    )
    _fresh_python(code)


def _fresh_python(code: str) -> str:
    """Run ``code`` in a new Python process; its stdout (the test fails with the end of stderr if it fails)."""
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=1800)
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout


def test_compile_profile_script_lists_the_kernels_of_a_first_run():
    """``scripts/compile_profile.py`` (CONTRIBUTING.md, first-run compile): a fresh cache, so the external robot's
    check compiles the legs kernels, listed dearest first with their exclusive time (<= inclusive)."""
    import os
    import pathlib
    import re
    import subprocess
    import sys

    script = pathlib.Path(__file__).parents[1] / "scripts" / "compile_profile.py"
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    out = subprocess.run([sys.executable, str(script), "a1", "--top", "4"], capture_output=True, text=True,
                         timeout=1800, env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    total = re.search(r"compile ([0-9.]+) s in (\d+) compiles", out.stdout)
    rows = re.findall(r"^ +([0-9.]+)s +([0-9.]+)s +\d+  (\S+)$", out.stdout, re.M)
    assert total and float(total.group(1)) > 0 and len(rows) == 4, out.stdout[-2000:]
    exclusive = [float(r[0]) for r in rows]
    assert exclusive == sorted(exclusive, reverse=True)
    assert all(float(e) <= float(i) for e, i, _ in rows) and rows[0][2].startswith("legs.")
