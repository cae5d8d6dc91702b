"""Functions of a height value that Layers from Material follows from a Bump or Displacement
node's Height back to its Image Texture, composed into one: the layer's scale, or its "remap".

No bpy here. A function is one of two kinds:
- ("affine", a, b): a v + b, unbounded (Math and Map Range without clamp, Invert);
- ("points", [(x, y), ...]): the scene's "remap" (docs/baker.md): piecewise linear through
  the points, x non-decreasing, constant beyond the first and the last point; two points of
  one x make a step, continuous from the right (the second's y at that x).
A clamp or a Color Ramp is bounded, so any chain holding one is a "points" function.

libsgbake has no call that composes remaps, so the composition is done here, exactly (no
sampling): the points of F(S(v)) are those of S and each place where S crosses a point of F.
"""

import bisect
import math

IDENTITY = ("affine", 1.0, 0.0)
# libsgbake's limits on a remap (kMaxRemapPoints).
MAX_POINTS = 65536
# Cycles tabulates a Color Ramp at this many evenly spaced values of [0, 1].
RAMP_TABLE_SIZE = 256


def clamp(low, high):
    """clamp(v, low, high) for low <= high (low == high: the constant low)."""
    return ("points", [(low, low), (high, high)])


def table(values, constant):
    """A Color Ramp as Cycles reads its table `values` (ramp(i / (n - 1)), i = 0 .. n - 1) at
    v: clamped to [0, 1], scaled to f = v (n - 1), read at i = floor(f), linearly towards entry
    i + 1, or (`constant`, the ramp's Constant interpolation) entry i alone: a step at every
    entry, the last entry's value at 1 only."""
    last = len(values) - 1
    if not constant:
        return ("points", [(i / last, float(y)) for i, y in enumerate(values)])
    points = [(0.0, float(values[0]))]
    for i in range(1, last + 1):
        if values[i] != values[i - 1]:
            points += [(i / last, float(values[i - 1])), (i / last, float(values[i]))]
    if len(points) == 1:
        points.append((1.0, points[0][1]))
    return ("points", points)


def curve(values, low, high, reach=1.0e4):
    """A Float Curve as Cycles reads its table `values` (the curve at low + i / (n - 1) (high -
    low), i = 0 .. n - 1; low and high its points' least and greatest x) at v: linearly between
    entries inside [low, high], and beyond it along its first or last segment (Cycles
    extrapolates): here to `reach` times the table's span beyond each end (a remap is constant
    past its last point)."""
    last = len(values) - 1
    span = high - low
    points = [(low + i / last * span, float(y)) for i, y in enumerate(values)]
    first_slope = (values[1] - values[0]) / (span / last)
    last_slope = (values[last] - values[last - 1]) / (span / last)
    return ("points", [(low - reach * span, values[0] - first_slope * reach * span)] + points
            + [(high + reach * span, values[last] + last_slope * reach * span)])


def compose(outer, inner):
    """outer(inner(v)) as a function of the kinds above."""
    if outer[0] == "affine":
        a, b = outer[1], outer[2]
        if inner[0] == "affine":
            return ("affine", a * inner[1], a * inner[2] + b)
        return ("points", [(x, a * y + b) for x, y in inner[1]])
    points = outer[1]
    if inner[0] == "affine":
        a, b = inner[1], inner[2]
        if a == 0.0:  # a constant height: outer's value at b
            level = _Pieces(points).right(b)
            return ("points", [(0.0, level), (1.0, level)])
        # v = (x - b) / a; a negative factor reverses the order, and a step's two points with
        # it, so that the value right of the step stays the second's.
        moved = [((x - b) / a, y) for x, y in points]
        return ("points", _tidy(moved if a > 0 else moved[::-1]))
    return ("points", _tidy(_composed(_Pieces(points), _Pieces(inner[1]))))


def is_constant(function):
    """Whether `function` (a "points" one) takes one value everywhere."""
    return function[0] == "points" and len({y for _, y in function[1]}) == 1


def value(points, v):
    """The remap through `points` at v (continuous from the right at a step)."""
    return _Pieces(points).right(v)


class _Pieces:
    """A "points" function with its sorted x."""

    def __init__(self, points):
        self.points = points
        self.xs = [x for x, _ in points]

    def line(self, v):
        """The piece of the function at v and right of it, as a function of the whole line:
        beyond the ends, the end's constant."""
        j = bisect.bisect_right(self.xs, v) - 1
        if j < 0 or j >= len(self.points) - 1:
            level = self.points[0 if j < 0 else -1][1]
            return lambda u: level
        (x0, y0), (x1, y1) = self.points[j], self.points[j + 1]
        slope = (y1 - y0) / (x1 - x0)
        return lambda u: y0 + (u - x0) * slope

    def right(self, v):
        """The value at v (continuous from the right)."""
        return self.line(v)(v)


def _composed(outer, inner):
    """The points of outer(inner(v)): at inner's points and where inner, on a sloped segment,
    crosses one of outer's x. Between two of those places inner is linear and stays within one
    piece of outer, so the composition is linear there: the piece is found at the middle, and
    the two lines composed give the values at both ends (so rounding in where a crossing is
    cannot move a step). Each place gets the value coming from the left and, when it differs,
    the one going on to the right; beyond them inner, hence the composition, is constant.
    (Where inner falls onto a step of outer from above, as v grows, the composition is not
    continuous from the right at that one v: the remap takes the value right of it.)"""
    places = set(inner.xs)
    marks = sorted(set(outer.xs))
    for (x0, y0), (x1, y1) in zip(inner.points, inner.points[1:]):
        if x1 == x0 or y1 == y0:
            continue
        low, high = min(y0, y1), max(y0, y1)
        for u in marks[bisect.bisect_right(marks, low):bisect.bisect_left(marks, high)]:
            places.add(min(max(x0 + (u - y0) * (x1 - x0) / (y1 - y0), x0), x1))
    places = sorted(places)
    ends = []  # (value at the left end, value at the right end) of each gap between places
    for a, b in zip(places, places[1:]):
        middle = inner.line(0.5 * (a + b))
        piece = outer.line(middle(0.5 * (a + b)))
        ends.append((piece(middle(a)), piece(middle(b))))
    first = outer.right(inner.points[0][1])
    last = outer.right(inner.points[-1][1])
    points = []
    for k, x in enumerate(places):
        before = ends[k - 1][1] if k > 0 else first
        after = ends[k][0] if k < len(ends) else last
        points.append((x, before))
        if after != before:
            points.append((x, after))
    return points


def _tidy(points):
    """`points` with at most two of one x (the first and the last: rounding can bring
    neighbours together) and without the middle of three of one value."""
    kept = []
    for x, y in points:
        if len(kept) >= 2 and kept[-1][0] == x and kept[-2][0] == x:
            kept[-1] = (x, y)
        else:
            kept.append((x, y))
    flat = []
    for i, (x, y) in enumerate(kept):
        if (0 < i < len(kept) - 1 and kept[i - 1][1] == y == kept[i + 1][1]):
            continue
        if flat and flat[-1] == (x, y):
            continue
        flat.append((x, y))
    if len(flat) == 1:
        flat.append((flat[0][0] + 1.0, flat[0][1]))
    return flat


def finite(function):
    """Whether every number of `function` is finite."""
    if function[0] == "affine":
        return math.isfinite(function[1]) and math.isfinite(function[2])
    return all(math.isfinite(x) and math.isfinite(y) for x, y in function[1])
