"""pinmech.design.synthesis: path, motion and function synthesis of linkages."""
