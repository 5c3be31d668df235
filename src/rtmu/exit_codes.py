"""The exit codes every ``rtmu`` subcommand shares, apart from the CLI so that any layer may name them.

A typed client error carries its code (``rtmu.client.errors``) without importing the
command line; subcommands add their own codes above these in their modules.
"""

from __future__ import annotations

EXIT_OK = 0
EXIT_USAGE = 2
EXIT_CONNECTION = 3
EXIT_UNSUPPORTED = 4
EXIT_TIMEOUT = 5

EXIT_FOREIGN_CONFIG = 9
"""The robot has a configuration RTMU cannot show or edit yet (an Omron LD robot's ``getConfigValues``
/ ``setConfigValues``, whose layouts are not public): ``rtmu config`` says which, and stops."""
