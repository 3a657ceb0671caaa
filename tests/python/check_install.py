"""`cmake --install --component python` into a temporary prefix, then `import calligraphy` there.

Run by CTest (python_install, python_install_path_python3) with the interpreter that runs the module's
build, not by pytest:

    check_install.py --cmake CMAKE --build BUILD_DIR --python INTERPRETER [--through-pth]

Installs the python component with `cmake -P BUILD_DIR/cmake_install.cmake` into a temporary prefix
and a temporary site folder (CALLIGRAPHY_PYTHON_PTH_DIR), then imports the installed package with
INTERPRETER in a clean environment: directly from the prefix's package folder, or, with
--through-pth, with only the temporary site folder added the way Python's `site` adds a site-packages
folder (so that calligraphy.pth alone must lead to the package and to numpy). Checks that the package
came from the temporary prefix and that a short simulated trial runs. Exits 77 (CTest: skipped) with
the reason when INTERPRETER is empty, missing, or the build interpreter itself.
"""

import argparse
import os
import pathlib
import subprocess
import sys
import tempfile

SKIPPED = 77

IMPORT_AND_RUN = """
import sys, pathlib
import calligraphy, calligraphy.experiments, numpy
package = pathlib.Path(calligraphy.__file__).resolve().parent
assert package.is_relative_to(pathlib.Path(sys.argv[1]).resolve()), package
# The statistics' subpackage, its R script, and the old module paths as the same modules.
import calligraphy.stats.study_report, calligraphy.stats.mixed_models, calligraphy.study_report
assert pathlib.Path(calligraphy.stats.__file__).resolve().parent == package / "stats", calligraphy.stats.__file__
assert calligraphy.stats.mixed_models._SCRIPT.is_file(), calligraphy.stats.mixed_models._SCRIPT
assert calligraphy.study_report is calligraphy.stats.study_report
metrics = calligraphy.simulate_trial("十", keep_trace=False, max_duration_s=20.0).metrics
assert metrics["strokes_total"] == 2, metrics
print(sys.executable, sys.version.split()[0], "imports calligraphy", calligraphy.__version__, "from", package,
      "with numpy", numpy.__version__, "from", pathlib.Path(numpy.__file__).parent.parent)
"""


def run(command, **kwargs):
    print("+", " ".join(str(part) for part in command), flush=True)
    return subprocess.run([str(part) for part in command], check=True, **kwargs)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cmake", required=True)
    parser.add_argument("--build", required=True, type=pathlib.Path)
    parser.add_argument("--python", default="")
    parser.add_argument("--through-pth", action="store_true")
    args = parser.parse_args()

    if not args.python or not pathlib.Path(args.python).exists():
        print(f"SKIPPED: no second python3 on PATH at configure time ({args.python or 'none'}); only "
              f"{sys.executable} can import the module")
        return SKIPPED
    if args.through_pth:
        other = subprocess.run([args.python, "-c", "import os, sys; print(os.path.realpath(sys.executable))"],
                               check=True, capture_output=True, text=True).stdout.strip()
        if other == os.path.realpath(sys.executable):
            print(f"SKIPPED: python3 on PATH ({args.python}) is the build interpreter {sys.executable}")
            return SKIPPED

    with tempfile.TemporaryDirectory(prefix="calligraphy-install-") as scratch:
        prefix = pathlib.Path(scratch) / "prefix"
        site = pathlib.Path(scratch) / "site"
        run([args.cmake, f"-DCMAKE_INSTALL_PREFIX={prefix}", "-DCOMPONENT=python",
             f"-DCALLIGRAPHY_PYTHON_PTH_DIR={site}", "-P", args.build / "cmake_install.cmake"])
        packages = sorted(prefix.glob("**/calligraphy/__init__.py"))
        if len(packages) != 1:
            print(f"FAILED: expected one installed package under {prefix}, found {packages} (is "
                  "CALLIGRAPHY_PYTHON_INSTALL_DIR absolute?)")
            return 1
        package_dir = packages[0].parent.parent
        pth = site / "calligraphy.pth"
        lines = [line for line in pth.read_text(encoding="utf-8").splitlines() if not line.startswith("#")]
        print(f"{pth}:", *lines, sep="\n  ")
        if pathlib.Path(lines[0]) != package_dir:
            print(f"FAILED: the first folder in {pth} is {lines[0]}, the package was installed in {package_dir}")
            return 1

        environment = {key: value for key, value in os.environ.items()
                       if key not in ("PYTHONPATH", "PYTHONHOME", "PYTHONSTARTUP")}
        if args.through_pth:
            # -S: none of the interpreter's own site folders (where an earlier install could be found);
            # then the temporary site folder, processed as Python's `site` processes site-packages.
            code = f"import site; site.addsitedir({str(site)!r})\n" + IMPORT_AND_RUN
            command = [args.python, "-S", "-c", code, prefix]
        else:
            environment["PYTHONPATH"] = str(package_dir)
            command = [args.python, "-c", IMPORT_AND_RUN, prefix]
        run(command, env=environment, cwd=scratch)
    return 0


if __name__ == "__main__":
    sys.exit(main())
