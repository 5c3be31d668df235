"""RTMU: a teleoperation client (and simulator) for ARIA ArNetworking robot servers."""

__version__ = "0.1.0"
