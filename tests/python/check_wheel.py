"""The wheel installs into a virtual environment and imports from there: packs the build's package
(bindings/python/make_wheel.py), makes a venv of the build interpreter with its site packages (numpy,
pandas from Debian), `pip install --no-index` the wheel, and in the venv's interpreter imports calligraphy
from the venv, runs a trial of 十, finds the R script of the mixed models beside the package and the licences
in it (calligraphy/licences, byte for byte), and runs binding tests (VENV_TESTS) with the venv's interpreter
on the installed package. Then checks
that a venv without numpy refuses the wheel naming numpy, offline. Exit 0 or 1 (77: venv or pip missing).

    python3 check_wheel.py --build BUILD --version 0.1.0
"""

import argparse
import os
import pathlib
import subprocess
import sys
import tempfile

SOURCE = pathlib.Path(__file__).resolve().parents[2]
# Binding tests that need only the installed package (no build tree, no CLI), run inside the venv.
VENV_TESTS = ("test_sim.py", "test_scene.py", "test_force_law.py", "test_renderer.py", "test_run_trial.py",
              "test_logging.py", "test_package_layering.py")


def run(command, **options):
    return subprocess.run([str(c) for c in command], capture_output=True, text=True, timeout=600, **options)


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--build", required=True)
    parser.add_argument("--version", required=True)
    arguments = parser.parse_args()
    try:
        import ensurepip  # noqa: F401
        import venv  # noqa: F401
    except ImportError:
        print("SKIP: this interpreter has no venv/ensurepip (Debian: apt-get install python3-venv)")
        return 77
    with tempfile.TemporaryDirectory(prefix="calligraphy-wheel-test-") as folder:
        folder = pathlib.Path(folder)
        made = run([sys.executable, SOURCE / "bindings/python/make_wheel.py", "--package",
                    pathlib.Path(arguments.build) / "python/calligraphy", "--version", arguments.version,
                    "--out", folder / "dist"])
        if made.returncode != 0:
            print(made.stdout, made.stderr)
            return 1
        wheel = pathlib.Path(made.stdout.strip().splitlines()[-1])
        tag = f"cp{sys.version_info.major}{sys.version_info.minor}"
        assert wheel.name == f"calligraphy-{arguments.version}-{tag}-{tag}-linux_x86_64.whl", wheel.name

        env = folder / "venv"
        created = run([sys.executable, "-m", "venv", "--system-site-packages", env])
        assert created.returncode == 0, created.stderr
        installed = run([env / "bin/pip", "install", "--no-index", "--quiet", wheel])
        assert installed.returncode == 0, installed.stderr
        probe = run([env / "bin/python", "-c",
                     "import calligraphy, calligraphy.stats.mixed_models as m, calligraphy.mixed_models; "
                     "import pathlib, sys; "
                     "print(pathlib.Path(calligraphy.__file__).resolve()); "
                     "print(m._SCRIPT.is_file() and calligraphy.mixed_models is m); "
                     "r = calligraphy.run_trial('十'); print(r.metrics['strokes_accepted'], r.metrics['strokes_total'])"],
                    cwd=folder)
        assert probe.returncode == 0, probe.stderr
        location, script, strokes = probe.stdout.split("\n")[:3]
        assert pathlib.Path(location).is_relative_to(env.resolve()), location  # the venv's, not Debian's copy
        assert script == "True" and strokes == "2 2", probe.stdout
        # The licences of the code and of the character data compiled into the extension go with it.
        licences = pathlib.Path(location).parent / "licences"
        for name, source in (("LICENSE", "LICENSE"), ("ARPHICPL.TXT", "data/corpus/ARPHICPL.TXT"),
                             ("NOTICE.md", "data/corpus/NOTICE.md")):
            assert (licences / name).read_bytes() == (SOURCE / source).read_bytes(), name
        # The binding tests that need no build tree, run by the venv's interpreter on the installed package
        # (conftest.py checks that `calligraphy` comes from the venv, not from a build or Debian's folders).
        tested = run([env / "bin/python", "-m", "pytest", "-q", "-p", "no:cacheprovider",
                      *(SOURCE / "tests/python" / name for name in VENV_TESTS)],
                     cwd=folder, env={**os.environ, "PYTHONPATH": "", "CALLIGRAPHY_EXPECT_PACKAGE_UNDER": str(env)})
        assert tested.returncode == 0, tested.stdout[-3000:] + tested.stderr[-2000:]
        passed = tested.stdout.strip().splitlines()[-1]
        uninstalled = run([env / "bin/pip", "uninstall", "--yes", "--quiet", "calligraphy"])
        assert uninstalled.returncode == 0, uninstalled.stderr

        bare = folder / "bare"
        assert run([sys.executable, "-m", "venv", bare]).returncode == 0
        refused = run([bare / "bin/pip", "install", "--no-index", wheel])
        assert refused.returncode != 0 and "numpy" in refused.stdout + refused.stderr, refused.stderr
    print(f"wheel {wheel.name}: installed into a venv, imported from it, a trial of 十 written, the binding tests "
          f"{', '.join(VENV_TESTS)} in the venv: {passed}; a venv without numpy refuses it naming numpy")
    return 0


if __name__ == "__main__":
    sys.exit(main())
