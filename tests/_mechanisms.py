"""Small mechanisms written as URDF strings, for tests that need more than the bundled models."""

from __future__ import annotations

import re
from pathlib import Path

_LINK = '<link name="{name}"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>'


def _links(*names: str) -> str:
    return "\n".join(_LINK.format(name=n) for n in names)


def four_bar_urdf(a: float = 0.04, b: float = 0.12, c: float = 0.08, d: float = 0.10) -> str:
    """Planar four-bar: crank a at O2 = (0,0), coupler b, rocker c at O4 = (d,0); cut at B."""
    return f"""<?xml version="1.0"?>
<robot name="four_bar">
  <link name="ground"/>
  {_links("crank", "coupler", "rocker")}
  <joint name="O2" type="continuous"><parent link="ground"/><child link="crank"/><axis xyz="0 0 1"/></joint>
  <joint name="A" type="continuous"><parent link="crank"/><child link="coupler"/>
    <origin xyz="{a} 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="O4" type="continuous"><parent link="ground"/><child link="rocker"/>
    <origin xyz="{d} 0 0"/><axis xyz="0 0 1"/></joint>
  <constraint name="B" type="revolute">
    <parent link="coupler"/> <parent_origin xyz="{b} 0 0"/> <parent_axis xyz="0 0 1"/>
    <child link="rocker"/> <child_origin xyz="{c} 0 0"/> <child_axis xyz="0 0 1"/>
  </constraint>
  <link name="P"/>
  <joint name="point_P" type="fixed"><parent link="coupler"/><child link="P"/><origin xyz="{b / 2} 0.02 0"/></joint>
</robot>
"""


def slider_crank_prismatic_cut_urdf(r: float = 0.05, l: float = 0.15, e: float = 0.01) -> str:
    """Offset slider-crank cut at its slider: a planar prismatic cut (2 rows: offset and turn)."""
    return f"""<?xml version="1.0"?>
<robot name="slider_crank_cut_at_slider">
  <link name="ground"/>
  {_links("crank", "rod", "block")}
  <joint name="O" type="continuous"><parent link="ground"/><child link="crank"/><axis xyz="0 0 1"/></joint>
  <joint name="A" type="continuous"><parent link="crank"/><child link="rod"/>
    <origin xyz="{r} 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="B" type="continuous"><parent link="rod"/><child link="block"/>
    <origin xyz="{l} 0 0"/><axis xyz="0 0 1"/></joint>
  <constraint name="slide" type="prismatic">
    <parent link="ground"/> <parent_origin xyz="0 {e} 0"/> <parent_axis xyz="1 0 0"/>
    <child link="block"/> <child_origin xyz="0 0 0"/> <child_axis xyz="1 0 0"/>
  </constraint>
</robot>
"""


def spatial_rsur_urdf() -> str:
    """A spatial RSUR loop: crank about z, universal joint, rocker about x, spherical cut.

    Joint freedoms 1 + 2 + 1 = 4, a spherical cut removes 3: mobility 1, spatial.
    """
    return f"""<?xml version="1.0"?>
<robot name="rsur">
  <link name="ground"/>
  {_links("crank", "u_cross", "coupler", "rocker")}
  <joint name="R1" type="revolute"><parent link="ground"/><child link="crank"/>
    <axis xyz="0 0 1"/><limit lower="-10" upper="10" effort="1" velocity="1"/></joint>
  <joint name="U1" type="revolute"><parent link="crank"/><child link="u_cross"/>
    <origin xyz="0.05 0 0"/><axis xyz="0 0 1"/><limit lower="-10" upper="10" effort="1" velocity="1"/></joint>
  <joint name="U2" type="revolute"><parent link="u_cross"/><child link="coupler"/>
    <axis xyz="0 1 0"/><limit lower="-10" upper="10" effort="1" velocity="1"/></joint>
  <joint name="R4" type="revolute"><parent link="ground"/><child link="rocker"/>
    <origin xyz="0.10 0.12 0.03"/><axis xyz="1 0 0"/><limit lower="-10" upper="10" effort="1" velocity="1"/></joint>
  <constraint name="S" type="spherical">
    <parent link="coupler"/> <parent_origin xyz="0.15 0 0"/>
    <child link="rocker"/> <child_origin xyz="0 0 0.08"/>
  </constraint>
</robot>
"""


def spatial_rsur_revolute_cut_urdf() -> str:
    """The same RSUR loop cut at the rocker's pivot instead (a revolute cut: 5 rows).

    The spherical joint is three revolute joints in the tree: 1 + 2 + 3 = 6 freedoms,
    minus 5 rows: mobility 1. Its angular rows exercise the revolute cut's axis rows.
    """
    limit = '<limit lower="-10" upper="10" effort="1" velocity="1"/>'
    return f"""<?xml version="1.0"?>
<robot name="rsur_cut_at_R4">
  <link name="ground"/>
  {_links("crank", "u_cross", "coupler", "s1", "s2", "rocker")}
  <joint name="R1" type="revolute"><parent link="ground"/><child link="crank"/>
    <axis xyz="0 0 1"/>{limit}</joint>
  <joint name="U1" type="revolute"><parent link="crank"/><child link="u_cross"/>
    <origin xyz="0.05 0 0"/><axis xyz="0 0 1"/>{limit}</joint>
  <joint name="U2" type="revolute"><parent link="u_cross"/><child link="coupler"/>
    <axis xyz="0 1 0"/>{limit}</joint>
  <joint name="Sx" type="revolute"><parent link="coupler"/><child link="s1"/>
    <origin xyz="0.15 0 0"/><axis xyz="1 0 0"/>{limit}</joint>
  <joint name="Sy" type="revolute"><parent link="s1"/><child link="s2"/><axis xyz="0 1 0"/>{limit}</joint>
  <joint name="Sz" type="revolute"><parent link="s2"/><child link="rocker"/><axis xyz="0 0 1"/>{limit}</joint>
  <constraint name="R4" type="revolute">
    <parent link="ground"/> <parent_origin xyz="0.10 0.12 0.03"/> <parent_axis xyz="1 0 0"/>
    <child link="rocker"/> <child_origin xyz="0 0 -0.08"/> <child_axis xyz="1 0 0"/>
  </constraint>
</robot>
"""


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def scaled_urdf(text: str, k: float) -> str:
    """Every length of a URDF times k: origins, box sizes, radii, lengths, prismatic limits
    (xyz, size, radius, length, lower, upper). Angles (rpy), axes (`<axis>`, `<parent_axis>`,
    `<child_axis>`: directions), masses and inertias keep their numbers.
    """
    def scale_numbers(match: re.Match) -> str:
        numbers = " ".join(f"{float(x) * k!r}" for x in match.group(2).split())
        return f'{match.group(1)}="{numbers}"'

    def scale_tag(match: re.Match) -> str:
        if match.group(1).endswith("axis"):
            return match.group(0)
        return re.sub(r'\b(xyz|size|radius|length|lower|upper)="([^"]*)"', scale_numbers, match.group(0))

    return re.sub(r"<(\w+)\b[^>]*>", scale_tag, text)


def stephenson_six_bar_urdf(a: float = 0.04, b: float = 0.12, c: float = 0.08, d: float = 0.10,
                            cx: float = 0.06, cy: float = 0.04, b2: float = 0.10, c2: float = 0.09,
                            o6: tuple[float, float] = (0.16, 0.10)) -> str:
    """Stephenson III six-bar: the four-bar O2-A-B-O4 (cut at B), its coupler a ternary link
    carrying the pin C at (cx, cy) in the coupler's frame, and a dyad C-D-O6 to the ground
    pivot O6 (link5 from C, link6 from O6, cut at D). Two loops, driven at the crank O2."""
    return f"""<?xml version="1.0"?>
<robot name="stephenson_six_bar">
  <link name="ground"/>
  {_links("crank", "coupler", "rocker", "link5", "link6")}
  <joint name="O2" type="continuous"><parent link="ground"/><child link="crank"/><axis xyz="0 0 1"/></joint>
  <joint name="A" type="continuous"><parent link="crank"/><child link="coupler"/>
    <origin xyz="{a} 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="O4" type="continuous"><parent link="ground"/><child link="rocker"/>
    <origin xyz="{d} 0 0"/><axis xyz="0 0 1"/></joint>
  <joint name="C" type="continuous"><parent link="coupler"/><child link="link5"/>
    <origin xyz="{cx} {cy} 0"/><axis xyz="0 0 1"/></joint>
  <joint name="O6" type="continuous"><parent link="ground"/><child link="link6"/>
    <origin xyz="{o6[0]} {o6[1]} 0"/><axis xyz="0 0 1"/></joint>
  <constraint name="B" type="revolute">
    <parent link="coupler"/> <parent_origin xyz="{b} 0 0"/> <parent_axis xyz="0 0 1"/>
    <child link="rocker"/> <child_origin xyz="{c} 0 0"/> <child_axis xyz="0 0 1"/>
  </constraint>
  <constraint name="D" type="revolute">
    <parent link="link5"/> <parent_origin xyz="{b2} 0 0"/> <parent_axis xyz="0 0 1"/>
    <child link="link6"/> <child_origin xyz="{c2} 0 0"/> <child_axis xyz="0 0 1"/>
  </constraint>
  <link name="D_pin"/>
  <joint name="point_D" type="fixed"><parent link="link5"/><child link="D_pin"/><origin xyz="{b2} 0 0"/></joint>
</robot>
"""


def cut_rows(model, data, closure, selected: bool = False):
    """A cut's closure rows from Pinocchio's frame placements in `data` (textbook, apart
    from the core): the pose error [R_P^T (p_C - p_P); a_P x R a_C (revolute), log3 R
    (prismatic, fixed), 0 (spherical)], R = R_P^T R_C, through the cut's row map (its
    independent rows, or with `selected` every selected row)."""
    import numpy as np
    import pinocchio as pin

    M_P, M_C = data.oMf[closure.parent_frame], data.oMf[closure.child_frame]
    R = M_P.rotation.T @ M_C.rotation
    angular = {"revolute": lambda: np.cross(closure.axis, R @ closure.child_axis),
               "spherical": lambda: np.zeros(3)}.get(closure.cut_type, lambda: pin.log3(R))()
    error6 = np.concatenate((M_P.rotation.T @ (M_C.translation - M_P.translation), angular))
    return (closure.selected_rows6 if selected else closure.rows6) @ error6
