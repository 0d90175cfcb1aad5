"""pinmech.solve.diagnostics: see the README's Layout."""
