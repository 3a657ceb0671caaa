#!/usr/bin/env python3
"""Round 14A: hostile cases written from the documentation alone (README.md, docs/python.md, docs/corpus.md,
docs/architecture.md, docs/cli.md and `--help`) on the INSTALLED package: what `cmake --install` of a build
writes and what the installed program, Python package and CMake package then do away from the source tree.
Run by CTest as `cli_unseen_round14a_tests`.

The build is the one CALLIGRAPHY_CLI lives in (`<build>/bin/calligraphy`); it is installed, never rebuilt, into
temporary prefixes: one whose name holds a space and CJK characters, one with the components `phantom_usb` and
`testing` asked for by name, the `python` component alone, a `DESTDIR` stage, a tree moved after its install,
one made read-only and run as nobody, one whose installed corpus store is cut or deleted, one installed twice
over itself and one where a link to a file outside was planted first. The installed `calligraphy` runs from an
empty folder with no `CALLIGRAPHY_*` variable, HOME and XDG_CACHE_HOME an empty folder, and without a network
(`unshare -n` where the user may make one): characters of the whole corpus picked at random (never the 58
embedded ones) are modelled, written and scored; the installed Python package is imported by `python3 -I` with
only the install on its path and loads every character of the corpus. A downstream CMake project finds the
package (named components, one that does not exist, a version above the installed one, the moved and the
staged prefix) and ONE translation unit including every installed public header is compiled, linked and run.

Each case checks a documented promise: the exit status, one error line naming the file, nothing written
outside the prefix, licence and notice files byte for byte, one version everywhere, no crash.
CALLIGRAPHY_CLI names the program of the build, CALLIGRAPHY_SOURCE_DIR the source tree. The round is skipped,
saying so, when the build has no install rules. CALLIGRAPHY_SANITIZED=1 takes five cases. The characters
picked at random are printed (and taken from CALLIGRAPHY_ROUND14A_CHARS when it is set, to run a pick again).
"""
import json
import os
import random
import re
import shutil
import stat
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

from outsider import CLI, TIMEOUT_S, OneErrorLine, sanitized_subset

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
BUILD = Path(CLI).resolve().parents[1] if CLI else None
EMBEDDED = {p.stem for p in (SOURCE / "data" / "hanzi-writer-data").glob("*.json")}
CORPUS = SOURCE / "data" / "corpus"
STORE_NAME = "hanzi-writer-data-2.0.1.clg"
PY = "/usr/bin/python3"
PY_SITE = Path("lib") / f"python{sys.version_info.major}.{sys.version_info.minor}" / "dist-packages"
SEN = "森"  # twelve strokes from the bundled store (鼎, docs/corpus.md's example, is one of the 58 embedded)

load_tests = sanitized_subset({"test_install_into_a_prefix_with_a_space_and_cjk_stays_inside_it",
                               "test_planted_link_to_a_file_outside_is_not_written_through",
                               "test_random_corpus_characters_offline_from_an_empty_home",
                               "test_missing_installed_store_is_named_and_the_compiled_in_one_still_serves",
                               "test_unknown_component_fails_to_configure_naming_it"})

SHARED = {}


def cmake_install(prefix, *components, destdir=None):
    """`cmake --install` of the build into `prefix` (each component by name, or the default install)."""
    env = dict(os.environ)
    env.pop("DESTDIR", None)
    if destdir is not None:
        env["DESTDIR"] = str(destdir)
    outputs = []
    for component in components or (None,):
        args = ["cmake", "--install", str(BUILD), "--prefix", str(prefix)]
        if component:
            args += ["--component", component]
        done = subprocess.run(args, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT_S)
        if done.returncode != 0:
            raise AssertionError(f"{' '.join(args)}: {done.stderr.decode('utf-8', 'replace')}")
        outputs.append(done.stdout.decode("utf-8"))
    return "".join(outputs)


def installed_paths(install_output):
    """The files an install says it wrote or found up to date."""
    return [Path(m.group(2)) for m in re.finditer(r"^-- (Installing|Up-to-date): (.*)$", install_output, re.M)]


def clean_env(home):
    """No CALLIGRAPHY_* variable, no display, HOME and XDG_CACHE_HOME an empty folder."""
    env = {"PATH": "/usr/local/bin:/usr/bin:/bin", "LANG": "C.UTF-8", "HOME": str(home),
           "XDG_CACHE_HOME": str(Path(home) / ".cache")}
    return env


def offline():
    """`unshare -n` when this user may make a network namespace (root, or user namespaces allowed)."""
    if "offline" not in SHARED:
        try:
            ok = subprocess.run(["unshare", "-n", "true"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                timeout=10).returncode == 0
            if not ok:
                ok = subprocess.run(["unshare", "-rn", "true"], stdout=subprocess.DEVNULL,
                                    stderr=subprocess.DEVNULL, timeout=10).returncode == 0
                SHARED["offline"] = ["unshare", "-rn"] if ok else []
            else:
                SHARED["offline"] = ["unshare", "-n"]
        except (OSError, subprocess.TimeoutExpired):
            SHARED["offline"] = []
        if not SHARED["offline"]:
            print("round14a: no network namespace for this user; the offline cases run with the network there",
                  file=sys.stderr)
    return SHARED["offline"]


def run_installed(prefix, args, cwd, env, wrapper=(), **kw):
    """The installed `calligraphy` of `prefix` with `args`, offline, in `cwd`, with `env` only."""
    return subprocess.run([*offline(), *wrapper, str(Path(prefix) / "bin" / "calligraphy"), *map(str, args)],
                          cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          stdin=subprocess.DEVNULL, timeout=TIMEOUT_S, **kw)


def run_python(site, code, cwd, env, wrapper=()):
    """`python3 -I` (no PYTHONPATH, no user site, not the current folder) with only `site` added to its path."""
    program = f"import sys; sys.path.insert(0, {str(site)!r})\n{code}"
    return subprocess.run([*offline(), *wrapper, PY, "-I", "-c", program], cwd=cwd, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
                          timeout=TIMEOUT_S)


def configure(project_dir, build_dir, prefix, cmakelists, extra=()):
    """A downstream project of `cmakelists` configured against `prefix` (CMAKE_PREFIX_PATH)."""
    project_dir = Path(project_dir)
    project_dir.mkdir(parents=True, exist_ok=True)
    (project_dir / "CMakeLists.txt").write_text(cmakelists, encoding="utf-8")
    return subprocess.run(["cmake", "-S", str(project_dir), "-B", str(build_dir), f"-DCMAKE_PREFIX_PATH={prefix}",
                           *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT_S)


def probe_project(find_call, tail=""):
    """A project of no language that only finds the package (cheap: no compiler is looked for)."""
    return f"cmake_minimum_required(VERSION 3.20)\nproject(probe LANGUAGES NONE)\n{find_call}\n{tail}\n"


def corpus_characters(prefix, cwd, env):
    listed = run_installed(prefix, ["characters"], cwd, env)
    assert listed.returncode == 0, listed.stderr
    return listed_characters(listed.stdout)


def listed_characters(output):
    """The characters of a `characters` listing (its header and closing summary left out)."""
    rows = (line.split() for line in output.decode("utf-8").splitlines())
    return [row[0] for row in rows if len(row) > 1 and row[1].startswith("U+")]


def random_picks(candidates, count):
    given = os.environ.get("CALLIGRAPHY_ROUND14A_CHARS")
    if given:
        return list(given)
    picks = random.SystemRandom().sample(sorted(candidates), count)
    print(f"round14a: characters picked at random: {''.join(picks)}", file=sys.stderr)
    return picks


def tree_digest(root):
    """Every file under `root` with its size and mode (a link as its target)."""
    out = {}
    for path in sorted(Path(root).rglob("*")):
        rel = str(path.relative_to(root))
        if path.is_symlink():
            out[rel] = ("link", os.readlink(path))
        elif path.is_file():
            out[rel] = ("file", path.stat().st_size, path.read_bytes()[:64])
    return out


def setUpModule():
    """The default install into a prefix whose name has a space and CJK characters, shared by most cases."""
    if not CLI or not Path(CLI).exists():
        raise unittest.SkipTest("CALLIGRAPHY_CLI is not set to the built program")
    if not (BUILD / "cmake_install.cmake").exists():
        raise unittest.SkipTest(f"the build {BUILD} has no install rules (no cmake_install.cmake)")
    if shutil.which("cmake") is None:
        raise unittest.SkipTest("cmake is not on PATH")
    base = Path(tempfile.mkdtemp(prefix="r14a-"))
    os.chmod(base, 0o755)  # nobody may traverse it (the read-only case)
    SHARED["base"] = base
    prefix = base / "安装 前缀 p"
    SHARED["prefix"] = prefix
    SHARED["install_output"] = cmake_install(prefix)
    home = base / "home"
    home.mkdir()
    SHARED["home"] = home
    work = base / "work"
    work.mkdir()
    SHARED["work"] = work
    version = run_installed(prefix, ["--version"], work, clean_env(home))
    assert version.returncode == 0, version.stderr
    SHARED["version"] = version.stdout.decode("utf-8").strip()


def tearDownModule():
    base = SHARED.get("base")
    if base:
        for path in [base, *base.rglob("*")]:  # the read-only trees
            if path.is_dir() and not path.is_symlink():
                os.chmod(path, 0o755)
        shutil.rmtree(base, ignore_errors=True)


class Base(unittest.TestCase, OneErrorLine):
    def setUp(self):
        self.prefix = SHARED["prefix"]
        self.home = SHARED["home"]
        self.env = clean_env(self.home)
        self.tmp = Path(tempfile.mkdtemp(prefix="case-", dir=SHARED["base"]))
        os.chmod(self.tmp, 0o777)

    def site(self, prefix=None):
        return Path(prefix or self.prefix) / PY_SITE

    def need_python(self):
        """Skips, saying so, when the build has no Python module (a sanitizer build, CALLIGRAPHY_BUILD_PYTHON=OFF)."""
        if not list((self.site() / "calligraphy").glob("_calligraphy*.so")):
            self.skipTest(f"the build {BUILD} has no Python module: none was installed")

    def version_number(self):
        match = re.fullmatch(r"calligraphy (\d+\.\d+\.\d+)", SHARED["version"])
        self.assertIsNotNone(match, SHARED["version"])
        return match.group(1)

    def assert_home_untouched(self):
        self.assertEqual(list(self.home.iterdir()), [], "the installed package wrote into HOME or its cache")


class InstalledTree(Base):
    """What the default install writes, where, and with which licences."""

    def test_install_into_a_prefix_with_a_space_and_cjk_stays_inside_it(self):
        paths = installed_paths(SHARED["install_output"])
        self.assertGreater(len(paths), 20)
        for path in paths:
            self.assertTrue(str(path).startswith(str(self.prefix) + "/"), path)
            self.assertTrue(path.exists() or path.is_symlink(), path)
        self.assertEqual({p.name for p in self.prefix.iterdir()} - {"bin", "include", "lib", "share"}, set())
        for rel in ("bin/calligraphy", "lib/cmake/calligraphy/calligraphyConfig.cmake",
                    f"share/calligraphy/corpus/{STORE_NAME}", "share/calligraphy/corpus/NOTICE.md"):
            self.assertTrue((self.prefix / rel).is_file(), rel)

    def test_plain_install_leaves_out_the_components_asked_for_by_name(self):
        headers = {p.relative_to(self.prefix / "include" / "calligraphy").parts[0]
                   for p in (self.prefix / "include" / "calligraphy").rglob("*.hpp")}
        self.assertNotIn("phantom_usb", headers)
        self.assertNotIn("testing", headers)
        self.assertNotIn("eval", headers)  # docs/architecture.md: `eval` is not installed
        libs = {p.name for p in (self.prefix / "lib").glob("*.a")}
        self.assertNotIn("libcalligraphy_phantom_usb.a", libs)
        self.assertNotIn("libcalligraphy_testing.a", libs)

    def test_corpus_store_licence_and_notice_are_the_sources_byte_for_byte(self):
        # docs/corpus.md: "The three files are installed under share/calligraphy/corpus/"
        for name in (STORE_NAME, "ARPHICPL.TXT", "NOTICE.md"):
            installed = self.prefix / "share" / "calligraphy" / "corpus" / name
            self.assertEqual(installed.read_bytes(), (CORPUS / name).read_bytes(), name)

    def test_embedded_data_licence_and_code_licence_are_installed(self):
        # README: the 58 embedded characters are under data/hanzi-writer-data/ARPHICPL.TXT, the code MIT (LICENSE),
        # both compiled into the installed library: their texts go with it.
        wanted = {"ARPHICPL.TXT": (SOURCE / "data" / "hanzi-writer-data" / "ARPHICPL.TXT").read_bytes(),
                  "LICENSE": (SOURCE / "LICENSE").read_bytes()}
        found = {name for name, text in wanted.items()
                 for p in self.prefix.rglob(name) if p.is_file() and p.read_bytes() == text}
        self.assertEqual(found, set(wanted))

    def test_every_include_of_an_installed_header_is_installed(self):
        root = self.prefix / "include"
        missing = []
        for header in root.rglob("*.hpp"):
            for match in re.finditer(r'^\s*#\s*include\s*[<"](calligraphy/[^>"]+)[>"]', header.read_text("utf-8"),
                                     re.M):
                if not (root / match.group(1)).is_file():
                    missing.append(f"{header.relative_to(root)} -> {match.group(1)}")
        self.assertEqual(missing, [])

    def test_installed_programs_point_into_no_build_or_source_tree(self):
        self.need_python()
        extension = next((self.site() / "calligraphy").glob("_calligraphy*.so"))
        for binary in (self.prefix / "bin" / "calligraphy", extension):
            dynamic = subprocess.run(["readelf", "-d", str(binary)], stdout=subprocess.PIPE, check=True,
                                     timeout=TIMEOUT_S).stdout.decode()
            for line in dynamic.splitlines():
                if "RPATH" in line or "RUNPATH" in line:
                    self.assertNotIn(str(BUILD), line, binary)
                    self.assertNotIn(str(SOURCE), line, binary)
        for config in (self.prefix / "lib" / "cmake" / "calligraphy").glob("*.cmake"):
            text = config.read_text("utf-8")
            self.assertNotIn(str(BUILD), text, config.name)
            self.assertNotIn(str(SOURCE.resolve()), text, config.name)

    def test_python_extension_needs_only_the_libraries_the_docs_name(self):
        # docs/python.md, "Install": "The extension links the library statically; it needs Debian's ... at run
        # time": each library it needs is named there (beside the C and C++ runtime every extension needs).
        self.need_python()
        documented = self.documented_runtime_libraries()
        extension = next((self.site() / "calligraphy").glob("_calligraphy*.so"))
        dynamic = subprocess.run(["readelf", "-d", str(extension)], stdout=subprocess.PIPE, check=True,
                                 timeout=TIMEOUT_S).stdout.decode()
        needed = set(re.findall(r"\(NEEDED\)\s+Shared library: \[lib([A-Za-z0-9_+-]+?)(?:[-.]\d[^\]]*)?\.so", dynamic))
        runtime = {"stdc++", "m", "gcc_s", "c", "ld-linux-x86-64"}
        self.assertEqual(needed - runtime - documented, set(),
                         f"docs/python.md names {sorted(documented)}; the extension needs {sorted(needed)}")

    def documented_runtime_libraries(self):
        text = (SOURCE / "docs" / "python.md").read_text("utf-8")
        words = r"\s+".join("The extension links the library statically; it needs".split())
        sentence = re.search(words + r"\s+(.*?)\s+at\s+run\s+time", text, re.S)
        self.assertIsNotNone(sentence, "docs/python.md no longer says what the extension needs at run time")
        return {re.sub(r"-\d.*$", "", name) for name in re.findall(r"`lib([A-Za-z0-9_.+-]+)`", sentence.group(1))}

    def test_haptics_link_line_is_what_readme_and_architecture_say(self):
        # README: haptics links -lspdlog -lfmt -lz, research adds -lcrypto; docs/architecture.md: haptics links
        # zlib, spdlog, fmt and OpenSSL's libcrypto. The installed export of the haptics modules decides.
        text = (self.prefix / "lib" / "cmake" / "calligraphy" / "calligraphyHapticsTargets.cmake").read_text("utf-8")
        links = " ".join(re.findall(r'INTERFACE_LINK_LIBRARIES "([^"]*)"', text))
        haptics_crypto = "crypto" in links
        readme = (SOURCE / "README.md").read_text("utf-8")
        architecture = (SOURCE / "docs" / "architecture.md").read_text("utf-8")
        readme_haptics = re.search(r"`calligraphy::haptics` \(.*?\) links `([^`]*)`", readme, re.S)
        self.assertIsNotNone(readme_haptics)
        self.assertEqual("-lcrypto" in readme_haptics.group(1), haptics_crypto,
                         f"README says haptics links {readme_haptics.group(1)}; the export links {links}")
        arch = re.search(r"\*\*`calligraphy::haptics`\*\*:.*?It links (.*?)[.;]", architecture, re.S)
        self.assertIsNotNone(arch)
        self.assertEqual("libcrypto" in arch.group(1), haptics_crypto, arch.group(1))


class Components(Base):
    """The components a user names: `python` alone, `phantom_usb` and `testing` beside the default."""

    @classmethod
    def setUpClass(cls):
        base = SHARED["base"]
        cls.python_only = base / "python 只"
        cmake_install(cls.python_only, "python")
        cls.full = base / "full 全"
        cmake_install(cls.full)
        cmake_install(cls.full, "phantom_usb", "testing")

    def test_python_component_alone_imports_and_serves_the_whole_corpus(self):
        self.need_python()
        done = run_python(self.site(self.python_only),
                          "import calligraphy as cg\n"
                          f"lib = cg.CharacterLibrary.default(); print(len(lib), len(lib.load({SEN!r}).strokes))\n"
                          "print(cg.__file__)",
                          self.tmp, self.env)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        first, where = done.stdout.decode().splitlines()
        count, strokes = first.split()
        self.assertEqual((count, strokes), ("9574", "12"))
        self.assertTrue(where.startswith(str(self.python_only)), where)
        self.assert_home_untouched()

    def test_python_component_alone_carries_the_data_licences(self):
        # It holds the library (statically linked) with the corpus and the embedded characters compiled in:
        # data under the Arphic Public License, whose text and the notice of the change go with the data.
        self.need_python()
        wanted = {"ARPHICPL.TXT": (CORPUS / "ARPHICPL.TXT").read_bytes(),
                  "NOTICE.md": (CORPUS / "NOTICE.md").read_bytes()}
        found = {name for name, text in wanted.items()
                 for p in self.python_only.rglob(name) if p.is_file() and p.read_bytes() == text}
        self.assertEqual(found, set(wanted), "the python component installs Arphic-licensed data without its licence")

    def test_components_named_add_their_files_and_nothing_else_changes(self):
        for rel in ("lib/libcalligraphy_phantom_usb.a", "lib/libcalligraphy_testing.a",
                    "include/calligraphy/testing", "include/calligraphy/phantom_usb"):
            self.assertTrue((self.full / rel).exists(), rel)
        plain = {str(p.relative_to(self.prefix)) for p in self.prefix.rglob("*")}
        full = {str(p.relative_to(self.full)) for p in self.full.rglob("*")}
        self.assertEqual(plain - full, set())
        self.assertTrue(all("phantom_usb" in p or "testing" in p or "Testing" in p or "PhantomUsb" in p
                            for p in full - plain), sorted(full - plain))

    def test_component_not_installed_fails_to_configure_naming_it(self):
        done = configure(self.tmp / "src", self.tmp / "b", self.prefix,
                         probe_project("find_package(calligraphy REQUIRED COMPONENTS haptics phantom_usb)"))
        self.assertNotEqual(done.returncode, 0)
        said = " ".join(done.stderr.decode().split())  # CMake wraps its message at spaces
        self.assertIn("component phantom_usb: not installed under " + " ".join(str(self.prefix).split()), said)
        self.assertIn("--component phantom_usb", said)
        done = configure(self.tmp / "src2", self.tmp / "b2", self.full,
                         probe_project("find_package(calligraphy REQUIRED COMPONENTS haptics phantom_usb testing)",
                                       "foreach(t calligraphy::phantom_usb calligraphy::testing calligraphy::core)\n"
                                       "  if(NOT TARGET ${t})\n    message(FATAL_ERROR \"no ${t}\")\n  endif()\n"
                                       "endforeach()"))
        self.assertEqual(done.returncode, 0, done.stderr.decode())

    def test_unknown_component_fails_to_configure_naming_it(self):
        done = configure(self.tmp / "src", self.tmp / "b", self.full,
                         probe_project("find_package(calligraphy REQUIRED COMPONENTS haptics quaternion_usb)"))
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("component quaternion_usb: no such component", " ".join(done.stderr.decode().split()))
        done = configure(self.tmp / "src2", self.tmp / "b2", self.full,
                         probe_project("find_package(calligraphy COMPONENTS quaternion_usb)",
                                       'message(STATUS "found=${calligraphy_FOUND}")'))
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        self.assertIn("found=0", done.stdout.decode())
        done = configure(self.tmp / "src3", self.tmp / "b3", self.full,
                         probe_project("find_package(calligraphy REQUIRED COMPONENTS haptics "
                                       "OPTIONAL_COMPONENTS quaternion_usb)",
                                       'message(STATUS "found=${calligraphy_FOUND} '
                                       'why=${calligraphy_NOT_FOUND_MESSAGE}.")'))
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        self.assertIn("found=1 why=.", done.stdout.decode())


class CMakePackage(Base):
    """A downstream project: versions, the one compile of every public header."""

    def test_version_above_the_installed_one_fails_naming_both(self):
        number = self.version_number()
        higher = f"{int(number.split('.')[0]) + 1}.0"
        done = configure(self.tmp / "src", self.tmp / "b", self.prefix,
                         probe_project(f"find_package(calligraphy {higher} REQUIRED COMPONENTS haptics)"))
        self.assertNotEqual(done.returncode, 0)
        self.assertIn(higher, done.stderr.decode())
        self.assertIn(number, done.stderr.decode())
        done = configure(self.tmp / "src2", self.tmp / "b2", self.prefix,
                         probe_project(f"find_package(calligraphy {number} EXACT REQUIRED COMPONENTS research)",
                                       'message(STATUS "version=${calligraphy_VERSION}")'))
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        self.assertIn(f"version={number}", done.stdout.decode())

    def test_every_public_header_in_one_translation_unit_builds_links_and_runs(self):
        if shutil.which("ninja") is None or shutil.which("c++") is None:
            self.skipTest("ninja or a C++ compiler is missing")
        include = self.prefix / "include"
        headers = sorted(str(p.relative_to(include)) for p in include.rglob("*.hpp"))
        self.assertGreater(len(headers), 50)
        source = self.tmp / "src"
        source.mkdir()
        (source / "main.cpp").write_text(
            "".join(f"#include <{h}>\n" for h in headers) +
            "#include <cstdio>\n"
            "int main() {\n"
            "  const calligraphy::Character c = calligraphy::CharacterLibrary::standard().load(U'\\u68EE');\n"
            "  std::printf(\"%zu\\n\", c.strokes.size());\n"
            "  return c.strokes.size() == 12 ? 0 : 1;\n"
            "}\n", encoding="utf-8")
        done = configure(source, self.tmp / "b", self.prefix,
                         "cmake_minimum_required(VERSION 3.20)\nproject(every_header CXX)\n"
                         "set(CMAKE_CXX_STANDARD 20)\nset(CMAKE_CXX_STANDARD_REQUIRED ON)\n"
                         "find_package(calligraphy 0.1 REQUIRED COMPONENTS haptics research)\n"
                         "add_executable(every_header main.cpp)\n"
                         "target_link_libraries(every_header PRIVATE calligraphy::research)\n",
                         ["-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release", "-DCMAKE_CXX_FLAGS=-O0"])
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        built = subprocess.run(["ninja", "-C", str(self.tmp / "b")], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, timeout=300)
        self.assertEqual(built.returncode, 0, built.stdout.decode()[-4000:])
        ran = subprocess.run([str(self.tmp / "b" / "every_header")], cwd=self.tmp, env=self.env,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT_S)
        self.assertEqual((ran.returncode, ran.stdout.decode().strip()), (0, "12"), ran.stderr.decode())


class Versions(Base):
    def test_one_version_in_the_program_its_record_python_and_cmake(self):
        self.need_python()
        number = self.version_number()
        again = run_installed(self.prefix, ["trial", "--version"], self.tmp, self.env)
        self.assertEqual((again.returncode, again.stdout.decode().strip()), (0, SHARED["version"]))
        done = run_installed(self.prefix, ["trial", "十", "--json", "r.json"], self.tmp, self.env)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        record = json.loads((self.tmp / "r.json").read_text("utf-8"))
        self.assertEqual(record["specification"]["library_version"], number)
        py = run_python(self.site(), "import calligraphy; print(calligraphy.__version__)", self.tmp, self.env)
        self.assertEqual((py.returncode, py.stdout.decode().strip()), (0, number), py.stderr.decode())
        config = (self.prefix / "lib" / "cmake" / "calligraphy" / "calligraphyConfigVersion.cmake").read_text()
        self.assertIn(f'set(PACKAGE_VERSION "{number}")', config)
        # README and docs/python.md name the wheel of this version
        self.assertIn(f"calligraphy-{number}-cp", (SOURCE / "README.md").read_text("utf-8"))
        self.assert_home_untouched()


class Offline(Base):
    """The installed program away from the source tree: no variable, an empty HOME, no network."""

    def test_random_corpus_characters_offline_from_an_empty_home(self):
        listed = corpus_characters(self.prefix, self.tmp, self.env)
        self.assertEqual(len(listed), 9574)
        self.assertEqual(len(EMBEDDED), 58)
        self.assertLessEqual(EMBEDDED, set(listed))
        strokes = random.SystemRandom().randint(1, 8)
        few_strokes = run_installed(self.prefix, ["characters", "--strokes", strokes], self.tmp, self.env)
        self.assertEqual(few_strokes.returncode, 0, few_strokes.stderr.decode())
        small = set(listed_characters(few_strokes.stdout))
        self.assertTrue(small and small <= set(listed), strokes)
        for char in random_picks(small - EMBEDDED, 3):
            with self.subTest(char=char, code_point=f"U+{ord(char):04X}"):
                model = run_installed(self.prefix, ["model", char, "--json"], self.tmp, self.env)
                self.assertEqual(model.returncode, 0, model.stderr.decode())
                self.assertEqual(json.loads(model.stdout)["character"], char)
                trial = run_installed(self.prefix, ["trial", char, "--seed", "2", "--json", "r.json", "--csv",
                                                    "t.csv"], self.tmp, self.env)
                self.assertEqual(trial.returncode, 0, trial.stderr.decode())
                scored = run_installed(self.prefix, ["score", "t.csv", "--character", char, "--json", "-"],
                                       self.tmp, self.env)
                self.assertEqual(scored.returncode, 0, scored.stderr.decode())
                self.assertEqual(json.loads(scored.stdout)["character"], char)
        self.assert_home_untouched()

    def test_python_loads_every_corpus_character_offline(self):
        self.need_python()
        code = ("import calligraphy as cg\n"
                "lib = cg.CharacterLibrary.default()\n"
                "chars = lib.characters()\n"
                "bad = []\n"
                "for c in chars:\n"
                "    try:\n"
                "        assert len(lib.load(c).strokes) > 0\n"
                "    except Exception as e:\n"
                "        bad.append(f'{c}: {e}')\n"
                "print(len(chars), len(bad)); print('\\n'.join(bad[:5]))\n"
                f"r = cg.simulate_trial({SEN!r}, seed=1, keep_trace=False)\n"
                "print(r.metrics['strokes_total'], r.metrics['completed_in_order'])\n")
        done = run_python(self.site(), code, self.tmp, self.env)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        lines = done.stdout.decode().split("\n")
        self.assertEqual(lines[0], "9574 0", done.stdout.decode())
        self.assertEqual(lines[-2], "12 True")
        self.assert_home_untouched()

    def test_installed_python_is_the_installed_package_with_its_documented_parts(self):
        self.need_python()
        code = ("import calligraphy, calligraphy.stats, importlib\n"
                "print(calligraphy.__file__)\n"
                "for name in ('statistics', 'mixed_models', 'design_models', 'design_analysis',\n"
                "             'crossover_analysis', 'study', 'study_report'):\n"
                "    old = importlib.import_module('calligraphy.' + name)\n"
                "    new = importlib.import_module('calligraphy.stats.' + name)\n"
                "    assert old is new, name\n"
                "print(calligraphy.run_trial('十').metrics['strokes_accepted'])\n")
        done = run_python(self.site(), code, self.tmp, self.env)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        where, accepted = done.stdout.decode().splitlines()
        self.assertTrue(where.startswith(str(self.site())), where)
        self.assertEqual(accepted, "2")
        package = self.site() / "calligraphy"
        for rel in ("_calligraphy.pyi", "py.typed", "stats/lmer_fit.R", "frames.py", "metrics.py", "experiments.py",
                    "cohort.py", "plot.py", "stats/_native.py", "stats/fonts.py"):
            self.assertTrue((package / rel).is_file(), rel)
        report = subprocess.run([*offline(), PY, "-I", "-c",
                                 f"import sys, runpy; sys.path.insert(0, {str(self.site())!r}); "
                                 "sys.argv = ['study_report', '--help']; "
                                 "runpy.run_module('calligraphy.study_report', run_name='__main__')"],
                                cwd=self.tmp, env=self.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                timeout=TIMEOUT_S)
        self.assertEqual(report.returncode, 0, report.stderr.decode())
        self.assertIn("--out", report.stdout.decode())

    def test_installed_store_read_with_store_gives_the_compiled_in_model(self):
        store = self.prefix / "share" / "calligraphy" / "corpus" / STORE_NAME
        plain = run_installed(self.prefix, ["model", SEN, "--json"], self.tmp, self.env)
        named = run_installed(self.prefix, ["model", SEN, "--json", "--store", store], self.tmp, self.env)
        self.assertEqual((plain.returncode, named.returncode), (0, 0), named.stderr.decode())
        self.assertEqual(json.loads(plain.stdout), json.loads(named.stdout))


class InstallHazards(Base):
    """Installs over each other, staged, moved, read-only, with a damaged store or a planted link."""

    def test_second_install_over_the_first_changes_nothing(self):
        prefix = self.tmp / "twice"
        first = cmake_install(prefix)
        before = tree_digest(prefix)
        second = cmake_install(prefix)
        self.assertEqual(tree_digest(prefix), before)
        self.assertEqual(sorted(installed_paths(first)), sorted(installed_paths(second)))
        self.assertNotIn("-- Installing:", second)
        done = run_installed(prefix, ["trial", SEN, "--json", "r.json"], self.tmp, self.env)
        self.assertEqual(done.returncode, 0, done.stderr.decode())

    def test_planted_link_to_a_file_outside_is_not_written_through(self):
        prefix = self.tmp / "planted"
        victim = self.tmp / "outside" / "victim"
        victim.parent.mkdir()
        victim.write_bytes(b"not yours\n")
        (prefix / "bin").mkdir(parents=True)
        (prefix / "bin" / "calligraphy").symlink_to(victim)
        (prefix / "share" / "calligraphy" / "corpus").mkdir(parents=True)
        (prefix / "share" / "calligraphy" / "corpus" / "NOTICE.md").symlink_to(victim)
        cmake_install(prefix)
        self.assertEqual(victim.read_bytes(), b"not yours\n", "cmake --install wrote outside its prefix")
        done = run_installed(prefix, ["--version"], self.tmp, self.env)
        self.assertEqual(done.stdout.decode().strip(), SHARED["version"])

    def test_destdir_stages_everything_under_it(self):
        stage = self.tmp / "stage 台"
        prefix = "/opt/calligraphy 书法"
        output = cmake_install(prefix, None, "python", destdir=stage)
        self.assertFalse(Path(prefix).exists())
        for path in installed_paths(output):
            self.assertTrue(str(path).startswith(str(stage) + prefix + "/"), path)
        staged = Path(str(stage) + prefix)
        done = run_installed(staged, ["model", SEN, "--json"], self.tmp, self.env)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        found = configure(self.tmp / "src", self.tmp / "b", staged,
                          probe_project("find_package(calligraphy REQUIRED COMPONENTS haptics)",
                                        "get_target_property(inc calligraphy::core INTERFACE_INCLUDE_DIRECTORIES)\n"
                                        'message(STATUS "inc=${inc}")'))
        self.assertEqual(found.returncode, 0, found.stderr.decode())
        self.assertIn(f"inc={staged}/include", found.stdout.decode())

    def test_moved_tree_runs_imports_and_is_found_where_it_now_is(self):
        self.need_python()
        first = self.tmp / "first"
        cmake_install(first)
        moved = self.tmp / "moved 移动"
        os.rename(first, moved)
        done = run_installed(moved, ["trial", SEN, "--json", "r.json", "--csv", "t.csv"], self.tmp, self.env)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        scored = run_installed(moved, ["score", "t.csv", "--character", SEN, "--json", "-"], self.tmp, self.env)
        self.assertEqual(scored.returncode, 0, scored.stderr.decode())
        py = run_python(self.site(moved), f"import calligraphy as cg; print(len(cg.CharacterLibrary.default()."
                                          f"load({SEN!r}).strokes), cg.__file__)", self.tmp, self.env)
        self.assertEqual(py.returncode, 0, py.stderr.decode())
        count, where = py.stdout.decode().strip().split(maxsplit=1)
        self.assertEqual(count, "12")
        self.assertTrue(where.startswith(str(moved)), where)
        found = configure(self.tmp / "src", self.tmp / "b", moved,
                          probe_project("find_package(calligraphy REQUIRED COMPONENTS haptics research)",
                                        "get_target_property(lib calligraphy::study IMPORTED_LOCATION_RELEASE)\n"
                                        'message(STATUS "lib=${lib}")'))
        self.assertEqual(found.returncode, 0, found.stderr.decode())
        self.assertIn(f"lib={moved}/lib/libcalligraphy_study.a", found.stdout.decode())

    def test_read_only_install_serves_nobody(self):
        self.need_python()
        if os.geteuid() != 0 or shutil.which("setpriv") is None:
            self.skipTest("needs root and setpriv to run as nobody")
        prefix = self.tmp / "ro 只读"
        cmake_install(prefix)
        for path in [prefix, *prefix.rglob("*")]:
            if not path.is_symlink():
                os.chmod(path, path.stat().st_mode & ~(stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH))
        before = tree_digest(prefix)
        nobody = ["setpriv", "--reuid", "nobody", "--regid", "nogroup", "--clear-groups"]
        out = self.tmp / "out"
        out.mkdir()
        os.chmod(out, 0o777)
        done = run_installed(prefix, ["trial", SEN, "--json", "r.json"], out, self.env, wrapper=nobody)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        py = run_python(self.site(prefix), "import calligraphy.stats.study, calligraphy as cg; "
                                           f"print(cg.simulate_trial({SEN!r}, keep_trace=False)"
                                           ".metrics['strokes_total'])", out, self.env, wrapper=nobody)
        self.assertEqual((py.returncode, py.stdout.decode().strip()), (0, "12"), py.stderr.decode())
        into = run_installed(prefix, ["model", SEN, "--svg", prefix / "share" / "m.svg"], out, self.env,
                             wrapper=nobody)
        self.assert_one_error(into, 1, "m.svg")
        self.assertEqual(tree_digest(prefix), before)

    def test_damaged_installed_store_is_named_and_the_compiled_in_one_still_serves(self):
        self.need_python()
        prefix = self.tmp / "damaged 损坏"
        cmake_install(prefix)
        store = prefix / "share" / "calligraphy" / "corpus" / STORE_NAME
        with open(store, "r+b") as handle:
            handle.truncate(store.stat().st_size // 2)
        plain = run_installed(prefix, ["trial", SEN, "--json", "r.json"], self.tmp, self.env)
        self.assertEqual(plain.returncode, 0, plain.stderr.decode())
        named = run_installed(prefix, ["model", SEN, "--store", store], self.tmp, self.env)
        self.assert_one_error(named, 1, STORE_NAME, "damaged 损坏")
        py = run_python(self.site(prefix), "import calligraphy as cg\ntry:\n"
                                           f"    cg.CharacterLibrary.from_store({str(store)!r})\n"
                                           "except cg.DataError as e:\n    print('DataError', e)\n",
                        self.tmp, self.env)
        self.assertEqual(py.returncode, 0, py.stderr.decode())
        self.assertTrue(py.stdout.decode().startswith("DataError"), py.stdout.decode())
        self.assertIn(STORE_NAME, py.stdout.decode())

    def test_missing_installed_store_is_named_and_the_compiled_in_one_still_serves(self):
        prefix = self.tmp / "missing"
        cmake_install(prefix)
        store = prefix / "share" / "calligraphy" / "corpus" / STORE_NAME
        store.unlink()
        plain = run_installed(prefix, ["model", SEN, "--json"], self.tmp, self.env)
        self.assertEqual(plain.returncode, 0, plain.stderr.decode())
        named = run_installed(prefix, ["trial", SEN, "--store", store], self.tmp, self.env)
        self.assert_one_error(named, 1, STORE_NAME)
        self.assertEqual(sorted(p.name for p in self.tmp.iterdir() if p.is_file()), [])


if __name__ == "__main__":
    unittest.main(verbosity=2)
