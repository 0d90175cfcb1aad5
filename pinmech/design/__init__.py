"""pinmech.design: design studies and synthesis; see docs/explanation/layout.md."""
