"""pinmech.solve: see the README's Layout."""
