"""The version of vares (read by the package metadata too)."""

__version__ = "0.1.0"
