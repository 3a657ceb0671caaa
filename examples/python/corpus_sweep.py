#!/usr/bin/env python3
"""Whole-corpus sweep: every character of a corpus written by a simulated writer with guidance off and on.

A notebook in script form (``# %%`` cells; in Jupyter, run the cells and then ``main([...])``). One
simulated trial per character x guidance x seed with ``calligraphy.experiments.sweep`` on every local
core (or a Dask cluster with --scheduler), then:

* the table, one row per trial (parquet when pyarrow is installed, else CSV);
* the share of characters completed in order (every stroke written, in the right order), guidance
  off and on, and the trials that failed (their error text);
* a figure: the character whose mean deviation guidance reduces most, written without and with
  guidance (``calligraphy.plot.trial``, the paper's Fig. 31), and histograms of the per-trial
  differences (off - on) of the mean deviation (shown in mm) and the writing time [s].

Characters come from the embedded set (58, runs anywhere), a hanzi-writer-data folder (--data, all
9,574 characters; ``scripts/fetch-hanzi-writer-data.sh`` prints it) or a corpus store (--store,
``calligraphy corpus build``); --every K keeps every K-th character in code-point order, --limit N the
first N of those. From a build tree:

    PYTHONPATH=build/python python3 examples/python/corpus_sweep.py
    PYTHONPATH=build/python python3 examples/python/corpus_sweep.py \\
        --data "$(scripts/fetch-hanzi-writer-data.sh)" --every 10 --out corpus_sweep_every10
"""

# %% [markdown]
# # Setup
# The sweep runs on worker processes that import this file, so all work is in functions called from
# `main`, under `if __name__ == "__main__":` (a 'spawn'/'forkserver' process pool requires it).

# %%
import argparse
import os
import sys
import time

import calligraphy
import calligraphy.experiments

METRICS = ("mean_deviation_m", "total_time_s")  # names of the metric table, SI units


# %% [markdown]
# # 1. Which characters
# Every character of the source in code-point order, thinned to every K-th and cut to the first N.

# %%
def choose_characters(store, data, every, limit):
    if store:
        library = calligraphy.CharacterLibrary.from_store(store)
    elif data:
        library = calligraphy.CharacterLibrary.from_hanzi_writer(data)
    else:
        library = calligraphy.CharacterLibrary.embedded()  # the 58 embedded characters
    characters = sorted(library.characters())[::every]
    return characters[:limit] if limit else characters


# %% [markdown]
# # 2. The sweep
# One trial per character x guidance x seed; the characters are loaded by name on the workers.

# %%
def run_sweep(characters, args, client):
    start = time.perf_counter()
    table = calligraphy.experiments.sweep(
        characters, {"guidance": [False, True], "writer": [args.writer]}, args.seeds, client=client,
        store=args.store, data=args.data, progress=not args.quiet, workers=args.workers)
    wall_s = time.perf_counter() - start
    print(f"{len(table)} trials of {len(characters)} characters in {wall_s:.1f} s wall: "
          f"{len(table) / wall_s:.2f} trials/s, {table.trial_time_s.sum() / wall_s:.0f} simulated s per wall s")
    return table


# %% [markdown]
# # 3. Save the table

# %%
def save_table(table, folder):
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        path = os.path.join(folder, "trials.csv")
        table.to_csv(path, index=False)
    else:
        path = os.path.join(folder, "trials.parquet")
        table.to_parquet(path, index=False)
    print(f"wrote {path}")


# %% [markdown]
# # 4. Completed in order, guidance off and on
# A character counts as completed in order in a trial when every stroke was written, in order, before the
# writer gave up or the time ran out; the share is over the trials that ran (failed ones listed apart).

# %%
def summarise(table):
    ran = table[table.error.isna()]
    for guidance, group in ran.groupby("guidance"):
        share = group.completed_in_order.astype(bool).mean()
        print(f"guidance {'on ' if guidance else 'off'}: {share:6.1%} of {len(group)} trials completed in order; "
              f"mean deviation {group.mean_deviation_m.mean() * 1e3:.2f} mm, writing time {group.total_time_s.mean():.1f} s")
    failed = table[table.error.notna()]
    if len(failed):
        print(f"{len(failed)} trials failed ({failed.character.nunique()} characters), e.g.:")
        for text, count in failed.error.value_counts().head(5).items():
            print(f"  {count} x {text}")
    return ran


def differences(ran):
    """Per character and seed: off - on of each metric (positive: guidance lowered it)."""
    wide = ran.pivot_table(index=["character", "seed"], columns="guidance", values=list(METRICS))
    return {metric: (wide[metric][False] - wide[metric][True]).dropna() for metric in METRICS}


# %% [markdown]
# # 5. Figure
# Top: the character guidance helps most, written without and with it (reference blue, pen green).
# Bottom: histograms of the differences over all characters.

# %%
def draw_figure(diffs, args, folder):
    try:
        import matplotlib

        if not os.environ.get("DISPLAY"):
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        import calligraphy.plot
    except ImportError:
        print("matplotlib is not installed: no figure")
        return
    deviation = diffs["mean_deviation_m"]
    if deviation.empty:
        print("no character ran with guidance off and on: no figure")
        return
    character, seed = deviation.idxmax()
    library = {"library": calligraphy.CharacterLibrary.from_store(args.store)} if args.store else (
        {"library": calligraphy.CharacterLibrary.from_hanzi_writer(args.data)} if args.data else {})
    fig, axes = plt.subplots(2, 2, figsize=(10, 8))
    for ax, guidance in zip(axes[0], (False, True)):
        result = calligraphy.simulate_trial(character, writer=args.writer, guidance=guidance, seed=int(seed),
                                            **library)
        calligraphy.plot.trial(result, ax=ax)
        ax.set_title(f"guidance {'on' if guidance else 'off'}: " + ax.get_title(), fontsize=9,
                     fontproperties=calligraphy.plot.cjk_font())
    for ax, metric, unit, scale in zip(axes[1], METRICS, ("mm", "s"), (1e3, 1.0)):
        values = diffs[metric] * scale  # shown in mm for people
        ax.hist(values, bins=40, color="tab:blue")
        ax.axvline(0.0, color="black", lw=0.8)
        ax.set_xlabel(f"{metric} off - on [{unit}]")
        ax.set_ylabel("trials")
        ax.set_title(f"{len(values)} trials: {(values > 0).mean():.1%} lower with guidance, "
                     f"{(values == 0).mean():.1%} equal", fontsize=9)
    fig.tight_layout()
    path = os.path.join(folder, "corpus_sweep.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")


# %% [markdown]
# # Main

# %%
def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    source = parser.add_mutually_exclusive_group()
    source.add_argument("--data", help="hanzi-writer-data folder (default: the embedded set)")
    source.add_argument("--store", help="corpus store made by `calligraphy corpus build`")
    parser.add_argument("--every", type=int, default=1, help="keep every K-th character (default 1: all)")
    parser.add_argument("--limit", type=int, default=0, help="at most N characters (default: no limit)")
    parser.add_argument("--seeds", type=int, default=1, help="seeds per character and guidance (default 1)")
    parser.add_argument("--writer", choices=("novice", "skilled", "foreign"), default="novice")
    parser.add_argument("--workers", type=int, default=None, help="local processes (default: every core)")
    parser.add_argument("--scheduler", help="address of a Dask scheduler to run on instead (tcp://host:8786)")
    parser.add_argument("--out", default="corpus_sweep_out", help="folder for the table and the figure")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    for name in ("every", "seeds"):
        if getattr(args, name) < 1:
            parser.error(f"--{name} must be at least 1")
    if args.limit < 0:
        parser.error("--limit must be at least 0")

    characters = choose_characters(args.store, args.data, args.every, args.limit)
    if not characters:
        parser.error("no characters chosen")
    print(f"{len(characters)} characters x guidance off/on x {args.seeds} seeds, writer {args.writer}")
    client = None
    if args.scheduler:
        import distributed

        client = distributed.Client(args.scheduler)
    try:
        table = run_sweep(characters, args, client)
    finally:
        if client is not None:
            client.close()
    os.makedirs(args.out, exist_ok=True)
    save_table(table, args.out)
    ran = summarise(table)
    draw_figure(differences(ran), args, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
