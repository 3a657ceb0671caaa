#!/usr/bin/env python3
"""The paper's Table 5 experiment (Wang, Zhang & Yao 2006, section 7) on simulated writers.

Four characters are written with and without haptic guidance by novice and skilled simulated writers,
several seeds each, at 1 kHz on the simulated Phantom Desktop. Prints the mean writing time [s] and
the mean deviation [mm] with their spread (sample standard deviation over the seeds), next to the
paper's measured times (which came from human writers and are not expected to match in size).

Also measures the speed of a simulated trial from Python: a 10-stroke character (家) at 1 kHz,
simulated seconds per wall-clock second.

Run from a build tree:
    PYTHONPATH=build/python /usr/bin/python3 examples/python/table5.py [--seeds 8] [--plots DIR]

Force plots (one trial per character with guidance off and on, the in-plane force against time with
the stroke boundaries, calligraphy.plot.forces) are written only when matplotlib imports.
"""

import argparse
import statistics
import sys
import time

import calligraphy

CHARACTERS = "永我九心"
# Table 5 of the paper, writing time [s]: (no feedback, with feedback), human writers.
PAPER_TIMES_S = {"C1": (50.8, 37.5), "C2": (30.3, 26.6), "C3": (31.0, 27.3), "C4": (32.2, 26.4)}


def spread(values):
    return statistics.stdev(values) if len(values) > 1 else 0.0


def table5(seeds):
    rows = []
    for writer in ("novice", "skilled"):
        for index, char in enumerate(CHARACTERS):
            cells = {}
            for guidance in (False, True):
                times, deviations, completed = [], [], 0
                for seed in range(seeds):
                    m = calligraphy.simulate_trial(char, writer=writer, guidance=guidance, seed=seed,
                                                   keep_trace=False).metrics
                    times.append(m["time_s"])
                    deviations.append(m["mean_deviation_mm"])
                    completed += m["completed_in_order"]
                cells[guidance] = (times, deviations, completed)
            rows.append((writer, f"C{index + 1}", char, cells))
    return rows


def print_table(rows, seeds):
    print(f"Table 5 on simulated writers: mean (std) over {seeds} seeds, 1 kHz, simulated Phantom Desktop")
    print()
    header = (f"{'writer':8} {'':3} {'char':4} | {'time off [s]':>14} {'time on [s]':>14} | "
              f"{'dev off [mm]':>13} {'dev on [mm]':>13} | {'done off/on':>11} | {'paper off/on [s]':>16}")
    print(header)
    print("-" * len(header))
    for writer, label, char, cells in rows:
        t_off, d_off, c_off = cells[False]
        t_on, d_on, c_on = cells[True]
        paper = PAPER_TIMES_S[label]
        print(f"{writer:8} {label:3} {char:>3}  | "
              f"{statistics.mean(t_off):7.2f} ({spread(t_off):4.2f}) {statistics.mean(t_on):7.2f} ({spread(t_on):4.2f}) | "
              f"{statistics.mean(d_off):6.2f} ({spread(d_off):4.2f}) {statistics.mean(d_on):6.2f} ({spread(d_on):4.2f}) | "
              f"{c_off:4d}/{c_on:<4d}  | {paper[0]:7.1f} / {paper[1]:5.1f}")
    print()
    print("time: from the start to the last stroke written; dev: mean in-plane distance of the pen tip")
    print("from the active stroke while writing; done: trials with every stroke written in order.")


def measure_speed(char="家", repeats=3):
    strokes = len(calligraphy.CharacterLibrary.default().load(char))
    runs = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = calligraphy.simulate_trial(char, seed=0, rate_hz=1000.0)
        wall = time.perf_counter() - start
        simulated = result.time_s.size * 1e-3  # one sample per 1 ms servo tick
        runs.append((simulated / wall, simulated, wall))
    best = max(runs)
    factor, simulated, wall = best
    print(f"Speed: {char} ({strokes} strokes), novice, guided, 1 kHz, trace kept: {simulated:.2f} s simulated "
          f"in {wall * 1e3:.1f} ms wall = {factor:.0f}x real time (best of {repeats})")
    return factor


def save_plots(folder):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        import calligraphy.plot
    except ImportError:
        print("matplotlib is not installed: no force plots")
        return
    import os

    os.makedirs(folder, exist_ok=True)
    for char in CHARACTERS:
        fig, axes = plt.subplots(2, 1, sharex=True, figsize=(9, 6))
        for ax, guidance in zip(axes, (False, True)):
            r = calligraphy.simulate_trial(char, guidance=guidance, seed=0)
            calligraphy.plot.forces(r, ax=ax)
            ax.text(0.01, 0.96, f"guidance {'on' if guidance else 'off'}", transform=ax.transAxes, va="top",
                    fontsize=9)
        path = os.path.join(folder, f"force_{ord(char):04X}.png")
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)
        print(f"wrote {path}")


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=8, help="trials per cell (default 8)")
    parser.add_argument("--plots", default="table5_plots", help="folder for force plots (needs matplotlib)")
    args = parser.parse_args(argv)
    if args.seeds < 1:
        parser.error("--seeds must be at least 1")
    start = time.perf_counter()
    rows = table5(args.seeds)
    print_table(rows, args.seeds)
    print(f"({len(rows) * 2 * args.seeds} trials in {time.perf_counter() - start:.1f} s wall)")
    print()
    measure_speed()
    save_plots(args.plots)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
