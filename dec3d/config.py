"""Settings every layer may read, kernels included.

Kept free of imports from the rest of the package so that `dec3d.kernels`
can use it without breaking the one-direction import rule.
"""
import numpy as np

#: floating point type of every state array
FLOAT = np.float64
#: integer type of indices into the stores
INT = np.int64
#: numba caching of compiled kernels (on disk next to the module)
NUMBA_CACHE = True
#: version written into save files; a file with a newer version is refused
SAVE_FORMAT_VERSION = 1


# ----------------------------------------------------------------------------------------------
# threads of the parallel kernels (numba prange); every kernel gives bit-identical results
# whatever the count (fixed-order sums, see dec3d/kernels/cycle.py)
# ----------------------------------------------------------------------------------------------

#: environment variable with the number of threads of the parallel kernels (read at import)
THREADS_ENV = "DEC3D_THREADS"
#: numba threading layers in the order dec3d wants them: GNU OpenMP first where the system has
#: libgomp, numba's own workqueue otherwise. A step of the cycle kernel is two parallel loops of a
#: few milliseconds each; OpenMP's idle workers wait spinning for a moment and start at once, the
#: workqueue's sleep and are woken for every loop, and on a virtual machine that wake-up is slow
#: and uneven: the 20-layer cube stack took 1.9x less time on two threads than on one with OpenMP,
#: 1.4x with the workqueue (bench/README.md, session 9). GNU OpenMP is not fork-safe (a process
#: forked after a parallel kernel ran aborts in its first parallel kernel; numba documentation,
#: "The Threading Layers"): dec3d's own worker processes are spawned (the factor-of-safety pool,
#: batch runs), never forked. TBB hung here in numba's before-fork handler (``tbb::finalize``
#: spinning on ``sched_yield``, numba issue #5983) when a later test forked, so it comes last.
#: GNU OpenMP is thread-safe, the workqueue is not (numba documentation); dec3d runs parallel
#: kernels from one thread only either way (``in_threads`` runs serial ``nogil`` kernels)
LAYER_PRIORITY = ("omp", "workqueue", "tbb")
#: how long GNU OpenMP's idle workers spin before they sleep (``GOMP_SPINCOUNT``, set at import
#: unless the user set it or ``OMP_WAIT_POLICY``; libgomp reads it when numba first loads it).
#: libgomp's own default, 300 000, held both cores when two dec3d processes shared the 2-core VM:
#: two 20-layer runs side by side took 2.15 s each against 0.79 s with the workqueue; with 1 000
#: they take 0.79 s, and a run alone keeps its speed (0.38 s for 100 steps either way)
OMP_SPINCOUNT = 1000


def max_threads() -> int:
    """The most threads the kernels may use in this process (numba's NUMBA_NUM_THREADS: by
    default the number of cores)."""
    from numba.core import config

    return int(config.NUMBA_NUM_THREADS)


def threads() -> int:
    """Threads the parallel kernels use now (in this thread of the program)."""
    import numba

    return int(numba.get_num_threads())


def set_threads(n) -> int:
    """Use ``n`` threads in the parallel kernels (1 ≤ n ≤ ``max_threads()``); ValueError
    otherwise. Returns n. (numba keeps the count per calling thread: a program that runs decks
    in another thread sets it there.)"""
    import numba

    top = max_threads()
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= top:
        raise ValueError(f"the number of threads must be a whole number from 1 to {top} "
                         f"(the cores numba may use here, NUMBA_NUM_THREADS), got {n!r}")
    numba.set_num_threads(n)
    return n


def threading_layer() -> str:
    """The numba threading layer in use ("not started yet" before the first parallel kernel)."""
    import numba

    try:
        return str(numba.threading_layer())
    except ValueError:
        return "not started yet"


def thread_report() -> str:
    """One line: threads used, of how many, and the threading layer."""
    return f"threads {threads()} of {max_threads()} (numba threading layer: {threading_layer()})"


def init_threads(environ=None) -> str | None:
    """Run once at ``import dec3d``: put numba's threading layers in dec3d's order (``LAYER_PRIORITY``)
    unless the user chose one (NUMBA_THREADING_LAYER or NUMBA_THREADING_LAYER_PRIORITY), shorten
    GNU OpenMP's idle spinning (``OMP_SPINCOUNT``) unless the user set it, and take
    the thread count from ``DEC3D_THREADS`` when set. Returns a warning for a value of
    ``DEC3D_THREADS`` that cannot be used (the count is then left as it was), else None."""
    import os
    import warnings

    from numba.core.errors import NumbaPerformanceWarning

    # the serial twins of the parallel kernels (``kernels.cycle._serial_twin``) go through numba's
    # parallel pipeline with every transformation off, by design: numba's warning that they have
    # nothing parallel is left out, for dec3d's kernels only
    warnings.filterwarnings("ignore", message=r"(?s).*no transformation for parallel execution was possible"
                            r".*dec3d[/\\]kernels", category=NumbaPerformanceWarning)
    env = os.environ if environ is None else environ
    if "NUMBA_THREADING_LAYER" not in env and "NUMBA_THREADING_LAYER_PRIORITY" not in env:
        from numba.core import config

        # the environment too: numba re-reads it when it changes, and child processes inherit it
        env["NUMBA_THREADING_LAYER_PRIORITY"] = " ".join(LAYER_PRIORITY)
        config.THREADING_LAYER_PRIORITY = list(LAYER_PRIORITY)
    if "GOMP_SPINCOUNT" not in env and "OMP_WAIT_POLICY" not in env:
        env["GOMP_SPINCOUNT"] = str(OMP_SPINCOUNT)
    raw = env.get(THREADS_ENV, "").strip()
    if not raw:
        return None
    try:
        n = int(raw)
    except ValueError:
        n = None
    top = max_threads()
    if n is None or n < 1:
        return (f"dec3d: {THREADS_ENV}={raw!r} is not a whole number ≥ 1; "
                f"the kernels use {threads()} thread(s)")
    if n > top:
        set_threads(top)
        return f"dec3d: {THREADS_ENV}={n} is more than the {top} cores numba may use here; using {top}"
    set_threads(n)
    return None


#: largest mass density dec3d accepts (kg/m³): 4e4 times osmium's, room for any density scaling a
#: deck does by hand, while a block's mass ρ·V stays a finite number (1e308 made it infinite)
DENSITY_LIMIT = 1e9
#: largest stiffness (joint kn, ks in Pa/m) and elastic modulus (zones and FE blocks, Pa) a command
#: takes: far above any rock, concrete or steel in any unit system a deck uses (steel is 2e11 Pa; a
#: 1 mm joint of it 2e14 Pa/m). A larger value is a typo, and its time step would be too small to get
#: anywhere (Δt ∝ 1/√k). (Strengths have no such limit: decks set `tension 1e20` for "never opens".)
STIFFNESS_LIMIT = 1e20
MODULUS_LIMIT = 1e16
