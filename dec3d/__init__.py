"""dec3d: an open-source, 3DEC-style three-dimensional distinct element program."""
__version__ = "0.1.0"
