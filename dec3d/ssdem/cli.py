"""`dec3d ssdem INPUT [--out DIR] [--compare bishop]`: static Winkler-spring slope analysis."""
from __future__ import annotations

import argparse
import sys
import time
from contextlib import nullcontext
from pathlib import Path

from dec3d.errors import Dec3dError

from .readers import DEFAULT_MAX_BLOCKS

#: every file `dec3d ssdem` writes, all inside the output folder
OUTPUT_NAMES = ("summary.txt", "blocks.csv", "interfaces.csv", "steps.csv", "result.json", "timings.json",
                "figure.png", "blocks.vtu", "interfaces.vtu")

#: progress bars only for runs at least this large (and only on a terminal)
PROGRESS_MIN_BLOCKS = 2000


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="dec3d ssdem",
        description="Static distinct element (Winkler spring) slope stability analysis after the SSDEM thesis.")
    ap.add_argument("input", metavar="INPUT", help="a .toml slope file, or a thesis Appendix A text file")
    ap.add_argument("--out", metavar="DIR", help="output folder (default: <input stem>_ssdem)")
    ap.add_argument("--compare", choices=["bishop"], help="also run Bishop's simplified method")
    ap.add_argument("--format", choices=["auto", "toml", "appendix-a"], default="auto",
                    help="input format (default: by suffix, .toml or else Appendix A)")
    ap.add_argument("--units", choices=["N-m", "kN-m", "lb-ft"], default="kN-m",
                    help="units of an Appendix A file (default kN-m, as the thesis)")
    ap.add_argument("--tensile-strength", type=float, default=None, metavar="T",
                    help="Appendix A only: turn the tension cut-off on at this tensile strength")
    ap.add_argument("--strength-reduction", action="store_true",
                    help="also find the factor on c' and tan(phi') at which the static solution fails "
                         "(a second FS, to 0.005)")
    ap.add_argument("--max-blocks", type=_positive_int, default=DEFAULT_MAX_BLOCKS, metavar="N",
                    help=f"refuse meshes and files of more than N blocks (default {DEFAULT_MAX_BLOCKS}, "
                         "about 6 GiB of memory)")
    ap.add_argument("--quiet", action="store_true", help="print nothing but errors")
    return ap


def _positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {v}")
    return v


def _trial_line(factor: float, held: bool) -> None:
    """One line per trial of the strength factor (each is a full analysis): the strength
    reduction, or the limit bracket of a slope that does not hold at full strength."""
    print(f"strength factor trial: c', tan phi' / {factor:.3f} {'holds' if held else 'fails'}", flush=True)


def _error(message: str) -> int:
    print(f"dec3d ssdem: error: {message}", file=sys.stderr)
    return 2


def _check_out(out: Path) -> str | None:
    """Why the output folder cannot take our files (None when it can)."""
    if out.exists() and not out.is_dir():
        return f"--out {out}: exists and is not a folder"
    for name in OUTPUT_NAMES:
        f = out / name
        if f.is_symlink() or (f.exists() and not f.is_file()):
            return (f"{f} is a symbolic link or not a regular file; dec3d ssdem writes only regular "
                    "files inside the output folder (remove it first)")
    return None


def _progress(n_blocks: int, quiet: bool):
    """(context, callback): a rich bar over load steps for big runs on a terminal, else nothing."""
    if quiet or n_blocks < PROGRESS_MIN_BLOCKS or not sys.stdout.isatty():
        return nullcontext(), None
    from rich.progress import Progress
    bar = Progress(transient=True)
    task = bar.add_task("load steps", total=None)

    def update(step, n_steps, iteration):
        bar.update(task, total=n_steps, completed=step - 1,
                   description=f"step {step}/{n_steps}, iteration {iteration}")
    return bar, update


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    from . import plot, report
    from .analysis import run_problem
    from .readers import read

    path = Path(args.input)
    if not path.exists():
        return _error(f"no such file: {path}")
    if not path.is_file():
        return _error(f"{path} is not a regular file")
    out = Path(args.out) if args.out else Path(f"{path.stem}_ssdem")   # a stem holds no separator
    why = _check_out(out)
    if why:
        return _error(why)
    toml = args.format == "toml" or (args.format == "auto" and path.suffix.lower() == ".toml")
    opts = dict(max_blocks=args.max_blocks)
    if not toml:
        opts.update(units=args.units, tensile_strength=args.tensile_strength)
    t0 = time.perf_counter()
    try:
        prob = read(path, args.format, **opts)
    except Dec3dError as exc:
        print(exc.format(), file=sys.stderr)
        return 2
    except OSError as exc:
        return _error(f"cannot read {path}: {exc.strerror or exc}")
    t_read = time.perf_counter() - t0
    ctx, update = _progress(prob.blocks.n, args.quiet)
    with ctx:
        an = run_problem(prob, compare_bishop=args.compare == "bishop", progress=update,
                         strength_reduction=args.strength_reduction,
                         reduction_progress=None if args.quiet else _trial_line)
    an.timings["read"] = t_read
    try:
        files = report.write_all(an, out)
        png = out / "figure.png"
        plot.figure(an, png)
        files += [png] + plot.vtk(an, out)
    except OSError as exc:
        return _error(f"cannot write to {out}: {exc.strerror or exc}")
    if not args.quiet:
        sys.stdout.write(report.summary_text(an))
        print(f"wrote {', '.join(f.name for f in files)} to {out}/")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
