"""Host of zone model ``elastic`` (kernel: ``dec3d/kernels/zmodels/elastic.py``)."""
from dec3d.kernels.zmodels import elastic as kernel
from dec3d.physics.cmodels import ELASTIC, zmodel

zmodel(kernel, "isotropic linear elasticity (bulk and shear, or young and poisson; density)", ELASTIC)
