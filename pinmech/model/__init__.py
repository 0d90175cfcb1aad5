"""pinmech.model: model files (URDF, drawn TOML, MJCF, robot.yaml) read into one Mechanism."""
