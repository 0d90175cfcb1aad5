"""Barker's classification of a four-bar (Barker 1985; Norton, Design of Machinery, table
2-4): fourteen types named by the Grashof condition and by which link is the shortest
(classes I and III) or the longest (class II), links numbered from the ground: 1 ground,
2 input, 3 coupler, 4 output.

    class I   (s + l < p + q): I-1 GCCC, I-2 GCRR, I-3 GRCR, I-4 GRRC  (shortest link 1..4)
    class II  (s + l > p + q): II-1 RRR1 .. II-4 RRR4                  (longest link 1..4)
    class III (s + l = p + q): III-1 SCCC, III-2 SCRR, III-3 SRCR, III-4 SRRC (shortest 1..4),
                               III-5 S2X (two equal pairs), III-6 S3X (all four equal)

The letters read input, coupler, output: C a link that turns fully, R one that rocks
(G Grashof, S special Grashof, i.e. a change point, X a crossover).
"""

from __future__ import annotations

from dataclasses import dataclass

#: Two lengths closer than this share of the four's sum are equal (as grashof.EQUAL).
EQUAL = 1e-9

_CODES = {
    ("I", 1): "GCCC", ("I", 2): "GCRR", ("I", 3): "GRCR", ("I", 4): "GRRC",
    ("II", 1): "RRR1", ("II", 2): "RRR2", ("II", 3): "RRR3", ("II", 4): "RRR4",
    ("III", 1): "SCCC", ("III", 2): "SCRR", ("III", 3): "SRCR", ("III", 4): "SRRC",
    ("III", 5): "S2X", ("III", 6): "S3X",
}


@dataclass(frozen=True)
class BarkerClass:
    """A four-bar's Barker type: `name` as "I-2", `code` as "GCRR"."""

    group: str
    case: int
    code: str

    @property
    def name(self) -> str:
        return f"{self.group}-{self.case}"


def barker_class(ground: float, input_: float, coupler: float, output: float) -> BarkerClass:
    """The Barker type of a four-bar of these link lengths [m] (any common unit).

    Raises:
        ValueError: a length that is not positive.
    """
    r = [ground, input_, coupler, output]
    if min(r) <= 0:
        raise ValueError(f"a four-bar's lengths must be positive, got {r}")
    tol = EQUAL * sum(r)
    s, l = min(r), max(r)
    p_q = sum(r) - s - l
    if abs(s + l - p_q) <= tol:
        return BarkerClass("III", _special_case(r, s, tol), _CODES["III", _special_case(r, s, tol)])
    if s + l < p_q:
        case = 1 + next(i for i, x in enumerate(r) if abs(x - s) <= tol)
        return BarkerClass("I", case, _CODES["I", case])
    case = 1 + next(i for i, x in enumerate(r) if abs(x - l) <= tol)
    return BarkerClass("II", case, _CODES["II", case])


def _special_case(r: list[float], s: float, tol: float) -> int:
    """Class III's case: 6 all equal, 5 two equal pairs, else 1..4 by the shortest link."""
    if max(r) - min(r) <= tol:
        return 6
    a, b, c, d = sorted(r)
    if abs(a - b) <= tol and abs(c - d) <= tol:
        return 5
    return 1 + next(i for i, x in enumerate(r) if abs(x - s) <= tol)
