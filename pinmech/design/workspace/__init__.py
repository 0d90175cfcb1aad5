"""pinmech.design.workspace.run: see docs/explanation/layout.md."""
