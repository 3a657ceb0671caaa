"""The window's pointer moved as a person moves a pen, for the trainer's tests: along a stroke's median as
the window shows it, with the minimum-jerk speed profile of a practised movement (Flash & Hogan,
J. Neurosci. 5:1688-1703, 1985), corners gone round on their inside, a slight wobble across the path, and
the pen lifted a little short of the stroke's end, never past it. Between strokes the pen travels in the
air, also minimum-jerk. Each movement is one xdotool command chain moving the pointer 60 times a second,
so that starting a process per move does not set the pace.

`pause_at_turns` writes each stretch between sharp turns as a minimum-jerk movement of its own, stopping
at the turn as a brush does at the turn of a 横折 (a pause, 顿笔) before going on: the pen then comes to
rest at the bottom of 永's hook, which on mouse-hand the guidance can hold there."""
import math
import random
import subprocess

MOVE_PERIOD_S = 1 / 60
CORNER_RADIUS_MM = 1.5  # how far before and after a corner the path leaves the median to go round it
WOBBLE_MM = 0.3         # amplitude of the sideways wobble
SHORT_OF_END_MM = (0.5, 1.5)
STROKE_SPEED_MM_S = 90.0  # mean speed of a movement (peak 1.9 times this, the minimum-jerk profile's)
TURN_DEGREES = 50         # a turn of the median sharper than this, over TURN_SPAN_MM either side, is a turn
TURN_SPAN_MM = 4.0


def minimum_jerk(tau):
    """The fraction of the way covered at the fraction `tau` of the time: zero speed and acceleration at
    both ends, so it never overshoots."""
    return tau ** 3 * (10 - 15 * tau + 6 * tau * tau)


def round_corners(points, radius):
    """The polyline with each inner vertex replaced by a quadratic Bezier from `radius` before it to
    `radius` after it (at most 0.45 of either segment), inside the corner."""
    out = [points[0]]
    for a, v, b in zip(points, points[1:], points[2:]):
        la, lb = math.dist(a, v), math.dist(v, b)
        if la == 0 or lb == 0:
            continue
        d = min(radius, 0.45 * la, 0.45 * lb)
        p0 = (v[0] + (a[0] - v[0]) * d / la, v[1] + (a[1] - v[1]) * d / la)
        p2 = (v[0] + (b[0] - v[0]) * d / lb, v[1] + (b[1] - v[1]) * d / lb)
        for k in range(9):
            t = k / 8
            out.append(tuple((1 - t) ** 2 * p0[i] + 2 * (1 - t) * t * v[i] + t * t * p2[i] for i in (0, 1)))
    out.append(points[-1])
    return out


class Path:
    """A polyline read by arc length."""

    def __init__(self, points):
        self.points = [p for i, p in enumerate(points) if i == 0 or math.dist(p, points[i - 1]) > 0]
        self.arc = [0.0]
        for a, b in zip(self.points, self.points[1:]):
            self.arc.append(self.arc[-1] + math.dist(a, b))
        self.length = self.arc[-1]

    def at(self, s):
        """The point at arc length `s` and the unit normal there."""
        s = min(max(s, 0.0), self.length)
        k = next((i for i in range(1, len(self.arc)) if self.arc[i] >= s), len(self.arc) - 1)
        a, b = self.points[k - 1], self.points[k]
        length = self.arc[k] - self.arc[k - 1]
        t = (s - self.arc[k - 1]) / length if length > 0 else 0.0
        tangent = ((b[0] - a[0]) / length, (b[1] - a[1]) / length) if length > 0 else (1.0, 0.0)
        return (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])), (-tangent[1], tangent[0])


def turns(path, span):
    """Arc lengths along `path` of its sharp turns: where the direction over `span` before a vertex and
    `span` after it differ by more than TURN_DEGREES, the sharpest vertex of each run of such vertices."""
    found = []
    for k in range(1, len(path.points) - 1):
        s = path.arc[k]
        if s < span or s > path.length - span:
            continue
        (before, _), (after, _) = path.at(s - span), path.at(s + span)
        v = path.points[k]
        a = (v[0] - before[0], v[1] - before[1])
        b = (after[0] - v[0], after[1] - v[1])
        cos = (a[0] * b[0] + a[1] * b[1]) / (math.hypot(*a) * math.hypot(*b))
        angle = math.degrees(math.acos(max(-1.0, min(1.0, cos))))
        if angle <= TURN_DEGREES:
            continue
        if found and s - found[-1][0] < 2 * span:
            if angle > found[-1][1]:
                found[-1] = (s, angle)
            continue
        found.append((s, angle))
    return [s for s, _ in found]


class Hand:
    """Writes strokes with the pointer in `window`. `px_per_mm`: the window's scale of the paper;
    `settle_s`: the pause over a stroke's start before the pen goes down, `press_s` after it (a device
    whose pen follows the pointer through a simulated hand needs a moment to get there)."""

    def __init__(self, window, px_per_mm, seed=1, settle_s=0.2, press_s=0.15, pause_at_turns=False):
        self.window, self.px_per_mm = window, px_per_mm
        self.random = random.Random(seed)
        self.settle_s, self.press_s = settle_s, press_s
        self.pause_at_turns = pause_at_turns
        self.position = None
        self.last_short_of_end_mm = None

    def _moves(self, points, duration_s):
        chain = []
        for x, y in points:
            chain += ["mousemove", "--window", self.window, str(round(x)), str(round(y)),
                      "sleep", "%.4f" % (duration_s / max(1, len(points)))]
        if points:
            self.position = points[-1]
        return chain

    def _travel(self, to):
        """Minimum-jerk through the air to `to` (nothing when already there)."""
        if self.position is None:
            return self._moves([to], 0.05)
        distance = math.dist(self.position, to)
        duration = 0.2 + 0.3 * min(1.0, distance / (40 * self.px_per_mm))
        steps = max(1, round(duration / MOVE_PERIOD_S))
        start = self.position
        return self._moves([tuple(start[i] + minimum_jerk(k / steps) * (to[i] - start[i]) for i in (0, 1))
                            for k in range(1, steps + 1)], duration)

    def stroke_samples(self, median_px):
        """The pointer positions of one stroke along `median_px` (window pixels, in writing order), one per
        move period, and how far short of the end the pen stops [mm]."""
        median = Path(median_px)
        path = Path(round_corners(median_px, CORNER_RADIUS_MM * self.px_per_mm))
        short_mm = self.random.uniform(*SHORT_OF_END_MM)
        travel = max(0.0, path.length - short_mm * self.px_per_mm)
        # One minimum-jerk movement, or one from each sharp turn to the next (the rounded path is shorter than
        # the median by a little at each turn: the turns are found on the median, placed in proportion).
        ends = [s * path.length / median.length for s in turns(median, TURN_SPAN_MM * self.px_per_mm)]
        ends = [0.0] + [s for s in ends if s < travel and self.pause_at_turns] + [travel]
        pace = self.random.uniform(0.9, 1.1)
        durations = [(0.08 + (b - a) / self.px_per_mm / STROKE_SPEED_MM_S) * pace for a, b in zip(ends, ends[1:])]
        duration = sum(durations)
        steps = max(2, round(duration / MOVE_PERIOD_S))

        def arc_at(t):
            for (a, b), d in zip(zip(ends, ends[1:]), durations):
                if t <= d:
                    return a + minimum_jerk(min(1.0, t / d)) * (b - a)
                t -= d
            return travel

        # A smooth sideways wobble: two sines of random phase, wavelengths of a few millimetres.
        phases = [self.random.uniform(0, 2 * math.pi) for _ in range(2)]
        wavelengths_px = [self.random.uniform(8, 14) * self.px_per_mm, self.random.uniform(3, 5) * self.px_per_mm]
        amplitude_px = WOBBLE_MM * self.px_per_mm

        def wobble(s):
            return amplitude_px * (0.65 * math.sin(2 * math.pi * s / wavelengths_px[0] + phases[0]) +
                                   0.35 * math.sin(2 * math.pi * s / wavelengths_px[1] + phases[1]))

        samples = []
        for k in range(steps + 1):
            s = arc_at(k / steps * duration)
            (x, y), (nx, ny) = path.at(s)
            w = wobble(s)
            samples.append((x + w * nx, y + w * ny))
        return samples, short_mm, duration

    def write(self, median_px):
        """Writes one stroke: through the air to its start, the pen down, along the stroke, the pen up.
        Returns how far short of the end it lifted [mm]."""
        samples, short_mm, duration = self.stroke_samples(median_px)
        chain = self._travel(samples[0])
        chain += ["sleep", str(self.settle_s), "mousedown", "1", "sleep", str(self.press_s)]
        chain += self._moves(samples[1:], duration)
        chain += ["sleep", "0.1", "mouseup", "1", "sleep", "0.15"]
        subprocess.run(["xdotool", *chain], check=True, capture_output=True, text=True)
        self.last_short_of_end_mm = short_mm
        return short_mm
