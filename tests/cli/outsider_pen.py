"""Pens written by hand for the rounds of hostile cases (test_unseen_round*.py): points along a stroke's median
and a trace file of ticks, the two things those rounds draw every trace from. NumPy only; the caller has
checked that it imports."""
import numpy as np


def along(median, offset=(0.0, 0.0), fraction=1.0, n=300):
    """`n` points equally spaced along a median [m], moved by `offset`, cut at `fraction` of its length."""
    m = np.asarray(median, dtype=float) + np.asarray(offset)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(m, axis=0), axis=1))])
    u = np.linspace(0.0, s[-1] * fraction, n)
    return np.column_stack([np.interp(u, s, m[:, 0]), np.interp(u, s, m[:, 1])])


def write_trace(path, ticks):
    """Ticks (t [s], x, y, z [m]) as the CSV `calligraphy score` reads: t in microseconds, x, y, z in 0.1 um."""
    with open(path, "w", encoding="utf-8") as f:
        f.write("t,x,y,z\n")
        for t, x, y, z in ticks:
            f.write(f"{t:.6f},{x:.7f},{y:.7f},{z:.7f}\n")
