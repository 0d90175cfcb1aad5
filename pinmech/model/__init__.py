"""pinmech.model: see the README's Layout."""
