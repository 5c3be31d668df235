"""Tests of the ``rtmu`` command line: each runs ``rtmu.cli.main`` or ``python -m rtmu`` on a real server."""
