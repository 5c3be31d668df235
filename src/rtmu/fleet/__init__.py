"""The fleet layer (see docs/architecture.md)."""
