"""Host of joint model ``barton-bandis`` (kernel: ``dec3d/kernels/joints/barton_bandis.py``;
equations and sources there). Not a 3DEC built-in: the model and property names are ours.

`friction-residual` is declared in [0, 90) but shares mohr's keyword, and the command layer keys the
ranges by keyword (the last model's, mohr's [0, 90], wins): 90 passes binding until ranges are checked
per model; the kernel then reads it as "never slips" (tan 90° is finite in floating point, and the
peak angle is never below φr). `jcs` and `closure-maximum` are declared > 0 (lo_open), which the
command layer does not pass on yet: 0 passes binding (the kernel then gives φp = φr, a linear closure)."""
from dec3d.kernels.joints import barton_bandis as kernel
from dec3d.physics.jmodels import STIFFNESS, Prop, jmodel

jmodel(kernel, "Barton's peak strength σn tan(φr + JRC log10(JCS/σn)) (≤ 70°), residual σn tan φr after the "
       "peak, Bandis' hyperbolic normal closure σn = kni v/(1 − v/vm)", STIFFNESS + [
           Prop("jrc", kernel.P_JRC, "joint roughness coefficient JRC (Barton's profiles 0-20)", "", hi=20.0),
           Prop("jcs", kernel.P_JCS, "joint wall compressive strength JCS", "Pa", lo=0.0, lo_open=True,
                required=True),
           Prop("friction-residual", kernel.P_PHIR, "residual friction angle φr", "deg", hi=90.0, hi_open=True,
                required=True),
           Prop("closure-maximum", kernel.P_VM, "maximum closure vm of the Bandis hyperbola", "m", lo=0.0,
                lo_open=True, required=True),
       ])
