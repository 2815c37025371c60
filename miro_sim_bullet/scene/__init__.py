"""World descriptions: the TOML files and what they contain (no PyBullet)."""
