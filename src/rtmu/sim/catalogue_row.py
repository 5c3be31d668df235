"""One row of a simulated server's data list, as the wire lists it (protocol §2.7–2.8)."""

Row = tuple[str, str, str, str, str, str]
"""(name, description, argument description, return description, command group, flags)"""
