"""Subcommands of the ``dtcosim`` CLI, one module each."""
