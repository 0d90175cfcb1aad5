"""pinmech.solve: see docs/explanation/layout.md."""
