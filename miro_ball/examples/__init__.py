"""Example clients, one small file each: what students copy from."""
