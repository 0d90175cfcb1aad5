"""pinmech.io: see docs/explanation/layout.md."""
