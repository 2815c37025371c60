"""Sound in the world: sources, how it travels, what MiRo's microphones hear."""
