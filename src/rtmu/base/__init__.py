"""The base layer (see docs/architecture.md)."""
