"""SeanNet: the scene-embedding network and its trainer (PyTorch side)."""
