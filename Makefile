# Convenience aliases: 'make X' runs './rtmu-dev X' (the README's commands), which needs only bash and
# installs what is missing on first use. See ./rtmu-dev help.

.PHONY: help setup demo test lint format bench docs screenshots

help:
	@bash rtmu-dev help

setup demo test lint format bench docs screenshots:
	@bash rtmu-dev $@
