"""Packs the built Python package (``<build>/python/calligraphy``: the extension, the pure-Python modules,
the subpackage calligraphy.stats with its R script, the type stubs, the licences in calligraphy/licences)
into a wheel (PEP 427) with setuptools and wheel (Debian python3-setuptools, python3-wheel), so that it
installs into any environment of the same interpreter version with ``pip install --no-index
calligraphy-*.whl``: a virtual environment among them.

    python3 make_wheel.py --package BUILD/python/calligraphy --version 0.1.0 --out DIR

Prints the wheel's path. The extension was built for this interpreter's ABI (the wheel's tag says which) and
links Debian 12's libraries at run time (docs/python.md, "Install"): the wheel is for Debian 12 machines, not
manylinux. Exit status 0, or 1 with a message naming what is missing.
"""

import argparse
import os
import pathlib
import shutil
import sys
import tempfile


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--package", required=True, help="the built package folder (<build>/python/calligraphy)")
    parser.add_argument("--version", required=True, help="the project's version")
    parser.add_argument("--out", required=True, help="the folder the wheel is written to (created if missing)")
    arguments = parser.parse_args()
    package = pathlib.Path(arguments.package).resolve()
    if (not (package / "__init__.py").is_file() or not list(package.glob("_calligraphy*.so"))
            or not (package / "stats" / "__init__.py").is_file()):
        print(f"make_wheel: {package} holds no built calligraphy package (build the calligraphy_python target)",
              file=sys.stderr)
        return 1
    try:
        import setuptools
        from setuptools.dist import Distribution
    except ImportError:
        print("make_wheel: needs setuptools and wheel (Debian: apt-get install python3-setuptools python3-wheel)",
              file=sys.stderr)
        return 1

    class BinaryDistribution(Distribution):
        """The package carries a compiled extension: the wheel is tagged with this interpreter's ABI and
        platform, not 'py3-none-any'."""

        def has_ext_modules(self):
            return True

    out = pathlib.Path(arguments.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="calligraphy-wheel-") as staging:
        shutil.copytree(package, pathlib.Path(staging) / "calligraphy",
                        ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "*.tmp"))
        before = set(out.glob("*.whl"))
        cwd = os.getcwd()
        os.chdir(staging)
        try:
            setuptools.setup(
                name="calligraphy", version=arguments.version,
                description="Haptic training of Chinese handwriting (Wang, Zhang & Yao 2006, Virtual Reality 9)",
                packages=["calligraphy", "calligraphy.stats"],
                package_data={"calligraphy": ["*.so", "*.pyi", "py.typed", "licences/*"],
                              "calligraphy.stats": ["*.R"]},
                python_requires=f"=={sys.version_info.major}.{sys.version_info.minor}.*",
                install_requires=["numpy"],
                extras_require={"tables": ["pandas"], "figures": ["matplotlib"],
                                "statistics": ["pandas", "scipy", "statsmodels"], "dask": ["dask", "distributed"]},
                distclass=BinaryDistribution,
                script_args=["--quiet", "bdist_wheel", "--dist-dir", str(out)])
        finally:
            os.chdir(cwd)
        made = sorted(set(out.glob("*.whl")) - before) or sorted(out.glob("calligraphy-*.whl"))
    if not made:
        print(f"make_wheel: setuptools wrote no wheel into {out}", file=sys.stderr)
        return 1
    print(made[-1])
    return 0


if __name__ == "__main__":
    sys.exit(main())
