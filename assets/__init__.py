"""Data package: the object catalog, room recipes and the class word-vector table (no code)."""
