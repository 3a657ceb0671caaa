"""The Python package's layering, read from its sources with `ast` (docs/python.md, "Packages"):

* the modules of ``calligraphy`` (bindings/python/calligraphy) and of ``calligraphy.stats`` (python/stats)
  import one another without a circle: every import counts, at the top of a file, inside a function or for
  type checkers only;
* ``calligraphy.stats`` imports nothing of ``calligraphy`` outside itself except through
  ``calligraphy.stats._native``, which imports the extension ``calligraphy._calligraphy`` and nothing else:
  never the bindings' modules (frames, metrics, experiments, cohort, plot) nor the package's ``__init__``;
* the built package holds every source module, and the old module paths are the new modules themselves.
"""

import ast
import importlib
import os
import pathlib
import subprocess
import sys
import warnings

import pytest

SOURCE = pathlib.Path(__file__).resolve().parents[2]
BINDINGS = SOURCE / "bindings/python/calligraphy"
STATS = SOURCE / "python/stats"
ROOT = "calligraphy"
STATS_PACKAGE = "calligraphy.stats"
EXTENSION = "calligraphy._calligraphy"
GATE = "calligraphy.stats._native"
MOVED = ("statistics", "mixed_models", "design_models", "design_analysis", "crossover_analysis", "study",
         "study_report")


def package_sources():
    """Module name -> (is a package's __init__, source text), for every module of both folders."""
    found = {}
    for folder, package in ((BINDINGS, ROOT), (STATS, STATS_PACKAGE)):
        for path in sorted(folder.glob("*.py")):
            is_init = path.stem == "__init__"
            found[package if is_init else f"{package}.{path.stem}"] = (is_init, path.read_text(encoding="utf-8"))
    return found


def named_imports(name, is_init, text, known):
    """The modules of `known` that the module `name` names in an import statement anywhere in `text`: for
    ``from X import y``, X.y when that is a module, else X (resolved to the longest known module)."""

    def longest(dotted):
        parts = dotted.split(".")
        for end in range(len(parts), 0, -1):
            candidate = ".".join(parts[:end])
            if candidate in known:
                return candidate
        return None

    package = name if is_init else name.rpartition(".")[0]
    named = set()
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - (node.level - 1)] + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            targets = [f"{base}.{alias.name}" for alias in node.names]
        else:
            continue
        named.update(t for t in map(longest, targets) if t is not None and t != name)
    return named


def import_graph(sources):
    """Module -> the modules its imports load, leaving out its own enclosing packages (Python has them
    before it runs the module, so they close no circle) and adding the packages a named module lies in."""
    known = set(sources) | {EXTENSION}
    graph = {}
    for name, (is_init, text) in sources.items():
        own = {".".join(name.split(".")[:end]) for end in range(1, name.count(".") + 1)}
        edges = set()
        for target in named_imports(name, is_init, text, known):
            parts = target.split(".")
            edges.update(".".join(parts[:end]) for end in range(1, len(parts) + 1))
        graph[name] = {t for t in edges if t in known and t != name and t not in own}
    return graph


def find_cycle(graph):
    """One circle of `graph` as a list of modules (first == last), or None."""
    state = {}
    stack = []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for target in sorted(graph.get(node, ())):
            if state.get(target) == "open":
                return stack[stack.index(target):] + [target]
            if target not in state:
                found = visit(target)
                if found:
                    return found
        stack.pop()
        state[node] = "done"
        return None

    for node in sorted(graph):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


def layering_breaches(sources):
    """(module, what it names) for every import of calligraphy.stats that leaves the package other than the
    gate's import of the extension, and every import of the gate other than the extension."""
    known = set(sources) | {EXTENSION}
    breaches = []
    for name, (is_init, text) in sorted(sources.items()):
        if name != STATS_PACKAGE and not name.startswith(STATS_PACKAGE + "."):
            continue
        for target in sorted(named_imports(name, is_init, text, known)):
            inside = target == STATS_PACKAGE or target.startswith(STATS_PACKAGE + ".")
            if name == GATE:
                allowed = target == EXTENSION
            else:
                allowed = inside
            if not allowed:
                breaches.append((name, target))
    return breaches


def test_the_package_import_graph_has_no_circle():
    sources = package_sources()
    assert GATE in sources and f"{STATS_PACKAGE}.design_analysis" in sources, sorted(sources)
    graph = import_graph(sources)
    # The graph is the real one: the known edges are in it.
    assert f"{STATS_PACKAGE}.crossover_analysis" in graph[f"{STATS_PACKAGE}.design_analysis"]
    assert f"{STATS_PACKAGE}.design_models" in graph[f"{STATS_PACKAGE}.crossover_analysis"]
    assert EXTENSION in graph[GATE]
    assert f"{STATS_PACKAGE}.study" in graph[f"{ROOT}.cohort"]
    cycle = find_cycle(graph)
    assert cycle is None, " -> ".join(cycle)


def test_the_stats_package_reaches_the_bindings_only_through_its_gate():
    sources = package_sources()
    assert layering_breaches(sources) == []
    graph = import_graph(sources)
    importers = sorted(name for name, targets in graph.items()
                       if EXTENSION in targets and name.startswith(STATS_PACKAGE))
    assert importers == [GATE]


def test_the_checks_see_a_circle_and_a_breach():
    """The checks above can fail: a circle made of two modules, and a stats module importing a bindings'
    module, the package's __init__ or the extension past the gate, are each reported."""
    sources = package_sources()
    crossed = dict(sources)
    crossed[f"{STATS_PACKAGE}.design_models"] = (False, sources[f"{STATS_PACKAGE}.design_models"][1]
                                                  + "\n\ndef _late():\n    from . import design_analysis\n")
    cycle = find_cycle(import_graph(crossed))
    assert cycle is not None and f"{STATS_PACKAGE}.design_models" in cycle
    for line, target in (("from .. import frames", f"{ROOT}.frames"),
                         ("from .. import DataError", ROOT),
                         ("from .._calligraphy import DataError", EXTENSION),
                         ("import calligraphy.metrics", f"{ROOT}.metrics")):
        broken = dict(sources)
        broken[f"{STATS_PACKAGE}.statistics"] = (False, sources[f"{STATS_PACKAGE}.statistics"][1] + "\n" + line + "\n")
        assert (f"{STATS_PACKAGE}.statistics", target) in layering_breaches(broken), line
    lax_gate = dict(sources)
    lax_gate[GATE] = (False, sources[GATE][1] + "\nfrom ..metrics import metric_frame\n")
    assert (GATE, f"{ROOT}.metrics") in layering_breaches(lax_gate)


def test_the_built_package_holds_every_source_module():
    stats = importlib.import_module(STATS_PACKAGE)
    built = pathlib.Path(stats.__file__).parent
    for path in list(STATS.glob("*.py")) + list(STATS.glob("*.R")):
        assert (built / path.name).is_file(), f"{path.name} is not copied into {built} (bindings/python/CMakeLists.txt)"
    for path in BINDINGS.glob("*.py"):
        assert (built.parent / path.name).is_file(), f"{path.name} is not copied into {built.parent}"


@pytest.mark.parametrize("module", MOVED)
def test_an_old_module_path_is_the_new_module_itself(module):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        old = importlib.import_module(f"{ROOT}.{module}")
        new = importlib.import_module(f"{STATS_PACKAGE}.{module}")
    assert old is new
    assert getattr(importlib.import_module(ROOT), module) is new
    assert new.__name__ == f"{STATS_PACKAGE}.{module}"


def test_a_moved_module_is_an_attribute_of_the_package_without_an_import():
    """As when the analysis imported them under their old paths: ``calligraphy.statistics`` is there once
    ``calligraphy`` is, and a name the package lacks is still an AttributeError."""
    probe = ("import importlib, calligraphy\n"
             f"moved = {MOVED!r}\n"
             "print(all(getattr(calligraphy, m) is importlib.import_module('calligraphy.stats.' + m) for m in moved))\n"
             "print(hasattr(calligraphy, 'no_such_module'))\n")
    done = run_python(["-c", probe])
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["True", "False"], done.stdout


def test_the_trial_figures_and_the_report_share_one_font_lookup():
    plot = importlib.import_module(f"{ROOT}.plot")
    fonts = importlib.import_module(f"{STATS_PACKAGE}.fonts")
    assert plot.cjk_font is fonts.cjk_font


def run_python(code_or_args):
    return subprocess.run([sys.executable, *code_or_args], capture_output=True, text=True, env=os.environ.copy(),
                          timeout=120)


def test_importing_the_statistics_loads_no_bindings_module():
    """At run time too: the analysis and the report load none of the bindings' own modules, and the
    package alone loads none of its modules."""
    probe = ("import sys, calligraphy.stats\n"
             "print(sorted(m for m in sys.modules if m.startswith('calligraphy.stats.')))\n"
             "import calligraphy.stats.study_report, calligraphy.stats.design_analysis\n"
             "print(sorted(m for m in sys.modules\n"
             "             if m.startswith('calligraphy.') and not m.startswith('calligraphy.stats')))\n")
    done = run_python(["-c", probe])
    assert done.returncode == 0, done.stderr
    alone, loaded = done.stdout.splitlines()[:2]
    assert alone == "[]"
    assert loaded == "['calligraphy._calligraphy']", loaded


@pytest.mark.parametrize("module", ["calligraphy.study_report", "calligraphy.stats.study_report"])
def test_the_report_command_runs_by_either_path(module):
    done = run_python(["-W", "error::DeprecationWarning", "-m", module, "--help"])
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("usage: python3 -m calligraphy.study_report"), done.stdout[:200]
    assert "--per-trial-page" in done.stdout
