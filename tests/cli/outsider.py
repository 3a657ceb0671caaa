"""What the rounds of hostile cases written from the documentation alone (test_unseen_round*.py) share: the
program they run (CALLIGRAPHY_CLI), its environment without a device library or a display, one way to run it,
and the lines of its error output.

Under the sanitizers (CALLIGRAPHY_SANITIZED=1, set by tests/CMakeLists.txt's add_outsider_round) each case is
a run of the program about ten times slower, so a round runs only the few cases it names there.
"""
import os
import select
import shutil
import subprocess
import unittest
from pathlib import Path

SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED") == "1"
CLI = os.environ.get("CALLIGRAPHY_CLI", "")
TIMEOUT_S = 60
# No real device library, no display: what a command checks before it opens either shows as its exit status.
ENV = {k: v for k, v in os.environ.items()
       if not k.startswith("CALLIGRAPHY_LIBHD") and k not in ("DISPLAY", "WAYLAND_DISPLAY")}


def start_own_x_server(screen="1024x768x24", framebuffer_dir=None, wait_s=20):
    """An X server of the caller's own (Xvfb -displayfd: the display number it picks, so that runs in parallel
    never share one), or None where Xvfb is missing or does not start within `wait_s`. Returns (process,
    ":N"); with `framebuffer_dir` its screen is kept there as the file Xvfb_screen0 (XWD) to read what is
    shown. The caller ends the process."""
    if shutil.which("Xvfb") is None:
        return None
    command = ["Xvfb", "-displayfd", "", "-screen", "0", screen, "-nolisten", "tcp"]
    if framebuffer_dir is not None:
        command += ["-fbdir", str(framebuffer_dir)]
    read_end, write_end = os.pipe()
    command[2] = str(write_end)
    process = subprocess.Popen(command, pass_fds=(write_end,), stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    os.close(write_end)
    number = b""
    try:
        while not number.endswith(b"\n") and select.select([read_end], [], [], wait_s)[0]:
            chunk = os.read(read_end, 16)
            if not chunk:
                break
            number += chunk
    finally:
        os.close(read_end)
    if not number.strip():
        process.kill()
        process.wait()
        return None
    return process, ":" + number.decode().strip()


def run(args, cwd, timeout=TIMEOUT_S, env=None, **kw):
    """The program with `args` (text or bytes) in `cwd`, its output and errors captured, no standard input."""
    arguments = [a if isinstance(a, bytes) else str(a) for a in args]
    kw.setdefault("stdout", subprocess.PIPE)
    kw.setdefault("stderr", subprocess.PIPE)
    kw.setdefault("stdin", subprocess.DEVNULL)
    return subprocess.run([CLI, *arguments], cwd=cwd, timeout=timeout, env=ENV if env is None else env, **kw)


def run_ok(args, cwd, ok=True):
    """As `run`; with `ok`, a run that did not exit 0 raises AssertionError naming the command, its status and
    its standard error."""
    result = run(args, cwd)
    if ok and result.returncode != 0:
        raise AssertionError(f"calligraphy {' '.join(map(str, args))}: {result.returncode}\n"
                             f"{result.stderr.decode('utf-8', 'replace')}")
    return result


def error_lines(result):
    """The lines the run wrote to its standard error, the blank ones at its two ends left out."""
    return result.stderr.decode("utf-8", "replace").strip().splitlines()


class OneErrorLine:
    """A mixin for unittest.TestCase: `assert_one_error` holds a run to the documented error output."""

    def assert_one_error(self, result, status, *needles):
        """The run ended with `status` (or one of a tuple of them) and wrote one error line holding each of
        `needles`: no traceback, no C++ runtime's abort text. Returns the line."""
        text = result.stderr.decode("utf-8", "replace")
        statuses = status if isinstance(status, tuple) else (status,)
        self.assertIn(result.returncode, statuses, text)
        self.assertNotIn("Traceback", text)
        self.assertNotIn("terminate called", text)
        got = error_lines(result)
        self.assertEqual(len(got), 1, f"expected one error line, got {got!r}")
        self.assertIn("error", got[0])
        for needle in needles:
            self.assertIn(needle, got[0])
        return got[0]


def sanitized_subset(names):
    """A `load_tests` (unittest's protocol) that keeps every case, or under the sanitizers only the test
    methods named in `names`."""
    def load_tests(loader, tests, pattern):  # noqa: ARG001 - unittest's protocol
        if not SANITIZED:
            return tests
        chosen = unittest.TestSuite()

        def walk(suite):
            for item in suite:
                if isinstance(item, unittest.TestSuite):
                    walk(item)
                elif getattr(item, "_testMethodName", "") in names:
                    chosen.addTest(item)
        walk(tests)
        return chosen
    return load_tests


def last_case(tests, name):
    """`tests` as one flat suite with the test method `name` moved to its end, and whether that case is in it: a
    case that waits on a clock runs last, beside what the others started."""
    cases, last = [], []

    def walk(suite):
        for item in suite:
            if isinstance(item, unittest.TestSuite):
                walk(item)
            else:
                (last if getattr(item, "_testMethodName", "") == name else cases).append(item)
    walk(tests)
    return unittest.TestSuite(cases + last), bool(last)


def strip_comment(line):
    """A shell line without its trailing `# comment` (a `#` outside quotes at the start or after a space), and
    the comment; a line with none as it is, right-stripped, and ""."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1] in " \t"):
            return line[:i].rstrip(), line[i + 1:].strip()
    return line.rstrip(), ""


def descendants(pid):
    """Every process below `pid`, by the parent ids of /proc, while they run (a process that starts a session
    of its own, as the serving R does, is found by its parent, not by the session id)."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                fields = Path(f"/proc/{entry}/stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            children.setdefault(int(fields[1]), []).append(int(entry))
    found, stack = [], [pid]
    while stack:
        for child in children.get(stack.pop(), []):
            found.append(child)
            stack.append(child)
    return found


def running(pid):
    """`pid` exists and has not ended (a zombie has)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False
