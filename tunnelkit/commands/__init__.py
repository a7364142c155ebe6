"""Sub-commands of the ``tunnelkit`` command line, one module each, discovered at start-up.

A module defines ``NAME``, ``HELP``, ``add_arguments(parser)`` and ``main(args) -> int``.
"""
