"""Host of joint model ``barton-bandis`` (kernel: ``dec3d/kernels/joints/barton_bandis.py``;
equations and sources there). Not a 3DEC built-in: the model and property names are ours.

`friction-residual` shares mohr's keyword and so its range check ([0, 90]) until the command layer
checks ranges per model: 90 there is the "never slips" idiom (tan 90° is finite in floating point)."""
from dec3d.kernels.joints import barton_bandis as kernel
from dec3d.physics.jmodels import STIFFNESS, Prop, jmodel

jmodel(kernel, "Barton's peak strength σn tan(φr + JRC log10(JCS/σn)) (≤ 70°), residual σn tan φr after the "
       "peak, Bandis' hyperbolic normal closure σn = kni v/(1 − v/vm)", STIFFNESS + [
           Prop("jrc", kernel.P_JRC, "joint roughness coefficient JRC (Barton's profiles 0-20)", "", hi=20.0),
           Prop("jcs", kernel.P_JCS, "joint wall compressive strength JCS", "Pa", lo=0.0, lo_open=True,
                required=True),
           Prop("friction-residual", kernel.P_PHIR, "residual friction angle φr", "deg", hi=90.0,
                required=True),
           Prop("closure-maximum", kernel.P_VM, "maximum closure vm of the Bandis hyperbola", "m", lo=0.0,
                lo_open=True, required=True),
       ])
