"""pinmech.design: studies, synthesis and workspace maps, and what they share."""
