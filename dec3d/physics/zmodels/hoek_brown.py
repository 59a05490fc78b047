"""Host of zone model ``hoek-brown`` (kernel: ``dec3d/kernels/zmodels/hoek_brown.py``, which gives
the criterion, the flow rule and the sources).

Properties: the elastic ones (bulk, shear or young and poisson; density) and Itasca's
``constant-mb`` (mb > 0), ``constant-s`` (0 <= s <= 1), ``constant-a`` (0 < a <= 1),
``constant-sci`` (σci > 0, the unconfined compressive strength of the intact rock; also taken as
``strength-compression``),
``constant-dilation`` (ψ in degrees, default 0) and ``flag-dilation`` (0: ψ = constant-dilation;
< 0: ψ = the local friction angle φc; > 0: ψ = flag × φc). Every own property defaults to 0, as in
Itasca's model, so mb, a and σci must be given (the range check refuses the zones otherwise).

Strength reduction (``model factor-of-safety``): not provided (``reduce`` is None). Itasca's
page says the model "can be used to perform factor of safety calculations" as the Mohr-Coulomb
model is; in its model source (``ModelHoek::run``, ``scaleProperties``) the reduction acts on the
instantaneous tangent c_c and tan φc at each stress level (or on σci alone, its flag-fos
option), which no change of the constant columns can express. It would need the kernel to read a factor per zone (as table strengths read
P_SRF), a change of the plug-in contract left to the engine's owner.
"""
from dec3d.kernels.zmodels import hoek_brown as kernel
from dec3d.physics.cmodels import ELASTIC, Prop, angle, which_zones, zmodel

_K = kernel

PROPS = ELASTIC + [
    Prop("constant-mb", _K.C_MB, "Hoek-Brown constant mb", "", lo=0.0, lo_open=True),
    Prop("constant-s", _K.C_S, "Hoek-Brown constant s", "", lo=0.0, hi=1.0),
    Prop("constant-a", _K.C_A, "Hoek-Brown exponent a", "", lo=0.0, lo_open=True, hi=1.0),
    Prop("constant-sci", _K.C_SCI, "unconfined compressive strength of the intact rock σci", "Pa",
         lo=0.0, lo_open=True),
    # (the name the issue and some of Itasca's pages use for σci: the same column)
    Prop("strength-compression", _K.C_SCI, "σci, the same as constant-sci", "Pa", lo=0.0, lo_open=True),
    angle("constant-dilation", _K.C_TANDIL, "dilation angle ψ (capped at the local friction angle)"),
    Prop("flag-dilation", _K.C_FLAGDIL, "dilation rule: 0 constant-dilation; < 0 ψ = φc; > 0 ψ = flag × φc",
         "", lo=None),
]


def hoek_check(p, ids):
    """Cross-property rules: none refuse; a dilation angle given together with a nonzero
    flag-dilation is ignored (the flag decides), which is worth a warning."""
    warnings = []
    both = (p[:, _K.C_FLAGDIL] != 0.0) & (p[:, _K.C_TANDIL] > 0.0)
    if both.any():
        warnings.append(f"constant-dilation is ignored where flag-dilation is nonzero: {which_zones(ids, both)}")
    return [], warnings


zmodel(kernel, "generalized Hoek-Brown yield (Itasca's model: tangent Mohr-Coulomb extension and tension "
       "cut-off at s σci/mb for tensile σ3, non-associated flow with a dilation angle)", PROPS,
       check=hoek_check, reduce=None)
