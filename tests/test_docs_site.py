"""The documentation site: ``mkdocs build --strict`` builds it, and each API page, opened in headless Chromium,
lists every public function of the modules it documents (their ``__all__``).

Needs the ``dev`` extra (mkdocs-material, mkdocstrings) and skips without it; ``.ci/run`` installs it and then
runs this file.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from legkin.viewer import chromium_path

ROOT = Path(__file__).resolve().parents[1]
HAVE_MKDOCS = all(importlib.util.find_spec(m) is not None for m in ("mkdocs", "mkdocstrings", "material"))
pytestmark = [
    pytest.mark.skipif(not HAVE_MKDOCS, reason="needs the dev extra (pip install -e '.[dev]'); .ci/run installs it"),
    pytest.mark.skipif(chromium_path() is None and not os.environ.get("CI"),
                       reason="needs headless Chromium (apt-get install chromium); required on CI"),
]
PAGES = sorted((ROOT / "docs" / "reference").glob("*.md"))


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("site")
    run = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-f", str(ROOT / "mkdocs.yml"), "-d", str(out)],
        capture_output=True, text=True, timeout=600, env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
    )
    assert run.returncode == 0, run.stdout + run.stderr
    return out


def rendered_dom(page: Path) -> str:
    """The DOM of ``page`` after headless Chromium ran its scripts."""
    with tempfile.TemporaryDirectory(prefix="legkin-chromium-") as profile:
        cmd = [
            str(chromium_path()), "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
            "--disable-component-update", "--disable-sync", "--no-first-run", f"--user-data-dir={profile}",
            "--dump-dom", page.as_uri(),
        ]
        return subprocess.run(cmd, check=True, timeout=180, capture_output=True, text=True).stdout


def documented_modules(page: Path) -> list[str]:
    """The modules a reference page documents (its ``::: module`` directives)."""
    return re.findall(r"^::: ([\w.]+)", page.read_text(), re.M)


def test_every_mechanism_has_an_api_page() -> None:
    from legkin._registry import list_models

    documented = {m for page in PAGES for m in documented_modules(page)}
    for name in list_models("legkin"):
        assert f"legkin.{name}.kinematics" in documented, f"no API reference page documents legkin.{name}"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.stem)
def test_api_page_lists_its_functions(site: Path, page: Path) -> None:
    dom = rendered_dom(site / "reference" / page.stem / "index.html")
    ids = set(re.findall(r'id="([^"]+)"', dom))
    role = re.search(r":(func|meth|mod|class|data|attr|exc):", dom)
    assert role is None, f"{page.name}: a Sphinx role is shown as text: {dom[role.start() - 60:role.end() + 60]!r}"
    modules = documented_modules(page)
    assert modules, f"{page} documents no module"
    for name in modules:
        expected = [f"{name}.{n}" for n in public_api(importlib.import_module(name))]
        assert expected, f"{name} has no public function or class"
        missing = [e for e in expected if e not in ids]
        assert not missing, f"{page.name}: the rendered page does not list {missing}"


def public_api(module: object) -> list[str]:
    """The public functions and classes of ``module`` (its ``__all__``, else what it defines) that its package
    defines, with the public methods each class defines, as dotted names relative to the module."""
    names = getattr(module, "__all__", None)
    if names is None:
        names = [n for n, v in vars(module).items() if not n.startswith("_") and getattr(v, "__module__", None)
                 == module.__name__]  # type: ignore[attr-defined]
    out = []
    package = module.__name__.rsplit(".", 1)[0]  # type: ignore[attr-defined]
    for n in names:
        obj = getattr(module, n, None)
        if not str(getattr(obj, "__module__", "")).startswith(package):
            continue  # re-exported from elsewhere (an error class of legkin.errors): documented on its own page
        if inspect.isfunction(obj):
            out.append(n)
        elif inspect.isclass(obj):
            out.append(n)
            out += [f"{n}.{m}" for m, f in vars(obj).items() if inspect.isfunction(f) and not m.startswith("_")
                    and getattr(f, "__doc__", None)]
    return out
