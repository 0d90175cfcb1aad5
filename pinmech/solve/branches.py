"""Assembly modes: the signature that names the branch a closed pose is on.

A mechanism with its drivers held has, in general, several assemblies (a four-bar's two,
a Stephenson six-bar's up to six): isolated solutions of the closure equations. A pose's
**assembly signature** is, per irreducible block of the dependent-joint constraint
Jacobian J_dep, the sign of that block's determinant:

* J_dep (closure rows x dependent joints, rows and columns in a fixed order) is put in
  block-triangular form from its structure (which joints each loop's rows involve): a
  row-to-column matching, then the strongly connected components of the resulting graph
  (Dulmage-Mendelsohn). A Watt six-bar driven at its crank gives two 2x2 blocks (one per
  dyad); a four-bar one.
* det J_dep is the product of the blocks' determinants, so along a motion on which J_dep
  stays regular no block determinant crosses zero: every sign is kept. Two assemblies of
  a block are separated by poses where its determinant vanishes (a dead centre, a fold):
  going from one to the other without passing such a pose is impossible, and passing one
  is what `continuation.py` watches for.
* One sign per block tells apart the two assemblies of a dyad; a block of more loops
  solved together (a Stephenson six-bar driven from a link of its four-bar loop) has more
  assemblies than two signs can name. There, continuation's trust region (the corrector
  stays close to the predicted pose) is what keeps the branch; the sign still catches
  every passage through a singular pose.

For a planar RRR dyad (a block of one revolute cut, two rows, and two dependent revolute
joints) the sign has a plain reading, which reports print: the cut pin is to the left or
right of the line from the dyad's first joint to its second, seen from the plane normal
(for the bundled four-bar, "B left of A->O4" is its open assembly).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

#: Signs a scene may ask for (`assembly` values), as +1 / -1: the signs reports print.
SIGN_WORDS = {"+": 1, "-": -1}


@dataclass(frozen=True)
class Block:
    """One irreducible block of J_dep: its rows and dependent-joint columns (indices into
    J_dep), the loops (cut names) its rows come from, and for a planar RRR dyad the three
    pins that label its sign (first joint, cut, second joint)."""

    rows: tuple[int, ...]
    cols: tuple[int, ...]
    loops: tuple[str, ...]
    dyad: tuple[int, int, int] | None = None  # (joint id, closure index, joint id)

    @property
    def name(self) -> str:
        return "+".join(self.loops)


@dataclass(frozen=True)
class Assembly:
    """The assembly a pose is on: one sign per block, with readable labels.

    Attributes:
        names: the blocks' names (their loops' cut names, "B" or "B+E").
        signs: +1 or -1 per block (the sign of its determinant; 0 at a singular pose).
        labels: per block, a plain reading ("B left of A->O4") or the sign ("+").
    """

    names: tuple[str, ...]
    signs: tuple[int, ...]
    labels: tuple[str, ...]

    def as_dict(self) -> dict[str, dict[str, object]]:
        return {n: {"sign": s, "label": lab} for n, s, lab in zip(self.names, self.signs, self.labels)}

    def describe(self) -> str:
        return ", ".join(f"{n}: {lab} ({_sign_word(s)})" if lab != _sign_word(s) else f"{n}: {lab}"
                         for n, s, lab in zip(self.names, self.signs, self.labels)) or "no loops"

    def pin_hint(self) -> str:
        """The scene line that pins this assembly."""
        return "assembly = { " + ", ".join(f'"{n}" = "{_sign_word(s)}"' for n, s in zip(self.names, self.signs)) + " }"


class AssemblyStructure:
    """The block structure of a mechanism's J_dep for a given set of drivers (fixed once).

    Args:
        model: the Pinocchio model.
        closures: the mechanism's closures (their frames and row counts, in J order).
        dep_v: velocity indices of the dependent joints (J_dep's columns, in order).
        plane_normal: the motion plane's unit normal for a planar mechanism, else None.
    """

    def __init__(self, model: pin.Model, closures: list, dep_v: np.ndarray,
                 plane_normal: np.ndarray | None) -> None:
        self.model = model
        pattern, row_cut = _pattern(model, closures, dep_v)
        self.blocks: tuple[Block, ...] = tuple(
            _block(rows, cols, closures, row_cut, model, dep_v, plane_normal)
            for rows, cols in _triangular_blocks(pattern)
        )
        self.names = tuple(b.name for b in self.blocks)
        self.plane_normal = plane_normal
        self._closures = closures
        self._col_nv = [model.joints[_joint_of_v(model, int(v))].nv for v in dep_v]
        n = len(dep_v)
        whole = len(self.blocks) == 1 and len(self.blocks[0].rows) == n
        self._index = None if whole else [np.ix_(b.rows, b.cols) for b in self.blocks]

    @property
    def signs_name_every_assembly(self) -> bool:
        """Whether the signature tells every assembly apart: a planar mechanism whose
        blocks are each one loop in two one-freedom joints (a dyad, RRR, RRP, RPR...: at
        most two assemblies, a circle or a line meeting a circle). Elsewhere a pose from a
        guess is checked against continuation (assembly_check.py)."""
        if self.plane_normal is None:
            return False
        return all(len(b.loops) == 1 and len(b.rows) == len(b.cols) == 2 and all(self._col_nv[c] == 1 for c in b.cols)
                   for b in self.blocks)

    def signs(self, J_dep: np.ndarray) -> tuple[int, ...]:
        """The sign of each block's determinant (J_dep: dependent columns, any positive
        column scaling)."""
        if self._index is None:
            d = _det(J_dep)
            return (1 if d > 0 else -1 if d < 0 else 0,) if self.blocks else ()
        return tuple(int(np.sign(_det(J_dep[ix]))) for ix in self._index)

    def signs_many(self, J_dep: np.ndarray) -> np.ndarray:
        """(N, blocks) signs for a stack (N, rows, cols) of J_dep."""
        out = np.empty((len(J_dep), len(self.blocks)), dtype=int)
        for k, b in enumerate(self.blocks):
            out[:, k] = np.sign(np.linalg.det(J_dep[:, b.rows][:, :, b.cols]))
        return out

    def assembly(self, signs: tuple[int, ...], data: pin.Data | None = None) -> Assembly:
        """Signs with their labels; `data` holding joint and cut-frame placements at the pose
        adds the dyads' left/right reading."""
        labels = []
        for b, s in zip(self.blocks, signs):
            labels.append(self._dyad_label(b, data) if b.dyad is not None and data is not None else _sign_word(s))
        return Assembly(self.names, tuple(signs), tuple(labels))

    def change(self, reference: tuple[int, ...], signs: tuple[int, ...], data: pin.Data | None = None,
               whose: str = "the reference's") -> str:
        """In words, a pose's assembly `signs` that differs from `reference`: which loops
        changed, and both assemblies as reports print them (`data`: at the pose)."""
        changed = [n for n, s, r in zip(self.names, signs, reference) if s != r] or list(self.names)
        found, expected = self.assembly(signs, data).describe(), self.assembly(reference).describe()
        return (f"the other assembly of loop{'s' if len(changed) > 1 else ''} {', '.join(changed)} "
                f"({found}; {whose} is {expected})")

    def _dyad_label(self, b: Block, data: pin.Data) -> str:
        j1, k, j2 = b.dyad
        cut = self._closures[k]
        p1, p2 = data.oMi[j1].translation, data.oMi[j2].translation
        frame = self.model.frames[cut.parent_frame]
        pc = (data.oMi[frame.parentJoint] * frame.placement).translation
        side = float(self.plane_normal @ np.cross(p2 - p1, pc - p1))
        word = "left of" if side > 0 else "right of" if side < 0 else "on"
        names = self.model.names
        return f"{cut.name} {word} {names[j1]}->{names[j2]}"


def parse_assembly(asked: object, structure: AssemblyStructure) -> dict[str, int] | None:
    """A scene's `assembly` value: "any" (None: no check), or a table block name -> sign
    word ("+", "-", "left", "right"). Raises ValueError with a one-line reason."""
    if asked == "any":
        return None
    if not isinstance(asked, dict):
        raise ValueError(f'must be "any" or a table of loop = "+"/"-" (loops: {", ".join(structure.names)})')  # noqa: TRY004 (one-line reason for the scene error)
    out = {}
    for written, word in asked.items():
        name = _block_name(written, structure.names)
        if name not in structure.names:
            raise ValueError(f"names no loop block '{name}' (blocks: {', '.join(structure.names) or 'none'})")
        if not isinstance(word, str) or word not in SIGN_WORDS:
            raise ValueError(f"{name} = {word!r}: use one of {', '.join(map(repr, SIGN_WORDS))}")
        out[name] = SIGN_WORDS[word]
    return out


def _block_name(written: str, names: tuple[str, ...]) -> str:
    """A block's name as a scene writes it: a hyphen may stand for the en dash of a loop
    named by two frames ("closedloop1_A-closedloop1_B", robot.yaml)."""
    if written in names:
        return written
    dashed = written.replace("-", "\u2013")
    return dashed if dashed in names else written


def _sign_word(s: int) -> str:
    return "+" if s > 0 else "-" if s < 0 else "0 (singular)"


def _det(A: np.ndarray) -> float:
    n = A.shape[0]
    if n == 1:
        return float(A[0, 0])
    if n == 2:
        return float(A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0])
    return float(np.linalg.det(A))


def _loop_joints(model: pin.Model, closure) -> set[int]:
    """Joint ids on the loop of a cut: in the support of exactly one of its two frames."""
    a = set(model.supports[model.frames[closure.parent_frame].parentJoint])
    b = set(model.supports[model.frames[closure.child_frame].parentJoint])
    return (a ^ b) - {0}


def _pattern(model: pin.Model, closures: list, dep_v: np.ndarray) -> tuple[np.ndarray, list[int]]:
    """Structural pattern of J_dep (rows x dependent columns) and each row's closure index."""
    col_of_v = {int(v): c for c, v in enumerate(dep_v)}
    rows, row_cut = [], []
    for k, closure in enumerate(closures):
        cols = set()
        for jid in _loop_joints(model, closure):
            joint = model.joints[jid]
            cols |= {col_of_v[v] for v in range(joint.idx_v, joint.idx_v + joint.nv) if v in col_of_v}
        for _ in range(closure.rows):
            row = np.zeros(len(dep_v), dtype=bool)
            row[list(cols)] = True
            rows.append(row)
            row_cut.append(k)
    return (np.array(rows).reshape(len(rows), len(dep_v)), row_cut)


def _triangular_blocks(pattern: np.ndarray) -> list[tuple[tuple[int, ...], tuple[int, ...]]]:
    """Irreducible diagonal blocks (rows, cols) of a square structural pattern: a maximum
    matching, then strongly connected components. Without a perfect matching (a
    structurally singular J_dep) the whole matrix is one block."""
    n = pattern.shape[0]
    if n == 0:
        return []
    match_col = _matching(pattern)
    if n != pattern.shape[1] or -1 in match_col:
        return [(tuple(range(n)), tuple(range(pattern.shape[1])))]
    row_of_col = {c: r for r, c in enumerate(match_col)}
    # row r depends on row s when r has an entry in the column matched to s
    graph = [[row_of_col[c] for c in np.flatnonzero(pattern[r]) if row_of_col[c] != r] for r in range(n)]
    blocks = []
    for comp in _strong_components(graph):
        rows = tuple(sorted(comp))
        blocks.append((rows, tuple(sorted(match_col[r] for r in rows))))
    return sorted(blocks, key=lambda b: b[0][0])


def _matching(pattern: np.ndarray) -> list[int]:
    """Row -> matched column (-1 where none), by augmenting paths (Kuhn)."""
    n_rows, n_cols = pattern.shape
    owner = [-1] * n_cols

    def augment(r: int, seen: set[int]) -> bool:
        for c in np.flatnonzero(pattern[r]).tolist():
            if c not in seen:
                seen.add(c)
                if owner[c] == -1 or augment(owner[c], seen):
                    owner[c] = r
                    return True
        return False

    for r in range(n_rows):
        augment(r, set())
    match = [-1] * n_rows
    for c, r in enumerate(owner):
        if r != -1:
            match[r] = c
    return match


def _strong_components(graph: list[list[int]]) -> list[list[int]]:
    """Tarjan's strongly connected components of a small directed graph."""
    index, low, on_stack, stack, out = {}, {}, set(), [], []
    counter = [0]

    def visit(v: int) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            out.append(comp)

    for v in range(len(graph)):
        if v not in index:
            visit(v)
    return out


def _block(rows, cols, closures, row_cut, model, dep_v, plane_normal) -> Block:
    """A block with its loops' names, and its labelling pins if it is a planar RRR dyad."""
    cuts = sorted({row_cut[r] for r in rows})
    loops = tuple(closures[k].name for k in cuts)
    dyad = None
    if plane_normal is not None and len(rows) == len(cols) == 2 and len(cuts) == 1 \
            and closures[cuts[0]].cut_type == "revolute":
        jids = [_joint_of_v(model, int(dep_v[c])) for c in cols]
        if all(_is_revolute(model.joints[j]) for j in jids) and jids[0] != jids[1]:
            first, second = sorted(jids)
            dyad = (first, cuts[0], second)
    return Block(tuple(rows), tuple(cols), loops, dyad)


def _joint_of_v(model: pin.Model, v: int) -> int:
    """The joint id owning velocity index v."""
    for jid in range(1, model.njoints):
        j = model.joints[jid]
        if j.idx_v <= v < j.idx_v + j.nv:
            return jid
    raise IndexError(v)


def _is_revolute(joint: pin.JointModel) -> bool:
    """One rotation about a fixed axis (revolute, continuous, or unaligned variants)."""
    return joint.nv == 1 and joint.shortname().startswith("JointModelR")
