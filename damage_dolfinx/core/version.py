"""The package's version (the face re-exports it as ``damage_dolfinx.__version__``)."""
__version__ = "0.1.0"
