"""The package version (one place: the package and its notebook helpers read it)."""

__version__ = "0.15.0"
