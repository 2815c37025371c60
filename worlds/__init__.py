"""Bundled world descriptions (TOML); see README "Worlds"."""
