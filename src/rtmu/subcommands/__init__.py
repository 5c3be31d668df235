"""One module per ``rtmu`` subcommand; each defines ``register(subparsers)``."""
