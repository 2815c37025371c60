"""Off-screen images of the world: the renderers and the eye worker processes."""
