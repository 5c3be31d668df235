"""The values layer (see docs/architecture.md)."""
