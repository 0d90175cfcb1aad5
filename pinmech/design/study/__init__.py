"""pinmech.design.study: sensitivity, tolerance and grid studies of named dimensions."""
