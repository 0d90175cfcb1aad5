"""pinmech.model: see docs/explanation/layout.md."""
