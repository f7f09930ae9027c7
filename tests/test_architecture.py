"""The package reads as layers (pyproject.toml, ``[tool.importlinter]``): the import contract holds, and it fails on
an upward import and on a cycle, function-level imports included (a copy of the package with one planted module)."""

from __future__ import annotations

import ast
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "bgfn"
LINT = Path(sys.executable).with_name("lint-imports")
#: Imports inside functions that are genuinely optional or heavy (each with a comment saying why at its place).
ALLOWED_FUNCTION_IMPORTS = {("bgfn.nav.pyins_bridge", "pyins"), ("bgfn.train.speed", "torch.profiler"),
                            # scipy.stats (and scipy.signal, which imports it) cost about a second in every process
                            ("bgfn.stats", "scipy.stats"), ("bgfn.data.imu_errors", "scipy"),
                            ("bgfn.data.imu_levels", "scipy")}


def _lint(src: Path, tmp: Path) -> subprocess.CompletedProcess:
    """``lint-imports`` over the package found under ``src``, with the project's contracts, no cache in the repo."""
    env = {"PYTHONPATH": str(src), "PATH": str(LINT.parent), "HOME": str(tmp)}
    return subprocess.run([str(LINT), "--no-cache", "--no-logo", str(ROOT / "pyproject.toml")], cwd=tmp, env=env,
                          capture_output=True, text=True, timeout=300)


def _copy(tmp: Path) -> Path:
    src = tmp / "src"
    shutil.copytree(PACKAGE, src / "bgfn", ignore=shutil.ignore_patterns("__pycache__"))
    return src


@pytest.fixture(scope="module")
def contracts() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["importlinter"]


def test_the_package_keeps_its_contracts(tmp_path):
    res = _lint(PACKAGE.parent, tmp_path)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "0 broken" in res.stdout


@pytest.mark.parametrize("planted, broken", [
    # a lower layer reaching up to the report, at module level
    ({"nav/planted.py": "from bgfn.report import verdict\n"}, "Layers"),
    # the same hidden inside a function (the import graph counts it)
    ({"nav/planted.py": "def f():\n    from bgfn.train import loop\n    return loop\n"}, "Layers"),
    # two modules of one package importing each other
    ({"nav/planted_a.py": "from bgfn.nav import planted_b\n",
      "nav/planted_b.py": "def f():\n    from bgfn.nav import planted_a\n    return planted_a\n"}, "No import cycle"),
    # the paper's evaluation reaching for a study beyond the paper
    ({"evaluate/planted.py": "from bgfn.studies.odometer import bars\n"}, "The paper's pipeline imports no study"),
    # one study importing another, beside the outage sweep they share
    ({"studies/gallery/planted.py": "from bgfn.studies.odometer import bars\n"}, "Studies: odometer"),
    # the filter engine importing an aid
    ({"nav/engine.py": "+from bgfn.nav import gnss_aid\n"}, "The filter engine imports no aid"),
    # the filter run importing a vehicle aid
    ({"nav/filter.py": "+from bgfn.nav import constraints\n"}, "imports no vehicle aid"),
])
def test_the_check_fails_on_a_planted_import(tmp_path, planted, broken):
    src = _copy(tmp_path)
    for where, body in planted.items():
        path = src / "bgfn" / where
        if body.startswith("+"):                      # appended to an existing module
            body = path.read_text(encoding="utf-8") + body[1:]
        path.write_text(body, encoding="utf-8")
    res = _lint(src, tmp_path)
    assert res.returncode != 0, res.stdout
    verdicts = " ".join(res.stdout.split("Broken contracts")[0].split())     # contract names are wrapped
    verdict = re.search(re.escape(broken) + r".*?\b(KEPT|BROKEN)\b", verdicts)
    assert verdict is not None and verdict.group(1) == "BROKEN", res.stdout


def test_every_module_of_the_top_level_is_in_a_layer(contracts):
    """A new top-level module or package must take its place in the layers (no module escapes the check)."""
    named = set()
    for layer in next(c for c in contracts["contracts"] if c["id"] == "layers")["layers"]:
        named |= {m.strip() for part in layer.split("|") for m in part.split(":")}
    present = {f"bgfn.{p.stem}" for p in PACKAGE.glob("*.py") if p.stem != "__init__"}
    present |= {f"bgfn.{p.name}" for p in PACKAGE.iterdir() if (p / "__init__.py").is_file()}
    assert present == named


def test_imports_inside_functions_are_the_few_optional_ones():
    """Imports live at the top of their module, where a reader sees the graph; inside a function only an optional
    or heavy one (ALLOWED_FUNCTION_IMPORTS), with a comment saying why on the line before."""
    found = set()
    for path in PACKAGE.rglob("*.py"):
        module = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts).removesuffix(".__init__")
        tree = ast.parse(path.read_text(encoding="utf-8"))
        lines = path.read_text(encoding="utf-8").splitlines()
        for fn in (n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))):
            for node in (n for n in ast.walk(fn) if isinstance(n, (ast.Import, ast.ImportFrom))):
                name = node.module if isinstance(node, ast.ImportFrom) else node.names[0].name
                found.add((module, name.split(".")[0] if name.startswith("pyins") else name))
                assert lines[node.lineno - 2].strip().startswith("#"), f"{path}:{node.lineno}: say why it is here"
    assert found <= ALLOWED_FUNCTION_IMPORTS, sorted(found - ALLOWED_FUNCTION_IMPORTS)
    assert len(found) < 10


#: Names that make sentences, labels or a page's prose: below ``report/`` a module returns numbers, tables and codes.
WORD_FUNCTION = re.compile(r"^(lines?|notes?|sentences?|describe\w*|\w+_lines?|\w+_notes?|\w+_sentences?|\w+_words"
                           r"|\w+_markdown)$")
#: Names of a field or a dict key that holds sentences (a result's ``notes``, a drive's ``meta["line"]``): the
#: words would be made where the value is filled. (A bare ``note`` is a user's own text, kept as a column.)
WORD_FIELD = re.compile(r"^(lines?|notes|sentences?|\w+_lines?|\w+_notes|\w+_sentences?|\w+_words|\w+_markdown)$")
#: The edge may word its own messages (the command line, the profile check); ``report/`` words everything else.
WORD_HOMES = ("report/", "__main__.py", "profile_schema.py")
#: Word-making functions allowed below ``report/``, each with why.
WORD_EXCEPTIONS = {
    # a progress line for the terminal or the log of a long run, not a sentence of a page
    "parallel.py:RunProgress.line",
}


def word_makers(package: Path) -> list[str]:
    """Every place below ``report/`` (modules under ``package`` outside :data:`WORD_HOMES`) that makes words:
    ``<module path>:<function>`` / ``<module path>:<class>.<method>`` named like a word-making function
    (:data:`WORD_FUNCTION`); ``<module path>:<NAME>`` of a module-level ``*_WORDS`` constant;
    ``<module path>:<class>.<field>`` of a class's annotated field and ``<module path>:[<key>]`` of a dict
    literal's key named like words (:data:`WORD_FIELD`)."""
    found = []
    for path in sorted(package.rglob("*.py")):
        rel = path.relative_to(package).as_posix()
        if rel.startswith(WORD_HOMES):
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in tree.body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and WORD_FUNCTION.match(node.name):
                found.append(f"{rel}:{node.name}")
            elif isinstance(node, ast.ClassDef):
                found += [f"{rel}:{node.name}.{m.name}" for m in node.body
                          if isinstance(m, (ast.FunctionDef, ast.AsyncFunctionDef)) and WORD_FUNCTION.match(m.name)]
                found += [f"{rel}:{node.name}.{m.target.id}" for m in node.body
                          if isinstance(m, ast.AnnAssign) and isinstance(m.target, ast.Name)
                          and WORD_FIELD.match(m.target.id)]
            elif isinstance(node, (ast.Assign, ast.AnnAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                found += [f"{rel}:{t.id}" for t in targets if isinstance(t, ast.Name) and t.id.endswith("_WORDS")]
        found += [f"{rel}:[{k.value!r}]" for d in ast.walk(tree) if isinstance(d, ast.Dict) for k in d.keys
                  if isinstance(k, ast.Constant) and isinstance(k.value, str) and WORD_FIELD.match(k.value)]
    return found


def test_sentences_are_made_in_report_only():
    """Below ``report/`` the layers return numbers, tables and codes; their words are made in ``report/``."""
    assert set(word_makers(PACKAGE)) == WORD_EXCEPTIONS


@pytest.mark.parametrize("where, body, name", [
    ("nav/planted.py", "def describe_windows(windows):\n    return [str(w) for w in windows]\n",
     "nav/planted.py:describe_windows"),
    ("train/planted.py", "class Plan:\n    def lines(self):\n        return []\n", "train/planted.py:Plan.lines"),
    ("studies/gallery/planted.py", "def decision_words(code):\n    return code\n",
     "studies/gallery/planted.py:decision_words"),
    ("energy/planted.py", "PLANTED_WORDS: dict = {'a': 'an a'}\n", "energy/planted.py:PLANTED_WORDS"),
    # a result's field of sentences, filled where the numbers are made
    ("studies/outage_sweep/planted.py", "class Result:\n    table: object\n    notes: list\n",
     "studies/outage_sweep/planted.py:Result.notes"),
    # a sentence kept in a record (a drive's meta) under a key
    ("data/planted.py", "def meta(x):\n    return {'offset_s': x, 'line': f'{x} s late'}\n",
     "data/planted.py:['line']"),
    ("evaluate/planted.py", "def gate_line(x):\n    return str(x)\n", "evaluate/planted.py:gate_line"),
])
def test_the_word_check_finds_a_planted_word_maker(tmp_path, where, body, name):
    package = _copy(tmp_path) / "bgfn"
    (package / where).write_text(body, encoding="utf-8")
    (package / "report" / "planted_words.py").write_text("def planted_lines():\n    return []\n", encoding="utf-8")
    assert set(word_makers(package)) == WORD_EXCEPTIONS | {name}          # the one below report, not report's own
