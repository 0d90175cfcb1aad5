"""pinmech.io: scene and hand files read into typed objects; results as text, JSON, tables."""
