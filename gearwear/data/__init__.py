"""Built-in scenes (TOML), shipped as package data."""
