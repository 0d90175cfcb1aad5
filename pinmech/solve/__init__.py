"""pinmech.solve: loops closed, rates, forces, sweeps and diagnostics, by the compiled core."""
