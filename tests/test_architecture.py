"""The layers of docs/ARCHITECTURE.md hold: the import contract, and no import left inside a
function to dodge a cycle."""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("benchmark", "damper", "controllers", "records")


def test_import_contract_is_kept():
    """import-linter's layers contract (pyproject.toml): applications > simulator > controllers >
    damper > records > foundation, imports inside functions included."""
    exe = shutil.which("lint-imports") or str(Path(sys.executable).with_name("lint-imports"))
    if not Path(exe).exists():
        pytest.skip("import-linter is not installed (pip install -e '.[test]')")
    done = subprocess.run([exe, "--config", str(ROOT / "pyproject.toml")], cwd=ROOT, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]


def _function_level_project_imports(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found: list[str] = []

    def visit(node, in_function):
        nonlocal found
        for child in ast.iter_child_nodes(node):
            inside = in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef))
            if in_function and isinstance(child, ast.ImportFrom) and child.level == 0 and child.module \
                    and child.module.split(".")[0] in PACKAGES:
                found.append(f"{path.relative_to(ROOT)}:{child.lineno}: from {child.module} import ...")
            elif in_function and isinstance(child, ast.Import):
                found += [f"{path.relative_to(ROOT)}:{child.lineno}: import {a.name}" for a in child.names
                          if a.name.split(".")[0] in PACKAGES]
            visit(child, inside)

    visit(tree, False)
    return found


def test_no_project_import_inside_a_function():
    """Project modules are imported at module level; only heavy optional third-party packages
    (matplotlib, dask) are imported lazily."""
    found = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            found += _function_level_project_imports(path)
    assert not found, "\n".join(found)


@pytest.mark.parametrize("library", ["records", "damper", "controllers"])
def test_libraries_do_not_load_the_simulator_or_the_applications(library):
    code = (f"import sys, {library}; import importlib, pkgutil, {library} as p\n"
            f"for m in pkgutil.walk_packages(p.__path__, '{library}.'):\n"
            f"    importlib.import_module(m.name)\n"
            "bad = sorted(m for m in sys.modules if m.startswith(('benchmark.simulator', 'benchmark.applications')))\n"
            "print(bad); raise SystemExit(1 if bad else 0)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert done.returncode == 0, done.stdout + done.stderr


def test_nothing_imports_the_command_line_entry_point():
    """``benchmark.applications.cli`` sits on top of every command module: a module that imports it
    back (as ``speed`` once did to call ``main``) closes an import cycle through the CLI."""
    found = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            if path.relative_to(ROOT).as_posix() in ("benchmark/applications/cli.py", "benchmark/__main__.py"):
                continue
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                         else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
                if any(n == "benchmark.applications.cli" for n in names) or (
                        isinstance(node, ast.ImportFrom) and node.module == "benchmark.applications"
                        and any(a.name == "cli" for a in node.names)):
                    found.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert not found, "imports of the CLI entry point: " + ", ".join(found)


def test_architecture_names_where_each_concept_lives_and_the_names_exist():
    """docs/ARCHITECTURE.md's "One concept, one place" table: every dotted name in it is importable
    (a module, or an attribute of one), so the table cannot drift from the code."""
    import importlib
    import re

    text = (ROOT / "docs" / "ARCHITECTURE.md").read_text(encoding="utf-8")
    section = text.split("## One concept, one place", 1)[1].split("\n## ", 1)[0]
    names = sorted({n for n in re.findall(r"`([a-z_]+(?:\.[A-Za-z_]+)+)", section)
                    if n.split(".")[0] in PACKAGES})
    assert len(names) >= 15, names
    missing = []
    for name in names:
        parts = name.split(".")
        for cut in range(len(parts), 0, -1):
            try:
                obj = importlib.import_module(".".join(parts[:cut]))
            except ImportError:
                continue
            try:
                for attr in parts[cut:]:
                    obj = getattr(obj, attr)
            except AttributeError:
                missing.append(name)
            break
        else:
            missing.append(name)
    assert not missing, missing


def test_no_module_has_an_invalid_escape_sequence():
    """A docstring with ``\\d`` (LaTeX in a non-raw string) is a SyntaxWarning today and an error in
    a later Python; it slipped in twice, so every module is compiled with warnings as errors."""
    import warnings

    bad = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                try:
                    compile(path.read_text(encoding="utf-8"), str(path), "exec")
                except (SyntaxError, SyntaxWarning, DeprecationWarning) as exc:
                    bad.append(f"{path.relative_to(ROOT)}: {exc}")
    assert not bad, "\n".join(bad)
