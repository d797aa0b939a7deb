"""Data package: the on-disk contract, Arrow table schemas and the manifest JSON Schema."""
