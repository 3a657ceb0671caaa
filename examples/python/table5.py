#!/usr/bin/env python3
"""The paper's Table 5 experiment (Wang, Zhang & Yao 2006, section 7) on simulated writers, and fixed,
fading and replayed guidance compared on retention.

(a) Table 5: four characters written with and without haptic guidance by the novice and the foreign
simulated writers (the paper's subjects included a foreign student, section 7), several seeds each, at
1 kHz on the simulated Phantom Desktop. Prints the mean writing time [s] and mean deviation [mm] with
their spread (sample standard deviation over the seeds), the trials written completely in order, and
the paper's measured times beside them (human writers: not expected to match in size).

(b) Retention: a foreign writer that learns (learning_rate > 0, calligraphy.next_repetition_profile)
practises the characters for N repetitions under each guidance mode, then writes them without guidance.
 - none: unguided practice (the control);
 - fixed: the paper's fixture, eq. (8), every repetition;
 - fading: the gain of each repetition from the previous one's mean deviation by next_guidance_gain
   (Emken, Benitez & Reinkensmeyer 2007), starting at 1;
 - replay: a teacher recorded from a skilled writer's guided trial (record_teacher), replayed in time.
The writer's profile after each repetition comes from what it did in that repetition (its WriterLog:
order and direction errors, and whether the display refused them) and the feedback share of the mode;
no result is set by hand. Prints the retention trials' time, deviation and out-of-order attempts, mean
(std) over seeds.

Also measures the speed of a simulated trial from Python: a 10-stroke character (家) at 1 kHz,
simulated seconds per wall-clock second.

Run from a build tree:
    PYTHONPATH=build/python /usr/bin/python3 examples/python/table5.py [--seeds 8] [--plots DIR]

Force plots (one trial per character with guidance off and on, the in-plane force against time with
the stroke boundaries, calligraphy.plot.forces) are written with --plots DIR when matplotlib imports.
"""

import argparse
import statistics
import sys
import time

import calligraphy

CHARACTERS = "永我九心"
WRITERS = ("novice", "foreign")
# Table 5 of the paper, writing time [s]: (no feedback, with feedback), human writers.
PAPER_TIMES_S = {"C1": (50.8, 37.5), "C2": (30.3, 26.6), "C3": (31.0, 27.3), "C4": (32.2, 26.4)}

RETENTION_CHARACTERS = "我九"
GUIDANCE_MODES = ("none", "fixed", "fading", "replay")


def spread(values):
    return statistics.stdev(values) if len(values) > 1 else 0.0


def cell(values, width=6, digits=2):
    """'mean (std)' of the values that are not None (a trial that wrote no stroke has no deviation)."""
    known = [v for v in values if v is not None]
    if not known:
        return f"{'n/a':>{width + 7}}"
    text = f"{statistics.mean(known):{width}.{digits}f} ({spread(known):4.{digits}f})"
    return text if len(known) == len(values) else text + f" [{len(values) - len(known)} n/a]"


def mean_of_known(values):
    known = [v for v in values if v is not None]
    return statistics.mean(known) if known else None


def trial_cell(character, writer, guidance, seeds):
    """Times [s], deviations [mm], trials completed in order and out-of-order attempts over `seeds`."""
    times, deviations, in_order, order_errors = [], [], 0, []
    for seed in seeds:
        result = calligraphy.simulate_trial(character, writer=writer, guidance=guidance, seed=seed,
                                            keep_trace=False)
        times.append(result.metrics["total_time_s"])
        deviations.append(result.metrics["mean_deviation_m"] * 1e3)
        in_order += bool(result.metrics["completed_in_order"])
        order_errors.append(result.writer_log.out_of_order_attempts())
    return {"time_s": times, "deviation_mm": deviations, "in_order": in_order, "order_errors": order_errors}


def table5(seeds, characters=CHARACTERS, writers=WRITERS):
    """One row per writer and character: {guidance: trial_cell}."""
    rows = []
    for writer in writers:
        for index, char in enumerate(characters):
            cells = {guidance: trial_cell(char, writer, guidance, range(seeds)) for guidance in (False, True)}
            rows.append((writer, f"C{index + 1}", char, cells))
    return rows


def print_table(rows, seeds):
    print(f"(a) Table 5 on simulated writers: mean (std) over {seeds} seeds, 1 kHz, simulated Phantom Desktop")
    print()
    header = (f"{'writer':8} {'':3} {'char':4} | {'time off [s]':>14} {'time on [s]':>14} | "
              f"{'dev off [mm]':>13} {'dev on [mm]':>13} | {'in order off/on':>15} | {'paper off/on [s]':>16}")
    print(header)
    print("-" * len(header))
    for writer, label, char, cells in rows:
        off, on = cells[False], cells[True]
        paper = PAPER_TIMES_S.get(label)
        paper_text = f"{paper[0]:7.1f} / {paper[1]:5.1f}" if paper else ""
        print(f"{writer:8} {label:3} {char:>3}  | {cell(off['time_s'], 7)} {cell(on['time_s'], 7)} | "
              f"{cell(off['deviation_mm'])} {cell(on['deviation_mm'])} | "
              f"{off['in_order']:6d}/{on['in_order']:<8d} | {paper_text}")
    print()
    print("time: from the start to the last stroke written (or to the writer giving up); dev: mean in-plane")
    print("distance of the pen tip from the active stroke while writing; in order: trials with every stroke")
    print("written, each in its turn; n/a: trials that wrote no stroke (no deviation). Paper: writing time of")
    print("human subjects without / with force feedback.")


def teachers(characters, seed=0):
    """A teacher's recording per character: a skilled writer's guided trial."""
    return {char: calligraphy.record_teacher(
        calligraphy.simulate_trial(char, writer="skilled", guidance=True, seed=seed)) for char in characters}


def train_and_retain(mode, seed, characters, repetitions, learning_rate, teacher_of):
    """Practice under `mode` for `repetitions`, then one unguided retention trial per character.

    Every trial's seed depends on the seed, the repetition and the character only, so the modes see the
    same random draws (common random numbers). Returns the retention trials' mean time [s], mean
    deviation [mm], out-of-order attempts (sum), the final profile and fading gain, and the practice
    trials' mean deviation [mm].
    """
    profile = calligraphy.writer_profile("foreign", {"learning_rate": learning_rate})
    gain = 1.0
    practice_deviations = []
    for repetition in range(repetitions):
        for index, char in enumerate(characters):
            kwargs = {"guidance": mode != "none"}
            share = 0.0 if mode == "none" else 1.0
            if mode == "fading":
                kwargs.update(guidance_mode="fading", guidance_gain=gain)
                share = gain
            elif mode == "replay":
                kwargs["teacher"] = teacher_of[char]
            result = calligraphy.simulate_trial(char, writer=profile, seed=seed * 1000 + repetition * 10 + index,
                                                keep_trace=False, **kwargs)
            practice_deviations.append(result.metrics["mean_deviation_m"] * 1e3)
            outcome = calligraphy.RepetitionOutcome.from_log(result.writer_log, share)
            profile = calligraphy.next_repetition_profile(profile, outcome)
            if mode == "fading":
                gain = calligraphy.next_guidance_gain(gain, result.metrics["mean_deviation_m"])
    times, deviations, order_errors = [], [], 0
    for index, char in enumerate(characters):
        result = calligraphy.simulate_trial(char, writer=profile, guidance=False, seed=seed * 1000 + 900 + index,
                                            keep_trace=False)
        times.append(result.metrics["total_time_s"])
        deviations.append(result.metrics["mean_deviation_m"] * 1e3)
        order_errors += result.writer_log.out_of_order_attempts()
    return (statistics.mean(times), mean_of_known(deviations), order_errors, profile, gain,
            mean_of_known(practice_deviations))


def retention(seeds, repetitions, learning_rate, characters=RETENTION_CHARACTERS):
    """{mode: {"time_s": [...], "deviation_mm": [...], "order_errors": [...], ...}} over seeds."""
    teacher_of = teachers(characters)
    table = {}
    for mode in GUIDANCE_MODES:
        rows = [train_and_retain(mode, seed, characters, repetitions, learning_rate, teacher_of)
                for seed in range(seeds)]
        table[mode] = {
            "time_s": [r[0] for r in rows],
            "deviation_mm": [r[1] for r in rows],
            "order_errors": [r[2] for r in rows],
            "bias_mm": [r[3].bias_offset_m * 1e3 for r in rows],
            "order_error_probability": [r[3].order_error_probability for r in rows],
            "final_gain": [r[4] for r in rows],
            "practice_deviation_mm": [r[5] for r in rows],
        }
    return table


def print_retention(table, seeds, repetitions, learning_rate, characters=RETENTION_CHARACTERS):
    print(f"(b) Retention after {repetitions} practice repetitions of {characters} by a learning foreign writer "
          f"(learning_rate {learning_rate}); unguided retention trials, mean (std) over {seeds} seeds")
    print()
    header = (f"{'practice':8} | {'practice dev':>13} | {'time [s]':>14} | {'dev [mm]':>13} | {'order errors':>13} | "
              f"{'bias [mm]':>13} | {'p(order err)':>13} | {'final gain':>10}")
    print(header)
    print("-" * len(header))
    for mode, columns in table.items():
        gain = f"{statistics.mean(columns['final_gain']):10.2f}" if mode == "fading" else f"{'':10}"
        print(f"{mode:8} | {cell(columns['practice_deviation_mm'])} | {cell(columns['time_s'], 7)} | {cell(columns['deviation_mm'])} | "
              f"{cell(columns['order_errors'])} | {cell(columns['bias_mm'])} | "
              f"{cell(columns['order_error_probability'], 6, 3)} | {gain}")
    print()
    print("practice dev: mean deviation [mm] over the practice trials (guided as the mode says);")
    print("time, dev: mean over the retention characters; order errors: out-of-order attempts summed over")
    print("them (the writer's log); bias, p(order err): the learned profile's bias_offset_m and")
    print("order_error_probability after practice; final gain: the fading gain after the last repetition.")


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
    parser.add_argument("--seeds", type=int, default=4, help="seeds per cell (default 4)")
    parser.add_argument("--repetitions", type=int, default=4, help="practice repetitions in (b) (default 4)")
    parser.add_argument("--learning-rate", type=float, default=0.3,
                        help="learning_rate of the foreign writer in (b) (default 0.3)")
    parser.add_argument("--plots", default=None, help="folder for force plots (needs matplotlib)")
    parser.add_argument("--no-speed", action="store_true", help="skip the speed measurement")
    args = parser.parse_args(argv)
    if args.seeds < 1:
        parser.error("--seeds must be at least 1")
    if args.repetitions < 1:
        parser.error("--repetitions must be at least 1")
    if not args.learning_rate > 0:
        parser.error("--learning-rate must be > 0 (retention needs a writer that learns)")
    start = time.perf_counter()
    rows = table5(args.seeds)
    print_table(rows, args.seeds)
    print(f"({len(rows) * 2 * args.seeds} trials in {time.perf_counter() - start:.1f} s wall)")
    print()
    start = time.perf_counter()
    table = retention(args.seeds, args.repetitions, args.learning_rate)
    print_retention(table, args.seeds, args.repetitions, args.learning_rate)
    trials = len(GUIDANCE_MODES) * args.seeds * (args.repetitions + 1) * len(RETENTION_CHARACTERS)
    print(f"({trials} trials in {time.perf_counter() - start:.1f} s wall)")
    print()
    if not args.no_speed:
        measure_speed()
    if args.plots:
        save_plots(args.plots)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
