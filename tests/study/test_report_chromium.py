#!/usr/bin/env python3
"""The per-trial pages of the shipped paper-table5 protocol (4 simulated subjects) loaded in headless
Chromium, run by CTest as `study_report_chromium`: each session's page as Chromium builds it has a trajectory
and a force figure per trial, each trial anchored by its session id and number, and no summary table; the
index links every session's page. Exits 77 (CTest: skipped) when no Chromium is installed. Prints the
measured session and report times. With CALLIGRAPHY_SCREENSHOT=FILE.png it also takes a screenshot of the
first session's page.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SKIP = 77


def chromium_command(user_data_dir):
    # Headless, offline, no sandbox (CI runs as root), a fresh profile.
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    return [browser, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync",
            f"--user-data-dir={user_data_dir}"]


def main():
    if not (shutil.which("chromium") or shutil.which("chromium-browser")):
        print("SKIPPED: chromium is not installed (scripts/install-deps.sh installs it)")
        return SKIP
    if not CLI or not Path(CLI).exists():
        print(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run this test through ctest")
        return 1
    with tempfile.TemporaryDirectory(prefix="calligraphy-report-") as folder:
        folder = Path(folder)
        start = time.monotonic()
        subprocess.run([CLI, "session", "run", SOURCE / "examples" / "protocols" / "paper-table5.json",
                        "--writer", "simulated", "--subjects", "4", "--out", folder / "S"],
                       check=True, stdout=subprocess.DEVNULL, timeout=1800)
        run_s = time.monotonic() - start
        start = time.monotonic()
        page = folder / "S" / "report.html"
        subprocess.run([CLI, "report", folder / "S", "--out", page], check=True, stdout=subprocess.DEVNULL,
                       timeout=600)
        report_s = time.monotonic() - start
        session_pages = sorted((folder / "S" / "report_files").glob("S0*/*.html"))
        size = sum(p.stat().st_size for p in session_pages) + page.stat().st_size
        print(f"session run, 4 simulated subjects: {run_s:.1f} s; report: {report_s:.1f} s, {size / 1e6:.1f} MB")
        trials = len(list((folder / "S").glob("S0*/*/trials/*.json")))
        profile = folder / "profile"

        def dom_of(path):
            return subprocess.run(chromium_command(profile) + ["--dump-dom", path.as_uri()], check=True,
                                  stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, timeout=300).stdout.decode()

        problems = []
        index = dom_of(page)
        counts = {"trajectory": 0, "force": 0, "learning-curve": 0}
        tables = 0
        for session_page in session_pages:
            if f'href="report_files/{session_page.parent.name}/{session_page.name}"' not in index:
                problems.append(f"the index does not link {session_page.name}")
            dom = dom_of(session_page)
            for name in counts:
                counts[name] += dom.count(f'<figure class="{name}"')
            tables += dom.count("<table")
            if f'id="trial-{session_page.stem}-1"' not in dom:
                problems.append(f"{session_page.name}: no anchor trial-{session_page.stem}-1")
        print(f"chromium DOM: {trials} trials on {len(session_pages)} pages, figures {counts}, {tables} tables")
        if trials != 104:
            problems.append(f"expected 104 saved trials (4 subjects x 26), found {trials}")
        if len(session_pages) != 4:
            problems.append(f"expected a page for each of the 4 sessions, found {len(session_pages)}")
        if counts["trajectory"] != trials or counts["force"] != trials:
            problems.append("not one trajectory and one force figure per trial")
        if counts["learning-curve"] != 0 or tables != 0:
            problems.append("a summary over trials on a per-trial page (the study report owns them)")
        screenshot = os.environ.get("CALLIGRAPHY_SCREENSHOT")
        if screenshot and session_pages:
            subprocess.run(chromium_command(folder / "profile2") + [f"--screenshot={screenshot}",
                                                                      "--window-size=1400,1900",
                                                                      session_pages[0].as_uri()],
                           check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=300)
        for problem in problems:
            print("FAILED:", problem)
        print(f"{1 if not problems else 0} passed, {1 if problems else 0} failed")
        return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
