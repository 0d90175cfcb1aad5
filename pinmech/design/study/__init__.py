"""pinmech.design.study.run: see docs/explanation/layout.md."""
