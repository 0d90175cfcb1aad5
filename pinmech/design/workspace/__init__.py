"""pinmech.design.workspace: workspace maps of parallel mechanisms (task and motor space)."""
