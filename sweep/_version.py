"""The package version, in one place (read by the package root and by result provenance)."""
__version__ = "0.2.0"
