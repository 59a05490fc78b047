"""Hook for `dec3d verify`: run one verification problem and return its named quantities."""
from __future__ import annotations

import pathlib

from .analysis import analyse, summary_numbers


def quantities(problem_dir: pathlib.Path, spec: dict) -> dict[str, float]:
    """Run `spec["input"]` (relative to problem_dir) with `spec["args"]`; see analysis.summary_numbers.

    Understood args: "--compare bishop", "--format F", "--units U", "--tensile-strength T",
    "--strength-reduction" (adds fs_reduction).
    """
    args = list(spec.get("args", []))
    opts: dict = {}
    compare = False
    fmt = "auto"
    i = 0
    while i < len(args):
        a = args[i]
        val = args[i + 1] if i + 1 < len(args) else None
        if a == "--strength-reduction":
            opts["strength_reduction"] = True
            i += 1
            continue
        if a == "--compare" and val == "bishop":
            compare = True
        elif a == "--format":
            fmt = val
        elif a == "--units":
            opts["units"] = val
        elif a == "--tensile-strength":
            opts["tensile_strength"] = float(val)
        else:
            raise ValueError(f"{problem_dir}: unsupported argument {a!r} in problem.toml")
        i += 2
    an = analyse(pathlib.Path(problem_dir) / spec["input"], fmt=fmt, compare_bishop=compare, **opts)
    return {k: float(v) for k, v in summary_numbers(an).items()}
