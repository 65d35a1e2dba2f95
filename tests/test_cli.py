"""The command line: every misuse is one line on stderr and a non-zero exit (never a traceback); options reach
the library; progress bars on stderr only on a terminal."""

from __future__ import annotations

import fcntl
import json
import os
import pty
import struct
import subprocess
import sys
import termios

import pytest

from legkin import validation
from legkin.__main__ import main

NO_DIR = "/nonexistent-legkin-dir/out"


def _misuse(tmp_path):
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    return [
        (["check", "--random-seed", "-1"], "--random-seed"),
        (["check", "--seed", "1"], "unrecognized arguments: --seed"),
        (["check", "--random-seed", "x"], "--random-seed"),
        (["check", "--samples", "0"], "--samples"),
        (["check", "--samples", "-5"], "--samples"),
        (["check", "--samples", "1.5"], "--samples"),
        (["check", "--ik-targets", "0"], "--ik-targets"),
        (["check", "no_such_robot"], "known models"),
        (["check", "quadruped", "no_such_robot"], "known models"),
        (["check", "--json", f"{NO_DIR}/c.json"], "does not exist"),
        (["check", "--json", str(tmp_path)], "is a directory"),
        (["check", "--json", f"{a_file}/c.json"], "is not a directory"),
        (["check", "--plots", str(a_file)], "not a directory"),
        (["view", "no_such_robot"], "known models"),
        (["view", "quadruped", "--q", "a"], "--q"),
        (["view", "quadruped", "--q", "nan", *["0"] * 11], "finite"),
        (["view", "quadruped", "--q", "inf", *["0"] * 11], "finite"),
        (["view", "quadruped", "--q", "1", "2"], "takes 12 values"),
        (["view", "quadruped", "--html", f"{NO_DIR}/v.html"], "does not exist"),
        (["view", "quadruped", "--html", str(tmp_path)], "is a directory"),
        (["view", "quadruped", "--pose", "no_such_pose", "--html", str(tmp_path / "v.html")], "poses:"),
        (["view", "quadruped", "--animate", "no_such_clip", "--html", str(tmp_path / "v.html")], "animations:"),
        (["view", "quadruped", "--animate", "foot_circles", "--pose", "standing"], "--animate"),
        (["view", "quadruped", "--pose", "standing", "--q", "0"], "not allowed"),
        (["bench", "--n", "0"], "--n"),
        (["bench", "--random-seed", "-1"], "--random-seed"),
        (["bench", "--json", f"{NO_DIR}/b.json"], "does not exist"),
        (["bench", "no_such_robot"], "known models"),
        (["generate", "no_such_robot"], "known models"),
        ([], "COMMAND"),
        (["no_such_command"], "invalid choice"),
        (["check", "--no-such-option"], "unrecognized"),
    ]


@pytest.mark.parametrize("case", range(32))
def test_misuse_is_one_line_and_status_2(case, tmp_path, capsys):
    cases = _misuse(tmp_path)
    assert len(cases) == 32
    argv, word = cases[case]
    assert main(argv) == 2
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("legkin") and "error" in lines[0], err
    assert word in lines[0], err
    assert "Traceback" not in out + err


@pytest.mark.parametrize(
    "argv",
    [
        ["view", "tripod", "--html", f"{NO_DIR}/v.html"],
        ["check", "--random-seed", "-1"],
        ["check", "--samples", "0"],
        ["check", "--json", f"{NO_DIR}/c.json"],
        ["view", "tripod", "--q", "x"],
    ],
)
def test_misuse_in_a_real_process(argv):
    proc = subprocess.run([sys.executable, "-m", "legkin", *argv], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "Traceback" not in proc.stderr


def test_write_failure_is_one_line(tmp_path, monkeypatch, capsys):
    # The path passed the up-front checks, then the write fails (e.g. the disk is full).
    def full(*args, **kwargs):
        raise OSError(28, "No space left on device", str(tmp_path / "c.json"))

    monkeypatch.setattr(validation, "write_json", full)
    assert main(["check", "quadruped", "--samples", "20", "--json", str(tmp_path / "c.json"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "No space left on device" in err[0] and "c.json" in err[0]


def test_internal_error_is_one_line_status_3(monkeypatch, capsys):
    def broken(*args, **kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr(validation, "run_checks", broken)
    monkeypatch.delenv("LEGKIN_DEBUG", raising=False)
    assert main(["check", "quadruped"]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "internal error" in err[0] and "RuntimeError: boom" in err[0]
    monkeypatch.setenv("LEGKIN_DEBUG", "1")
    with pytest.raises(RuntimeError):
        main(["check", "quadruped"])


def test_interrupt_is_status_130(monkeypatch, capsys):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(validation, "run_checks", interrupted)
    assert main(["check", "quadruped"]) == 130
    assert capsys.readouterr().err.strip() == "legkin: interrupted"


# ---------------------------------------------------------------------------------------------- options
def _capture_run_checks(monkeypatch):
    seen = {}

    def fake(models, **kwargs):
        seen.update(kwargs, models=models)
        return {}

    monkeypatch.setattr(validation, "run_checks", fake)
    return seen


def test_check_passes_ik_options(monkeypatch, capsys):
    seen = _capture_run_checks(monkeypatch)
    assert main(["check", "wheel_leg", "--samples", "30"]) == 0
    assert seen["ik_targets"] is None and seen["classify"] == 2000 and seen["samples"] == 30
    assert seen["models"] == ["wheel_leg"]
    assert main(["check", "--ik-targets", "7", "--classify-all", "--random-seed", "3"]) == 0
    assert seen["ik_targets"] == 7 and seen["classify"] is None and seen["seed"] == 3
    assert seen["models"] is None
    assert seen["progress"] is False  # stderr is captured, not a terminal


def test_check_ik_targets_sets_the_robustness_row(tmp_path):
    out = tmp_path / "c.json"
    args = ["check", "wheel_leg", "--samples", "20", "--ik-targets", "24", "--classify-all", "--json", str(out)]
    assert main(args) == 0
    rows = [r for r in json.loads(out.read_text())["models"]["wheel_leg"]["checks"] if r.get("counts")]
    assert len(rows) == 1 and rows[0]["counts"]["targets"] == 24


# ---------------------------------------------------------------------------------------------- progress
def _run_on_terminal(argv, timeout=300):
    """Run ``legkin argv`` with stderr on a pseudo-terminal (100 columns); returns (status, stderr bytes)."""
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
    proc = subprocess.Popen(
        [sys.executable, "-m", "legkin", *argv], stdout=subprocess.DEVNULL, stderr=slave, stdin=subprocess.DEVNULL
    )
    os.close(slave)
    data = b""
    try:
        while True:
            try:
                chunk = os.read(master, 4096)
            except OSError:  # EIO: the child closed the terminal
                break
            if not chunk:
                break
            data += chunk
        return proc.wait(timeout=timeout), data
    finally:
        os.close(master)
        if proc.poll() is None:
            proc.kill()


def test_check_progress_on_a_terminal_only():
    argv = ["check", "quadruped", "--samples", "30"]
    status, err = _run_on_terminal(argv)
    assert status == 0 and b"legkin check" in err and b"quadruped" in err
    status, err = _run_on_terminal([*argv, "--quiet"])
    assert status == 0 and err == b""
    proc = subprocess.run([sys.executable, "-m", "legkin", *argv], capture_output=True, timeout=300)
    assert proc.returncode == 0 and proc.stderr == b""  # stderr is a pipe: no bar


def test_run_checks_progress_bar(capsys):
    validation.run_checks(["quadruped"], samples=20, progress=True)
    assert "legkin check" in capsys.readouterr().err
    validation.run_checks(["quadruped"], samples=20)
    assert capsys.readouterr().err == ""


def test_bench_progress_bar(capsys, monkeypatch):
    from legkin import bench

    bar = bench._Progress(2, "quadruped", enabled=True)
    bar.show("first method (run 1/5)")
    bar.step("first method")
    bar.close()
    err = capsys.readouterr().err
    assert "legkin bench quadruped" in err and "first method" in err
    quiet = bench._Progress(2, "quadruped", enabled=False)
    quiet.step("x")
    quiet.close()
    assert capsys.readouterr().err == ""

    seen = {}

    def fake(models=None, n=None, seed=0, quick=False, quiet=False):
        seen.update(quiet=quiet, seed=seed, n=n)
        return {"models": {}, "single": {}, "skipped": {}}

    monkeypatch.setattr(bench, "run_bench", fake)
    assert main(["bench", "--quiet", "--n", "5", "--random-seed", "2"]) == 0
    assert seen == {"quiet": True, "seed": 2, "n": 5}


def test_generate_out_writes_the_committed_files(tmp_path):
    """``legkin generate --out DIR`` (what an installed legkin needs) writes the same bytes as urdf/."""
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    run = subprocess.run([sys.executable, "-m", "legkin", "generate", "tripod", "--out", str(tmp_path)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    for name in ("tripod.urdf", "tripod.srdf"):
        assert (tmp_path / name).read_bytes() == (root / "urdf" / name).read_bytes()
    bad = subprocess.run([sys.executable, "-m", "legkin", "generate", "tripod", "--out", str(tmp_path / "tripod.urdf")],
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode != 0 and "Traceback" not in bad.stderr and "not a directory" in bad.stderr


def test_view_floating_stands_on_the_ground(tmp_path, capsys):
    page = tmp_path / "q.html"
    assert main(["view", "quadruped", "--floating", "--html", str(page)]) == 0
    assert page.stat().st_size > 10_000
    assert main(["view", "tripod", "--floating", "--html", str(tmp_path / "t.html")]) == 2
    assert "fixed-base" in capsys.readouterr().err


# ---------------------------------------------------------------------------------------------- worker processes
def test_check_jobs_default_and_option(monkeypatch):
    seen = _capture_run_checks(monkeypatch)
    assert main(["check", "tripod", "--samples", "5"]) == 0
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    assert seen["jobs"] == min(4, cpus)
    assert main(["check", "tripod", "--samples", "5", "--jobs", "1"]) == 0 and seen["jobs"] == 1
    assert main(["check", "-j", "3"]) == 0 and seen["jobs"] == 3
    assert main(["check", "--jobs", "0"]) == 2


def test_run_checks_in_worker_processes_gives_the_same_rows():
    """jobs=2: the models run in two spawned processes (the external robots in one group, with the quadruped,
    whose checks run the legs kernels), same rows and order."""
    models = ["quadruped", "a1", "tripod", "go1"]
    serial = validation.run_checks(models, samples=30, seed=4, ik_targets=40)
    parallel = validation.run_checks(models, samples=30, seed=4, ik_targets=40, jobs=2)
    assert list(parallel) == models
    for name in models:
        a, b = serial[name][0], parallel[name][0]
        assert [repr(r.as_dict()) for r in a] == [repr(r.as_dict()) for r in b]  # repr: NaN == NaN, floats exact
    assert validation._groups(models) == [["tripod"], ["quadruped", "a1", "go1"]]  # dearest first (_COST)


@pytest.mark.parametrize("jobs", [0, -1, 1.5, True, "2"])
def test_run_checks_rejects_bad_jobs(jobs):
    from legkin.errors import InvalidArgumentError

    with pytest.raises(InvalidArgumentError, match="jobs"):
        validation.run_checks(["quadruped"], samples=5, jobs=jobs)


# ---------------------------------------------------------------------------------------------- first run
def test_check_says_when_the_kernels_are_not_cached_yet(tmp_path):
    """A first run after an install (an empty numba cache): ``_first_run_note`` names the count of kernels not yet
    cached (``_kernels.cache_status``: none of them at first, some after one call has compiled its kernels)."""
    code = (
        "import sys; from legkin import _kernels; from legkin.__main__ import _first_run_note; "
        "note = _first_run_note(['tripod']); cached, total = _kernels.cache_status(); "
        "print(cached, total, note is not None, 'of' in (note or '') and str(total - cached) in note)"
    )
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    run = lambda: subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=600)  # noqa: E731
    cold = run().stdout.split()
    assert cold[0] == "0" and int(cold[1]) > 10 and cold[2:] == ["True", "True"], cold
    warm_up = "import numpy as np; from legkin import tripod; tripod.fk(tripod.ik(np.array([0.2, -0.1])))"
    assert subprocess.run([sys.executable, "-c", warm_up], env=env, timeout=600).returncode == 0
    after = run().stdout.split()
    assert 0 < int(after[0]) < int(after[1]) == int(cold[1]), after  # the kernels of those calls, cached


def test_check_prints_the_first_run_note_unless_quiet(monkeypatch, capsys):
    import legkin.__main__ as cli

    seen = _capture_run_checks(monkeypatch)
    monkeypatch.setattr(cli, "_first_run_note", lambda models: f"first run of {models}")
    assert main(["check", "tripod", "--samples", "5"]) == 0 and seen["models"] == ["tripod"]
    assert "first run of ['tripod']" in capsys.readouterr().err
    assert main(["check", "tripod", "--samples", "5", "--quiet"]) == 0
    assert "first run" not in capsys.readouterr().err
    monkeypatch.setattr(cli, "_first_run_note", lambda models: None)
    assert main(["check", "tripod", "--samples", "5"]) == 0 and "first run" not in capsys.readouterr().err
