"""Generation and training presets (TOML files, no code)."""
