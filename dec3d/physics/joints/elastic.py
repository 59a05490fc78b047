"""Host of joint model ``elastic`` (kernel: ``dec3d/kernels/joints/elastic.py``)."""
from dec3d.kernels.joints import elastic as kernel
from dec3d.physics.jmodels import STIFFNESS, jmodel

jmodel(kernel, "linear elastic joint, no tension (3DEC's `elastic`)", STIFFNESS)
