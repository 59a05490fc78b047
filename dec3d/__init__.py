"""dec3d: an open-source, 3DEC-style three-dimensional distinct element program."""
__version__ = "0.1.0"

from .kcache import guard as _guard

_guard()      # before any kernel is imported: stale cached kernels cleared, cold-start notice


def _init_threads():
    import sys

    from .config import init_threads

    msg = init_threads()     # numba threading layers in dec3d's order; DEC3D_THREADS
    if msg:
        sys.stderr.write(msg + "\n")


_init_threads()


def __getattr__(name):
    # Session and run_deck import the language layer; loaded on first use so that
    # `import dec3d.kernels...` stays light.
    if name in ("Session", "run_deck"):
        from . import session

        return getattr(session, name)
    if name == "Model":             # a model driven from Python (dec3d.itasca, docs/python.md)
        from .itasca import Model

        return Model
    raise AttributeError(name)
