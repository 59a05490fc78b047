"""3DEC 4/5 top-level commands and their 3DEC 7+ spelling (reference §13).

Used to turn "unknown command" into a precise "legacy syntax" error with the modern form.
"""
from __future__ import annotations

from ..lang.abbrev import matches

_LEGACY = {
    "new": "model new",
    "poly": "block create brick|polyhedron|prism ... (group instead of region)",
    "polyhedron": "block create polyhedron face ...",
    "jset": "block cut joint-set dip <d> dip-direction <dd> origin <v>",
    "property": "block property density <f> / block contact property ...",
    "change": "block property ... range ... / block contact jmodel assign ... range ...",
    "hide": "block hide [range ...]",
    "seek": "block hide off",
    "gravity": "model gravity <v>",
    "damp": "block mechanical damping local|global|combined",
    "cycle": "model cycle <n>",
    "solve": "model solve [ratio <f>] ...",
    "save": "model save '<name>'",
    "restore": "model restore '<name>'",
    "set": "model ... / program ... (the setting's own command)",
    "print": "block list ... / model list ...",
    "fix": "block fix [velocity|rotation] [range]",
    "free": "block free [velocity|rotation] [range]",
    "boundary": "block gridpoint apply ... / block face apply ...",
    "gen": "block zone generate edgelength <f>",
    "generate": "block zone generate edgelength <f>",
    "insitu": "block insitu stress ...",
    "join": "block join on [range]",
    "mark": "block group '<name>' range ...",
    "delete": "block delete [range]",
    "excavate": "block excavate [range]",
    "fill": "block fill [range]",
    "config": "model configure <option>",
    "frac": "block mechanical ... (time step fraction)",
    "mscale": "block mechanical mass-scale",
    "step": "model cycle <n>",
    "reset": "block contact reset ... / block gridpoint initialize ...",
    "title": "model title '<text>'",
    "tunnel": "block create tunnel ...",
    "water": "block ... fluid",
    "edge": "block tolerance edge",
    "densify": "block densify ...",
    "bound": "block gridpoint apply ...",
    "region": "block group ... (regions became groups)",
    "pl": "plot ... (display only in dec3d)",
    "range": "block group '<name>' range ... (3DEC 5 named ranges became groups)",
    "list": "block list ... / model list ... / history list",
    "history": "model history mechanical ... / block history ... / block contact history ...",
}


def legacy_hint(word: str) -> str | None:
    """The 3DEC 7+ spelling for a 3DEC 5 top-level word, or None."""
    hits = matches(word, _LEGACY)
    if len(hits) == 1:
        return f"in 3DEC 7+ write `{_LEGACY[hits[0]]}`"
    return None


def legacy_models() -> dict:
    """3DEC 4/5 constitutive-model numbers (`change cons=n`, `change jcons=n`) -> dec3d's model names,
    from the models' own ``LEGACY_CODE`` (zone models: 0 is the null model); for the translator
    (``dec3d.lang.legacy``, ``State.models``), which knows no model."""
    from ..kernels.joints import MODELS as JOINT_KERNELS
    from ..physics.cmodels import ZONE_MODELS

    cons = {"0": "null"}
    cons.update({str(m.kernel.LEGACY_CODE): name for name, m in ZONE_MODELS.items()
                 if getattr(m.kernel, "LEGACY_CODE", None) is not None})
    jcons = {str(k.LEGACY_CODE): k.NAME for k in JOINT_KERNELS if getattr(k, "LEGACY_CODE", None) is not None}
    return {"cons": cons, "jcons": jcons}
