"""Units of reported quantities: shown only when the deck declares them.

3DEC, like dec3d, works in any consistent system of units: a deck in kN, kPa and t/m³ runs the same as
one in N, Pa and kg/m³. A report that printed "Pa" after a stress of such a deck would be wrong, so
dec3d prints model quantities (forces, stresses, lengths, model time, …) without a unit unless the deck
says which system it uses: ``model configure units si`` (a dec3d setting; 3DEC has none). The setting
is saved with the model; ``model configure units none`` takes it back.

With a declared system, the reports name the units (``axial (N)``, ``Δt = 2e-05 s``) and the VTK files
carry a field-data array ``units`` (text: ``system=SI`` and one ``array=unit`` line per array written).
Wall-clock times (``finished in 3.2 s``) are real seconds and always say so.
"""
from __future__ import annotations

#: the unit systems reports can name (``model configure units``; "none", the default, names none)
SYSTEMS = {
    "si": {
        "length": "m", "area": "m²", "volume": "m³", "mass": "kg", "time": "s", "force": "N",
        "moment": "N·m", "stress": "Pa", "stiffness": "Pa/m", "velocity": "m/s", "acceleration": "m/s²",
        "density": "kg/m³", "frequency": "Hz", "rate": "1/s", "angular-velocity": "rad/s",
        "per-length": "1/m", "energy": "J", "pressure": "Pa", "flow": "m³/s",
    },
}
#: the words ``model configure units`` takes
NAMES = tuple(SYSTEMS) + ("none",)

#: the physical dimension of each array dec3d writes to VTK (what ``units`` field data names)
ARRAY_DIMS = {
    "displacement": "length", "velocity": "velocity", "stress_gp": "stress", "stress": "stress",
    "density": "density", "volume": "volume", "mass": "mass", "spin": "angular-velocity",
    "normal_stress": "stress", "shear_stress": "stress", "normal_force": "force", "shear_force": "force",
    "opening": "length", "slip_displacement": "length", "shear_displacement": "length",
    "normal_displacement": "length", "pore_pressure": "pressure", "pore_force": "force",
    "area": "area", "axial_force": "force", "shear_force_magnitude": "force",
    "shear_displacement_magnitude": "length", "pressure": "pressure",
}


def system(settings) -> str:
    """The declared system's name ("" when none is declared)."""
    s = getattr(settings, "units", "") or ""
    return s if s in SYSTEMS else ""


def _settings(where):
    """Accept a session, a model or a settings object."""
    m = getattr(where, "model", where)
    return getattr(m, "settings", m)


def symbol(where, dim: str) -> str:
    """The unit of dimension ``dim`` in the declared system, "" when none is declared."""
    name = system(_settings(where))
    if not name:
        return ""
    return SYSTEMS[name][dim]


def suffix(where, dim: str) -> str:
    """" m" (a space and the unit) after a number, or "" when no units are declared."""
    u = symbol(where, dim)
    return f" {u}" if u else ""


def paren(where, dim: str) -> str:
    """" (m)" after a column or axis name, or "" when no units are declared."""
    u = symbol(where, dim)
    return f" ({u})" if u else ""


def field_lines(where, arrays) -> list[str]:
    """The text of the ``units`` field-data array for a file holding ``arrays`` (names); [] when no
    system is declared."""
    name = system(_settings(where))
    if not name:
        return []
    table = SYSTEMS[name]
    lines = [f"system={name.upper()}"]
    for a in arrays:
        dim = ARRAY_DIMS.get(a)
        if dim:
            lines.append(f"{a}={table[dim]}")
    return lines


def describe(where) -> str:
    """One line for ``model list``: which system, or how to declare one."""
    name = system(_settings(where))
    if name:
        t = SYSTEMS[name]
        return (f"{name.upper()} ({t['length']}, {t['mass']}, {t['time']}, {t['force']}, {t['stress']}); "
                "reports name them")
    return "not declared: reports show no units (`model configure units si` to show SI units)"
