"""``import itasca`` for 3DEC Python scripts run outside 3DEC: this is dec3d's ``dec3d.itasca``.

A shim shipped with dec3d (``pip install "dec3d[itasca]"`` documents the intent; docs/python.md): on
import it puts ``dec3d.itasca`` and its sub-modules in place of this package, so ``import itasca as it``,
``it.block.find(1)``, ``from itasca import blockarray as ba`` and ``import itasca.block.contact`` all give
dec3d's. Inside Itasca's own programs their built-in ``itasca`` module is used instead.
"""
from dec3d.itasca.driver import alias_itasca as _alias

_alias()
