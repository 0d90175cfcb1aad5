"""The scene-level result: everything `pinmech solve` reports for one scene."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from pinmech.solve.results import LoopSolution

if TYPE_CHECKING:
    from pinmech.io.scene import Scene
    from pinmech.io.scene_model import Drivers
    from pinmech.model.mechanism import Mechanism
    from pinmech.solve.forces import ForceSolution
    from pinmech.solve.motion import Motion


@dataclass(frozen=True)
class Analysis:
    """Everything `pinmech solve` reports for one scene."""

    scene: Scene
    mechanism: Mechanism
    drivers: Drivers
    solution: LoopSolution
    motion: Motion
    extra: dict[str, Any] | None = None
    forces: ForceSolution | None = None  # driver efforts and reactions, when the scene asks (forces.py)

    def _repr_html_(self) -> str:
        """Jupyter shows the points' and links' motion as tables."""
        import html

        from pinmech.io.html_tables import motion_table_html

        return f"<h4>{html.escape(self.scene.title)}</h4>" + motion_table_html(self.motion, self.mechanism.plane_normal)
