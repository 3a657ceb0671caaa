"""Ctrl-C during a long simulate_trial raises KeyboardInterrupt promptly, not after the trial."""
import os
import signal
import threading
import time

import pytest

import calligraphy


def test_sigint_interrupts_a_long_trial():
    # About 8 million servo ticks at 100 kHz: several seconds of work on this machine.
    def send_sigint():
        time.sleep(0.3)
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=send_sigint, daemon=True).start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        calligraphy.simulate_trial("永我九心马", rate_hz=100000.0, max_duration_s=100.0, keep_trace=False)
    elapsed = time.monotonic() - start
    # The runner polls every 50 ms; a generous bound keeps the test about behaviour, not speed.
    assert elapsed < 2.5


def test_a_trial_after_an_interrupt_runs_normally():
    result = calligraphy.simulate_trial("乙", seed=1)
    assert result.metrics["end_reason"] == "completed"
