"""The package's version, on the ground floor: ``discsim.__version__`` re-exports it, and the sweep cache, which
keys its entries by it, reads it here when called (so nothing below the package imports the package)."""

__version__ = "0.1.0"
