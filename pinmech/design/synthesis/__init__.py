"""pinmech.design.synthesis: see docs/explanation/layout.md."""
