"""Type stubs (made by mypy's stubgen at build time) and the documentation help() shows."""

import ast
import pathlib
import pydoc
import textwrap

import pytest

import calligraphy

PACKAGE = pathlib.Path(calligraphy.__file__).parent

GOOD = """
import numpy as np
import calligraphy

library = calligraphy.CharacterLibrary.default()
scene = calligraphy.Scene([library.load("永")], layout=calligraphy.SceneLayout(character_size_m=0.05))
law = calligraphy.ForceLawParameters(guidance_stiffness_n_per_m=300.0)
law.nearest.newton_starts = 4
result = calligraphy.simulate_trial(scene, writer=calligraphy.WriterProfile.skilled(), force_law=law, seed=2)
time_s: np.ndarray = result.time_s
paper_m = scene.characters[0].placement.to_paper(np.zeros((3, 2)))
output = calligraphy.Renderer(scene, law).tick(calligraphy.DeviceState(position_m=(0.0, 0.0, 0.01)))
state: calligraphy.InteractionState = output.state
acronym: str = calligraphy.typical_stroke("HZG").acronym
version: str = calligraphy.__version__
"""

# Each line is wrong in one way the stubs must catch.
BAD = [
    'calligraphy.simulate_trial("永", rate_hz="fast")',
    "calligraphy.ForceLawParameters(stiffness=3.0)",
    "calligraphy.ForceLawParameters(400.0)",
    'calligraphy.Scene("永").stroke_count.upper()',
    "calligraphy.CharacterLibrary.default().load(3)",
    "calligraphy.nearest_point([[0, 0], [1, 0]], [0, 1], newton_starts=1.5)",
]


def test_stubs_are_installed_with_the_module():
    stub = PACKAGE / "_calligraphy.pyi"
    assert stub.is_file(), "build with CALLIGRAPHY_PYTHON_STUBS=ON (needs python3-mypy)"
    assert (PACKAGE / "py.typed").is_file()
    tree = ast.parse(stub.read_text(encoding="utf-8"))
    defined = {node.name for node in tree.body if isinstance(node, (ast.ClassDef, ast.FunctionDef))}
    defined |= {node.target.id for node in tree.body if isinstance(node, ast.AnnAssign)}
    assert set(calligraphy.__all__) <= defined


def test_mypy_accepts_good_use_and_rejects_each_mistake(tmp_path):
    api = pytest.importorskip("mypy.api")
    (tmp_path / "good.py").write_text(GOOD, encoding="utf-8")
    (tmp_path / "bad.py").write_text("import calligraphy\n" + "\n".join(BAD) + "\n", encoding="utf-8")
    cache = str(tmp_path / "cache")
    out, err, status = api.run([str(tmp_path / "good.py"), "--cache-dir", cache, "--no-error-summary"])
    assert status == 0, out + err
    out, err, status = api.run([str(tmp_path / "bad.py"), "--cache-dir", cache, "--no-error-summary"])
    flagged = {int(line.split(":")[1]) for line in out.splitlines() if line.startswith(str(tmp_path / "bad.py"))}
    assert flagged == set(range(2, 2 + len(BAD))), out + err


def help_text(thing):
    return pydoc.render_doc(thing, renderer=pydoc.plaintext)


def test_help_shows_units_shapes_and_errors():
    scene = help_text(calligraphy.Scene)
    for fragment in ("[m]", "(N, 2)", "(2, 2)", "KeyError", "ValueError", "TypeError"):
        assert fragment in scene, fragment
    placement = help_text(calligraphy.Placement)
    assert "points: numpy.typing.ArrayLike" in placement and "(N, 2)" in placement
    law = help_text(calligraphy.ForceLawParameters)
    assert "guidance_stiffness_n_per_m: float = 400.0" in law  # keyword-only constructor with defaults
    assert "[N/m]" in law and "[N s/m]" in law
    trial = textwrap.dedent(calligraphy.simulate_trial.__doc__)
    assert "rate_hz: float = 1000.0" in trial and "[Hz]" in trial and "GIL" in trial
