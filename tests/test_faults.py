"""Faults a user's program meets (issue 25), each reproduced in a fresh Python process and now handled: a fork after
a parallel batch, concurrent batches on a threading layer that is not thread-safe, a damaged or read-only numba cache,
signals to the command line, a viewer open to the network, and small gaps of the error contract.

Each test runs its program in a subprocess (a fork, an abort or a hang must not take pytest down), with a timeout."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import legkin

SRC = str(Path(legkin.__file__).resolve().parents[1])


def run_py(code: str, *, env: dict[str, str] | None = None, timeout: float = 300) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter that imports this legkin; its completed process (text output)."""
    full = {**os.environ, "PYTHONPATH": SRC, **(env or {})}
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          env=full, timeout=timeout)


# --- fork and threads -------------------------------------------------------------------------------------------

FORK_CHILD = """
    import os, signal, numpy as np
    from legkin import {module}
    {setup}
    first = {call}
    pid = os.fork()
    if pid == 0:
        signal.alarm(20)  # a hung child dies of SIGALRM instead of hanging the test
        os._exit(0 if np.array_equal({call}, first, equal_nan=True) else 1)
    _, status = os.waitpid(pid, 0)
    print("child", status)
"""


@pytest.mark.parametrize("module, setup, call", [
    # tripod, wheel_leg and hybrid_leg split large batches among a thread pool, whose threads a fork does not copy
    ("tripod", "m = tripod.ik(np.tile([0.2, -0.1], (1000, 1)))", "tripod.fk(m)"),
    # the quadruped's batches run on numba's threading layer (GNU OpenMP here: it kills a forked child)
    ("quadruped", "q = np.tile([0.1, 0.8, 1.2], (5000, 1))", "quadruped.fk(q, 'LF')"),
], ids=["pool", "openmp"])
def test_batch_in_a_forked_child(module, setup, call):
    """The issue's reproducer: after the parent has run a large batch, the same batch in a forked child returns
    the parent's answer (it hung on the pool's missing threads, or was killed by GNU OpenMP)."""
    proc = run_py(FORK_CHILD.format(module=module, setup=setup, call=call))
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["child", "0"], (proc.stdout, proc.stderr)


def test_multiprocessing_fork_pool():
    """A ``multiprocessing`` pool with the fork start method (Linux's default before Python 3.14) runs batches."""
    proc = run_py("""
        import multiprocessing, numpy as np
        from legkin import quadruped, tripod
        m = tripod.ik(np.tile([0.2, -0.1], (1000, 1))); tripod.fk(m)
        q = np.tile([0.1, 0.8, 1.2], (5000, 1)); quadruped.fk(q, "LF")
        def work(i):
            return float(np.nansum(tripod.fk(m)) + np.nansum(quadruped.fk(q, "LF")))
        with multiprocessing.get_context("fork").Pool(2) as pool:
            res = pool.map_async(work, range(4)).get(timeout=60)
        print(len(set(res)) == 1 and res[0] == work(0))
    """)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "True"


@pytest.mark.parametrize("layer", ["workqueue", "omp"])
def test_concurrent_batches_on_every_threading_layer(layer):
    """Four Python threads run ``parfor`` batches at once: bit-identical to a serial run. Under ``workqueue``
    (numba's fallback where OpenMP and TBB are absent) this aborted the process ("Concurrent access has been
    detected"); legkin serializes the batches of a layer that is not thread-safe."""
    proc = run_py("""
        import threading, numba, numpy as np
        from legkin import quadruped
        q = np.tile([0.1, 0.8, 1.2], (20000, 1))
        ref = quadruped.fk(q, "LF")
        same = []
        def run():
            for _ in range(25):
                same.append(np.array_equal(quadruped.fk(q, "LF"), ref))
        threads = [threading.Thread(target=run) for _ in range(4)]
        for t in threads: t.start()
        for t in threads: t.join()
        print(numba.threading_layer(), all(same), len(same))
    """, env={"NUMBA_THREADING_LAYER": layer})
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.split() == [layer, "True", "100"]


# --- numba's cache ----------------------------------------------------------------------------------------------

KERNELS = """
from legkin._kernels import kernel


@kernel(entry=True)
def twice(x):
    return 2.0 * x


@kernel(entry=True)
def thrice(x):
    return 3.0 * x
"""

CALL_KERNELS = """
    import sys, warnings
    sys.path.insert(0, {where!r})
    warnings.simplefilter("always")
    import kmod
    print(kmod.twice(1.5), kmod.thrice(1.5))
    print("compiled", sum(len(k.stats.cache_misses) for k in (kmod.twice, kmod.thrice)))
"""


def _damage(files: dict[str, Path], how: str) -> Path:
    """Damage the cache of ``kmod.twice`` as ``how`` says; the file damaged."""
    nbi, nbc = files["twice.nbi"], files["twice.nbc"]
    if how == "truncated index":
        nbi.write_bytes(nbi.read_bytes()[:20])
        return nbi
    if how == "garbage index":
        nbi.write_bytes(os.urandom(300))
        return nbi
    if how == "truncated data":
        nbc.write_bytes(nbc.read_bytes()[: nbc.stat().st_size // 2])
        return nbc
    if how == "flipped bytes":
        raw = bytearray(nbc.read_bytes())
        for i in range(len(raw) // 2, len(raw) // 2 + 64):
            raw[i] ^= 0xFF
        nbc.write_bytes(bytes(raw))
        return nbc
    if how == "swapped data":  # thrice's machine code under twice's name
        nbc.write_bytes(files["thrice.nbc"].read_bytes())
        return nbc
    assert how == "swapped index"
    nbi.write_bytes(files["thrice.nbi"].read_bytes())
    return nbi


@pytest.fixture(scope="module")
def warm_cache(tmp_path_factory) -> Path:
    """A directory with ``kmod.py`` (two kernels) and their numba cache beside it (``__pycache__``: numba names
    it relative to the source file, so that a copy of the directory is a cache hit), made by one process."""
    where = tmp_path_factory.mktemp("kmod")
    (where / "kmod.py").write_text(KERNELS)
    warm = run_py(CALL_KERNELS.format(where=str(where)), env={"NUMBA_CACHE_DIR": ""})
    assert warm.returncode == 0 and warm.stdout.split() == ["3.0", "4.5", "compiled", "2"], warm.stderr
    return where


@pytest.mark.parametrize("how", ["truncated index", "garbage index", "truncated data", "flipped bytes",
                                 "swapped data", "swapped index"])
def test_damaged_cache_file_is_discarded_and_rebuilt(warm_cache, tmp_path, how):
    """A damaged cache file (the issue: a truncated index gave EOFError in every later process, garbage
    UnpicklingError, flipped bytes SIGABRT, a swapped file SIGSEGV or another kernel's answer): the next process
    warns naming the file, compiles the kernel again and gets the right answer; the process after it loads the
    rebuilt entry without a warning."""
    import shutil

    (tmp_path / "kmod.py").write_bytes((warm_cache / "kmod.py").read_bytes())
    shutil.copystat(warm_cache / "kmod.py", tmp_path / "kmod.py")  # numba's source stamp: the same file
    shutil.copytree(warm_cache / "__pycache__", tmp_path / "__pycache__")
    env = {"NUMBA_CACHE_DIR": ""}
    call = CALL_KERNELS.format(where=str(tmp_path))
    found = (tmp_path / "__pycache__").rglob("kmod.*.nb?")
    files = {f"{p.name.split('.')[1].split('-')[0]}.{p.suffix[1:]}": p for p in found}
    assert sorted(files) == ["thrice.nbc", "thrice.nbi", "twice.nbc", "twice.nbi"], files
    damaged = _damage(files, how)
    hit = run_py(call, env=env)
    assert hit.returncode == 0, hit.stderr[-3000:]
    assert hit.stdout.split() == ["3.0", "4.5", "compiled", "1"], (hit.stdout, hit.stderr)
    assert "CacheWarning" in hit.stderr and str(damaged) in hit.stderr, hit.stderr
    again = run_py(call, env=env)
    assert again.stdout.split() == ["3.0", "4.5", "compiled", "0"] and "Warning" not in again.stderr, again.stderr


READ_ONLY = ("mount --bind {src} {src} && mount -o remount,bind,ro {src} && "
             "HOME=/proc/legkin XDG_CACHE_HOME=/proc/legkin NUMBA_CACHE_DIR=/proc/legkin {python} -c {code}")


def _read_only_run(src: str, code: str) -> subprocess.CompletedProcess:
    """Run ``code`` with ``src`` mounted read-only and every numba cache location unwritable (a private mount
    namespace); skips where there is none."""
    import shlex

    probe = subprocess.run(["unshare", "--mount", "true"], capture_output=True)
    if probe.returncode != 0:
        pytest.skip("no private mount namespace here (unshare --mount)")
    script = READ_ONLY.format(src=shlex.quote(src), python=shlex.quote(sys.executable),
                              code=shlex.quote(textwrap.dedent(code)))
    return subprocess.run(["unshare", "--mount", "bash", "-c", script], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": SRC}, timeout=300)


def test_no_writable_cache_location_loads_the_readable_cache():
    """The issue's case: site-packages, $HOME and NUMBA_CACHE_DIR read-only, a complete cache in the package's
    ``__pycache__``. Every call raised ``RuntimeError: no locator available``; now the kernels load from that cache
    (none compiled) with one CacheWarning."""
    code = """
        import warnings, numpy as np
        warnings.simplefilter("always")
        from legkin import tripod, _kernels
        m = tripod.ik(np.array([0.2, -0.1]))
        print(np.round(tripod.fk(m), 12).tolist())
        print("compiled", sum(len(r().stats.cache_misses) for r in _kernels._cached_kernels if r() is not None))
    """
    warm = run_py(code, env={"NUMBA_CACHE_DIR": ""})
    assert warm.returncode == 0, warm.stderr[-2000:]
    proc = _read_only_run(SRC, code)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.splitlines() == [warm.stdout.splitlines()[0], "compiled 0"], proc.stdout
    assert proc.stderr.count("CacheWarning") == 1, proc.stderr


def test_no_cache_at_all_compiles_in_memory(tmp_path):
    """No writable location and nothing cached: the kernels compile in memory, one warning."""
    (tmp_path / "kmod.py").write_text(KERNELS)
    proc = _read_only_run(str(tmp_path), CALL_KERNELS.format(where=str(tmp_path)))
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.split() == ["3.0", "4.5", "compiled", "2"], proc.stdout
    assert proc.stderr.count("CacheWarning") == 1, proc.stderr
    assert not list(tmp_path.rglob("*.nb?"))


def test_numba_cache_internals_are_the_checked_ones():
    """legkin._cache subclasses numba's cache classes (not an extension API): it was read and tested against the numba
    versions of ``CHECKED_NUMBA``. A numba outside them fails here, so that it is checked before it is declared."""
    import numba

    from legkin import _cache

    assert _cache.numba_checked(), f"numba {numba.__version__}: check legkin/_cache.py against its numba.core.caching"
    from numba.core import caching

    for name in ("_load_index", "_save_index", "_load_data", "_save_data", "_open_for_write", "_dump"):
        assert callable(getattr(caching.IndexDataCacheFile, name))
    assert caching.FunctionCache._impl_class._locator_classes[0].__name__.lstrip("_") == "UserProvidedCacheLocator"


# --- signals, the viewer's address, a broken pipe ---------------------------------------------------------------

def _descendants(pid: int) -> list[int]:
    """The process ids below ``pid`` (from /proc)."""
    children: dict[int, list[int]] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    out, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            out.append(child)
            todo.append(child)
    return out


def _alive(pid: int) -> bool:
    """True if ``pid`` runs (a zombie, dead but not reaped, does not count)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.parametrize("signum, status", [(2, 130), (15, 143)], ids=["SIGINT", "SIGTERM"])
def test_signal_stops_check_and_its_workers(signum, status):
    """Ctrl-C (SIGINT) or SIGTERM to ``legkin check --jobs 2`` while its workers run: the command exits within 2 s
    with 128 + the signal's number and leaves no process behind (the issue: Ctrl-C waited up to 115 s for the
    workers; SIGTERM killed the parent and left 2 workers and the resource tracker running)."""
    import signal
    import time

    proc = _legkin("check", "tripod", "hybrid_leg", "--jobs", "2", "--samples", "100000", "--quiet")
    below: list[int] = []
    try:
        deadline = time.monotonic() + 60
        while len(_descendants(proc.pid)) < 3 and time.monotonic() < deadline:  # 2 workers and a resource tracker
            time.sleep(0.2)
        time.sleep(2.0)  # the workers are busy
        below = _descendants(proc.pid)
        assert len(below) >= 2, "the workers did not start"
        t0 = time.monotonic()
        os.kill(proc.pid, signal.Signals(signum))
        code = proc.wait(timeout=30)
        seconds = time.monotonic() - t0
        left = _left_behind(below, t0 + 5)
    finally:
        _reap(proc, below)
    stderr = proc.stderr.read()  # until its last writer, the resource tracker, is gone
    assert code == status, stderr
    assert seconds < 2.0, f"exited {seconds:.1f} s after the signal"
    assert not left, f"processes left behind: {left}"
    # the killed workers' tqdm locks (named semaphores) made the resource tracker warn of leaked semaphores
    assert "leaked" not in stderr, stderr


def _legkin(*argv: str) -> subprocess.Popen:
    """``python -m legkin ARGV`` started (stdout and stderr piped, text), with Ctrl-C's default action: a shell's
    background job (``pytest &``, nohup) ignores SIGINT, and Python then installs no KeyboardInterrupt for it."""
    import signal

    return subprocess.Popen([sys.executable, "-m", "legkin", *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env={**os.environ, "PYTHONPATH": SRC},
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _left_behind(pids: list[int], until: float) -> list[int]:
    """The processes of ``pids`` still running at the monotonic time ``until`` (or as soon as none runs)."""
    import time

    while any(_alive(p) for p in pids) and time.monotonic() < until:
        time.sleep(0.05)
    return [p for p in pids if _alive(p)]


def _reap(proc: subprocess.Popen, below: list[int]) -> None:
    """Kill ``proc`` if it runs, and the processes of ``below`` (those left behind: the faults) that still do."""
    import signal

    if proc.poll() is None:
        proc.kill()
    for p in below:
        if _alive(p):
            os.kill(p, signal.SIGKILL)


def _listening(pid: int) -> list[str]:
    """The local addresses ``pid``'s TCP sockets listen on (from /proc/net/tcp, tcp6)."""
    inodes = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        try:
            target = os.readlink(fd)
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    out = []
    for table in ("tcp", "tcp6"):
        for line in Path(f"/proc/net/{table}").read_text().splitlines()[1:]:
            f = line.split()
            if f[3] == "0A" and f[9] in inodes:  # 0A: LISTEN
                addr, port = f[1].split(":")
                out.append(f"{'.'.join(str(int(addr[i:i + 2], 16)) for i in (6, 4, 2, 0)) if len(addr) == 8 else addr}"
                           f":{int(port, 16)}")
    return out


@pytest.mark.parametrize("host, expect, signum, status", [(None, "127.0.0.1", 1, 129), ("0.0.0.0", "0.0.0.0", 2, 130)],
                         ids=["default-SIGHUP", "open-SIGINT"])
def test_viewer_binds_localhost_and_stops_on_signals(host, expect, signum, status):
    """``legkin view`` serves on 127.0.0.1 only (the issue: on every interface); ``--host 0.0.0.0`` opens it. SIGHUP
    (the terminal closed) stops its meshcat server too (it runs in a session of its own, so the terminal's SIGHUP
    never reaches it; the issue: it kept running), and the command exits with 128 + the signal's number (it exited
    0; SIGTERM takes SIGHUP's path, legkin._signals.signals_raise)."""
    import signal
    import time

    proc = _legkin("view", "tripod", *([] if host is None else ["--host", host]))
    below: list[int] = []
    try:
        assert proc.stdout is not None and "meshcat viewer" in proc.stdout.readline()
        below = _descendants(proc.pid)
        assert below, "no server process"
        addresses = [a for p in below for a in _listening(p)]
        proc.send_signal(signal.Signals(signum))
        code = proc.wait(timeout=15)
        left = _left_behind(below, time.monotonic() + 10)
    finally:
        _reap(proc, below)
    assert not left, "the meshcat server outlived legkin view"
    assert code == status, (code, proc.stderr.read())
    assert addresses, "no listening socket found"
    web = [a for a in addresses if not a.endswith(":6000") and not a.split(":")[-1].startswith("60")]
    assert web and all(a.startswith(expect + ":") for a in web), addresses
    assert all(a.startswith(("127.0.0.1:", expect + ":")) for a in addresses), addresses


def test_broken_pipe_exits_quietly_with_its_own_code():
    """``legkin list | head -0``: the reader went away. Exit 141 (128 + SIGPIPE), nothing on stderr; it was 1, the
    status that means "checks failed"."""
    proc = subprocess.run(f"{sys.executable} -m legkin check bolt --samples 20 --quiet | head -c 0; "
                          "exit ${PIPESTATUS[0]}", shell=True, executable="/bin/bash", capture_output=True,
                          text=True, env={**os.environ, "PYTHONPATH": SRC}, timeout=300)
    assert proc.returncode == 141, (proc.returncode, proc.stderr)
    assert proc.stderr == ""


# --- small gaps of the error contract ---------------------------------------------------------------------------

def test_leg_check_does_not_depend_on_history():
    """wheel_leg accepted ``leg=True`` or ``1.0`` after one call with ``leg=1`` (an ``lru_cache`` keyed on the leg
    value: ``True == 1 == 1.0``) but refused them in a fresh process. Now refused after it too."""
    proc = run_py("""
        import numpy as np
        from legkin import wheel_leg
        from legkin.errors import InvalidParameterError
        q = np.array([1.2, 0.3, 0.1])
        wheel_leg.fk(q, 1); wheel_leg.module_origin(1)
        for leg in (True, 1.0):
            for call in (lambda: wheel_leg.fk(q, leg), lambda: wheel_leg.module_origin(leg)):
                try:
                    call()
                    print("accepted", leg)
                except InvalidParameterError:
                    print("refused", leg)
    """)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["refused", "True"] * 2 + ["refused", "1.0"] * 2


HUGE_CALLS = [
    "wheel_leg.linkage_points(10**400, 0.2)",
    "wheel_leg.passive_angles(10**400, 0.2)",
    "wheel_leg.linkage_points(1.0, 10**400)",
    "hybrid_leg.extension_motor_angle(1e308)",
    "hybrid_leg.extension_motor_angle([0.1, -1e308])",
    "hybrid_leg.extension_motor_angle(10**400)",
]


def test_huge_numbers_get_legkin_errors():
    """An int beyond the largest float raised ``OverflowError``; ``extension_motor_angle(1e308)`` returned -inf (its
    inverse overflows). Now an InvalidInputError that says so (one process for the six calls)."""
    proc = run_py(f"""
        from legkin import hybrid_leg, wheel_leg
        from legkin.errors import InvalidInputError
        for call in {HUGE_CALLS!r}:
            try:
                print(repr(eval(call)))
            except InvalidInputError as exc:
                print("InvalidInputError:", exc)
    """)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert len(lines) == len(HUGE_CALLS), proc.stdout
    for call, line in zip(HUGE_CALLS, lines):
        assert line.startswith("InvalidInputError:"), (call, line)
        assert "digits" in line or "overflows" in line, (call, line)


def test_batch_error_names_the_first_bad_row():
    """An inf in one row refused the whole batch without saying which row."""
    proc = run_py("""
        import numpy as np
        from legkin import tripod
        t = np.tile([0.2, -0.1], (6, 1)); t[3, 1] = np.inf; t[5, 0] = np.nan
        try:
            tripod.ik(t)
        except Exception as exc:
            print(type(exc).__name__, exc)
    """)
    assert proc.stdout.strip() == "InvalidInputError target must be finite: row 3 has inf (target[3, 1])", proc


def test_uncompiled_path_raises_the_same_errors():
    """Under ``NUMBA_DISABLE_JIT=1 -W error``, ``tripod.ik`` of an unreachable target raised numpy's RuntimeWarning
    where the compiled path raises UnreachableError; a batch warned where it gives NaN rows."""
    code = """
        import warnings, numpy as np
        warnings.simplefilter("error")
        from legkin import tripod
        try:
            tripod.ik(np.array([3.0, 0.0]))
        except Exception as exc:
            print(type(exc).__name__)
        q, ok = tripod.ik(np.array([[3.0, 0.0], [0.2, -0.1]]), return_mask=True)
        print(ok.tolist(), bool(np.isnan(q[0]).all()))
    """
    compiled = run_py(code)
    uncompiled = run_py(code, env={"NUMBA_DISABLE_JIT": "1"})
    assert compiled.stdout.split() == ["UnreachableError", "[False,", "True]", "True"], compiled.stderr
    assert uncompiled.stdout == compiled.stdout, uncompiled.stderr[-2000:]


# --- memory, and a check row's tolerance ------------------------------------------------------------------------

def test_large_batches_work_in_chunks():
    """A wheel_leg.ik batch needed ~330 bytes a target, 13x its answer (3.2 GiB extra for 10^7 targets); tripod.ik
    168 B against a 25 B answer, wheel_leg.ik_all 370 B against 50 B, a 6-DOF leg's ik 95 B against 49 B. Now every
    batch runs by chunks (here of 512 targets, so that the test is fast; scripts/batch_memory.py measures all of
    them at 10^6): the memory beyond the answer stays below the answer's size, and the answers are the same bit for
    bit as one whole batch's, also where an argument has one row per target."""
    proc = run_py("""
        import tracemalloc, numpy as np
        from legkin import _batch, hybrid_leg, legs, tripod, wheel_leg
        n, rng = 20_000, np.random.default_rng(0)
        box = lambda lo, hi: np.asarray(lo) + (np.asarray(hi) - np.asarray(lo)) * rng.random((n, len(lo)))
        wq = box([0.9, -0.3, -0.3], [1.5, 0.3, 0.3])
        tq = tripod.ik(np.column_stack([rng.uniform(-0.5, 0.5, n), rng.uniform(-1, 1, n)]))
        leg = next(iter(legs.from_model(legs.load_erd("talos")[0]).values()))
        mid, half = (leg.lower + leg.upper) / 2, (leg.upper - leg.lower) / 2
        calls = {
            "wheel_leg.ik": lambda x=wheel_leg.fk(wq, "FL"): wheel_leg.ik(x, "FL", return_mask=True),
            "wheel_leg.ik_all": lambda x=wheel_leg.fk(wq, "FL"): wheel_leg.ik_all(x, "FL", return_mask=True),
            "tripod.fk": lambda: tripod.fk(tq, return_mask=True),
            "tripod.ik": lambda x=tripod.fk(tq): tripod.ik(x, return_mask=True),
            "hybrid_leg.ik": lambda x=hybrid_leg.fk(box([-0.2, -0.2, 2.8], [0.2, 0.2, 3.2])):
                hybrid_leg.ik(x, return_mask=True),
            "Leg6.ik": lambda x=leg.fk(box(mid - 0.3 * half, mid + 0.3 * half)): leg.ik(x, return_mask=True),
            # per-target arguments are cut with the rows (a chunk must not read the first chunk's q_near or alpha)
            "hybrid_leg.ik(q_near=per_target)": lambda x=hybrid_leg.fk(box([-0.2, -0.2, 2.8], [0.2, 0.2, 3.2])),
                near=box([-1.0, -1.0, 2.6], [1.0, 1.0, 3.4]): hybrid_leg.ik(x, q_near=near, return_mask=True),
            "wheel_leg.fk(alpha=per_target)": lambda a=rng.uniform(-0.5, 0.5, n), ww=rng.uniform(-0.01, 0.01, n):
                wheel_leg.fk(wq, "FL", alpha=a, w=ww, return_mask=True),
            "wheel_leg.ik(alpha=per_target)": lambda a=rng.uniform(-0.5, 0.5, n), x=wheel_leg.fk(wq, "FL"):
                wheel_leg.ik(x, "FL", alpha=a, return_mask=True),
        }
        for name, call in calls.items():
            _batch.CHUNK = 10 ** 9
            whole = call()
            _batch.CHUNK = 512
            tracemalloc.start()
            out = call()
            peak = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
            answer = sum(a.nbytes for a in out)
            same = all(np.array_equal(a, b, equal_nan=True) for a, b in zip(out, whole))
            print(name, round((peak - answer) / n, 1), round(answer / n, 1), same)
    """)
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = [line.split() for line in proc.stdout.splitlines()]
    assert len(lines) == 9, proc.stdout
    for name, extra, answer, same in lines:
        assert float(extra) < float(answer), f"{name}: {extra} bytes a target beyond the answer ({answer} bytes)"
        assert same == "True", f"{name}: the chunks' answers differ from one batch's"


def test_tripod_jacobian_rows_hold_to_their_conditioning_bound():
    """The issue: ``legkin check tripod --samples 20000`` failed the "[alpha=pi/2] A_u vs Pinocchio" row by chance
    (3.31e-12 against 1e-12 at alpha_y = -0.928, alpha_z = 1.947, where |A_u| = 1563). The row now holds each sample
    to eps x amplification x AMP_CONSTANT (scripts/tripod_conditioning_sweep.py measured the constant over 20 seeds x
    10^3..10^5 samples); that sample, with 300 random ones, is within the bound."""
    import math

    import numpy as np

    from legkin import load
    from legkin import tripod as at
    from legkin.tripod import checks
    from legkin.tripod.configuration import sample_workspace

    geo = at.Geometry(alpha=math.pi / 2)
    ay, az = sample_workspace(300, np.random.default_rng(1), geo)
    ay, az = np.append(ay, -0.9279651073828754), np.append(az, 1.9469632412795885)
    q = at.ik_joints(np.stack([ay, az], axis=-1), geometry=geo)
    err, amp = checks.actuation_jacobian_errors(load("tripod", alpha=math.pi / 2), geo, q, ay, az)
    eps = np.finfo(float).eps
    assert np.all(err <= checks.AMP_CONSTANT * eps * amp), (err / (eps * amp)).max()
    # the bound explains the sample that failed: a large amplification (cond(G) ~ 1543), not a wrong formula
    assert amp[-1] > 10 * np.median(amp), (amp[-1], np.median(amp))


def test_tripod_fk_round_trip_holds_to_its_conditioning_bound():
    """The check sweep (issue 25): "[alpha=pi/4] fk(ik(u)) round trip, platform rotation" reached 1.41e-12 against a
    fixed 1e-12 at seed 19, 10^5 samples, at a pose near a forward singularity (1 / sigma_min(A_u) = 261). The row
    now holds each sample to eps x amplification x FK_CONSTANT (scripts/tripod_conditioning_sweep.py --row fk
    measured the constant over 20 seeds x 10^3..10^5 samples); that sample, with 300 random ones, is within it."""
    import math

    import numpy as np

    from legkin import tripod as at
    from legkin.tripod import checks
    from legkin.tripod.configuration import sample_workspace

    geo = at.Geometry(alpha=math.pi / 4)
    ay, az = sample_workspace(300, np.random.default_rng(19), geo)
    ay, az = np.append(ay, -0.0028632618673902765), np.append(az, 2.356265716541423)
    q = at.ik_joints(np.stack([ay, az], axis=-1), geometry=geo)
    far = 1 + np.cos(ay) * np.cos(az) > checks.NEAR_FLIP
    err, amp, inc, inc_amp = checks.fk_round_trip_errors(geo, q, ay, az, far)
    eps = np.finfo(float).eps
    assert np.all(err <= checks.FK_CONSTANT * eps * amp), (err / (eps * amp)).max()
    assert np.all(inc[far] <= checks.INCONSISTENCY_CONSTANT * eps * inc_amp[far])
    # the bound explains the sample that failed: a large amplification, not a wrong fk
    assert err[-1] > 1e-12 and amp[-1] > 50 * np.median(amp), (err[-1], amp[-1], np.median(amp))
