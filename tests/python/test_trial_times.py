"""A trial's times are exact to the tick: n ticks at 1 kHz read n ms, in the trace and in the metrics, and
print as such (13.073, not 13.072999999980317)."""

import numpy as np
import pytest

import calligraphy


@pytest.mark.parametrize("rate_hz", [1000.0, 4000.0])
def test_a_trials_times_are_whole_ticks(rate_hz):
    result = calligraphy.simulate_trial("十", seed=1, rate_hz=rate_hz)
    ticks = len(result.time_s)
    assert ticks > 1000
    # The simulated device's clock counts whole ticks: tick k is at k / rate_hz, as a division gives it.
    assert np.array_equal(result.time_s, np.arange(ticks) / rate_hz)
    m = result.metrics
    assert repr(m["trial_time_s"]) == repr((ticks - 1) / rate_hz)
    for key in ("total_time_s", "pen_down_time_s"):
        ticks_in = round(m[key] * rate_hz)
        assert ticks_in > 0, key
        # The duration is a whole number of ticks, and prints as one: no rounding noise of the differences.
        assert m[key] == ticks_in / rate_hz, key
        assert len(repr(m[key])) <= 7, (key, m[key])  # e.g. 6.28575 at 4 kHz, 6.282 at 1 kHz
