"""Model-wide settings set by `model ...` commands (title, gravity, large strain, configure options).

A plain dataclass: it round-trips through JSON for save files (`to_dict` / `from_dict`).
SI units; angles are never stored in degrees.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field


@dataclass
class Settings:
    #: `model title`
    title: str = ""
    #: `model gravity`, m/s^2, (gx, gy, gz)
    gravity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    #: `model large-strain on|off` (3DEC's default is off)
    large_strain: bool = False
    #: `model configure <option>`: options switched on, in the order given
    configure: list[str] = field(default_factory=list)
    #: `model update-interval` (steps between contact detection passes; 3DEC default 10)
    update_interval: int = 10
    #: rigid-block engine settings (``dec3d.physics.rigid.MECH_DEFAULTS``): CTOL, damping,
    #: time step, joint model and properties of new contacts; plain JSON values
    mechanical: dict = field(default_factory=dict)
    #: `model configure units <system>`: the unit system reports and VTK name ("" = none declared:
    #: no units shown; ``dec3d.units``)
    units: str = ""
    #: discrete fracture networks (``dec3d.model.fractures``): templates, DFN names, next ids; plain JSON
    fractures: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        d = asdict(self)
        d["gravity"] = list(self.gravity)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "Settings":
        known = {k: d[k] for k in cls.__dataclass_fields__ if k in d}
        if "gravity" in known:
            known["gravity"] = tuple(float(g) for g in known["gravity"])
        return cls(**known)
