"""The FE-block half of the deformable step: element forces, masses, stiffness and slave nodes
of 20-node bricks, for the gridpoint motion of ``dec3d.physics.zones`` to move.

FE-block text (shared/seeds/003_*, "Solution Algorithm"): the nodes of FE blocks obey the same
equations of motion as zone gridpoints, m ü + α m u̇ = F, F = F^S (Eq. 7) + F^C + F^B (Eq. 9) +
F^G (Eq. 8). ``FeStepper`` holds what a run needs and has no motion of its own:

1. checks (``error`` raised, naming blocks or elements): every live FE block has an element with a
   model; elastic elements have bulk, shear and density; every element has det J > 0;
2. ``mass`` (HRZ lumping, ``feb_lumped_mass``) and ``stiff`` (twice the Gershgorin row-sum bound
   of ``feb_stiffness``: the k of Eq. 84 for density scaling) per vertex row, zero at slave nodes.
   The factor 2 (``DAMPING_MARGIN``) is because local damping can raise the force on a node by
   1 + α (α = 0.8 when the force opposes the velocity), which lowers the stable step by
   (1 + α)^½: measured on the cantilever of fem_beam.dat, m = k Δt²/4 with the bare bound and
   α = 0.8 diverges within 60 steps (the largest eigenvalue of M⁻¹K is 2.43/Δt², above 4/1.8);
   with the factor it converges;
   ``gweight`` (ρ ∫ N_a dV per node: consistent gravity F^G = gweight g, Eq. 8; elements whose
   ``feblocks.gravity`` is 0, `feblock gravity delete`, add none);
3. each step: ``forces`` adds F^S of the elastic elements (``feb_step``, 2×2×2 or 3×3×3 per
   element; 2×2×2 elements with the hourglass control of ``kernels.feblock_hg`` where their
   ``feblocks.hourglass`` is not 0) and F^G to the force accumulator; ``slave_forces`` sends what contacts and face loads
   put on slave nodes to the masters (Eq. 9) — call it after those are added and before the
   motion; ``follow`` moves the slave nodes with the masters (positions in large strain,
   velocities, displacements) after the motion.

The motion update must use ``masters`` (slave rows excluded: they carry no mass) and must not add
m g again for FE nodes (gravity is in ``forces``).
"""
from __future__ import annotations

import numpy as np

from dec3d.kernels.feblock import (_slave_weights, feb_body_force, feb_element_pass, feb_element_pass_serial,
                                   feb_lumped_mass, feb_node_lists, feb_node_sums_mag, feb_node_sums_mag_serial,
                                   feb_slave_forces, feb_slave_interp, feb_stiffness)
from dec3d.model.feblocks import feblock_store
from dec3d.model.model import KIND_FE
from dec3d.model.zones import ZMODEL_ELASTIC, ZMODEL_NULL, ZP_BULK, ZP_DENSITY, ZP_SHEAR
from dec3d.physics.zone_setup import block_elements

_F = np.float64
_I = np.int64

#: elements of one Gauss rule above which the element pass runs on threads (same results either way)
PARALLEL_MIN = 2048

#: the Gershgorin bound times this is the node stiffness used for time step and density scaling
DAMPING_MARGIN = 2.0


def fe_blocks(model) -> np.ndarray:
    """Rows of the live FE blocks."""
    b = model.blocks
    return np.flatnonzero((b["kind"] == KIND_FE) & ~b["hidden"]).astype(_I)


def _ids(model, rows) -> str:
    ids = sorted(set(int(i) for i in model.blocks["id"][np.asarray(rows, _I)]))
    return ", ".join(str(i) for i in ids[:10]) + (f" … ({len(ids)} blocks)" if len(ids) > 10 else "")


class FeStepper:
    def __init__(self, model, error, ref=None, geo=None):
        """``error``: the exception class to raise (the engine's ``RunError``); ``ref``: the
        positions of the masses and gravity weights, ``geo``: those of the stiffness (both
        (nv, 3), default the current positions; see ``physics.zones.ZoneStepper``)."""
        self.model = model
        es = feblock_store(model)
        b, v = model.blocks, model.vertices
        self.blocks = fe_blocks(model)
        on, erow, cm = block_elements(model, es, self.blocks, (ZMODEL_NULL, ZMODEL_ELASTIC), error, "FE elements",
                                      "yet (only elastic and null)")
        live = np.zeros(b.n, bool)
        live[es["block"][erow[cm == ZMODEL_ELASTIC]]] = True
        none = self.blocks[~live[self.blocks]]
        if len(none):
            raise error(f"FE blocks {_ids(model, none)} have no element with a constitutive model: use "
                        "`block zone cmodel assign elastic` or `feblock change cmodel elastic` before cycling")
        el = erow[cm == ZMODEL_ELASTIC]
        p = es["prop"]
        miss = (p[el, ZP_BULK] <= 0) | (p[el, ZP_SHEAR] <= 0) | (p[el, ZP_DENSITY] <= 0)
        if miss.any():
            raise error(f"{int(miss.sum())} elastic FE elements of blocks {_ids(model, es['block'][el[miss]])} "
                        "lack bulk, shear or density: set them before cycling")
        self.bulk = np.ascontiguousarray(p[:, ZP_BULK])
        self.shear = np.ascontiguousarray(p[:, ZP_SHEAR])
        self.density = np.ascontiguousarray(p[:, ZP_DENSITY])
        self.nodes = np.ascontiguousarray(es["nodes"])
        self.slaves = np.ascontiguousarray(es["slaves"])
        # node rows resolved to their link masters (joined blocks share nodes): what slave nodes pass
        # on (Eq. 9) arrives after the linked rows were summed onto their masters, so it goes there
        link = v["link"][np.maximum(self.nodes, 0)]
        self.mnodes = np.ascontiguousarray(np.where(link >= 0, link, self.nodes))
        nq = es["nq"][el]
        hg = es["hourglass"][el] if "hourglass" in es else np.zeros(len(el))
        hg = np.where(nq == 2, hg, 0.0)
        # one kernel call per (Gauss rule, hourglass eps_h): elements their mesh holds run without control
        self.groups = [(np.int64(q), float(h), np.ascontiguousarray(el[(nq == q) & (hg == h)]))
                       for q in (2, 3) for h in np.unique(hg[nq == q])]
        # per Gauss rule: scratch of the parallel element pass and the fixed-order node lists
        self.scratch = [(np.empty((len(r), 20, 3)), np.empty(len(r), np.bool_), *feb_node_lists(v.n, self.nodes, r))
                        for _, _, r in self.groups]
        self.erows = np.ascontiguousarray(erow)
        n = v.n
        self.error = error
        pos = np.ascontiguousarray(v["pos"] if ref is None else ref)
        self.mass = np.zeros(n)
        self.gweight = np.zeros(n)
        gw = np.zeros((n, 3))
        first = feb_lumped_mass(pos, self.nodes, np.ascontiguousarray(el), self.density, self.mass)
        # consistent gravity only of the elements that carry it (``feblocks.gravity``, `feblock gravity`)
        grav = el[es["gravity"][el] != 0] if "gravity" in es else el
        first = max(first, feb_body_force(pos, self.nodes, np.ascontiguousarray(grav), self.density,
                                          np.array([0.0, 0.0, 1.0]), gw))
        self._check(first)
        self.gweight = gw[:, 2].copy()
        self.stiffness(v["pos"] if geo is None else geo)
        vb = v["block"]
        mine = v["zoned"] & on[np.maximum(vb, 0)] & (vb >= 0)
        self.rows = np.flatnonzero(mine).astype(_I)
        self.masters = np.ascontiguousarray(self.rows[~v["feslave"][self.rows]])
        self.slave_rows = np.ascontiguousarray(self.rows[v["feslave"][self.rows]])

    def _check(self, first: int) -> None:
        if first >= 0:
            es, b = self.model.store("feblocks"), self.model.blocks
            raise self.error(f"FE element {int(es['id'][first])} (block {int(b['id'][es['block'][first]])}) has "
                             "a non-positive Jacobian at a Gauss point")

    def stiffness(self, geo) -> None:
        """``stiff``: the nodal stiffness of the elements on the positions ``geo`` (large strain:
        worked out again on the schedule of ``ZoneStepper.regeometry``)."""
        pos = np.ascontiguousarray(geo)
        self.stiff = np.zeros(len(pos))
        first = -1
        for q, h, rows in self.groups:
            first = max(first, feb_stiffness(pos, self.nodes, rows, self.bulk, self.shear, self.stiff, q, h))
        self._check(first)
        self.stiff *= DAMPING_MARGIN

    def forces(self, pos, vel, dt: float, gravity, facc, fmag=None) -> int:
        """Add the element forces F^S (stresses updated; elements on the threads, node sums in a
        fixed order) and the consistent gravity F^G to facc, and the magnitudes of both to fmag
        (if given). Returns the first element row skipped (det J not positive), −1 if none."""
        es = self.model.store("feblocks")
        gs, st = es["gstress"], es["stress"]
        mag = fmag if fmag is not None else np.zeros(len(facc))
        first = -1
        for (q, h, rows), (fe, ok, nstart, nent) in zip(self.groups, self.scratch):
            # small meshes on the calling thread: starting the threads costs more than the work
            par = len(rows) > PARALLEL_MIN
            (feb_element_pass if par else feb_element_pass_serial)(pos, vel, self.nodes, rows, self.bulk,
                                                                  self.shear, dt, gs, st, fe, ok, q, h)
            (feb_node_sums_mag if par else feb_node_sums_mag_serial)(facc, mag, fe, ok, nstart, nent)
            if first < 0 and not ok.all():
                first = int(rows[np.flatnonzero(~ok)[0]])
        g = np.asarray(gravity, _F)
        if g.any():
            w = self.gweight[self.masters]
            facc[self.masters] += w[:, None] * g
            mag[self.masters] += np.abs(w) * float(np.sqrt(g @ g))
        return first

    def stiffness_damping(self, pos, vel, f) -> None:
        """Add −K v of the elastic elements (hourglass control included) to f (nv, 3): the element
        pass on zero stresses with the strain increment of ``vel`` over a unit time (for Rayleigh
        damping's stiffness term, ``physics.dynamic.zone_stiffness_damping``); the element stresses
        are not touched."""
        es = self.model.store("feblocks")
        sc = getattr(self, "_damp_scratch", None)
        if sc is None or sc[0].shape != es["gstress"].shape or len(sc[2]) != len(f):
            sc = self._damp_scratch = (np.zeros_like(es["gstress"]), np.zeros_like(es["stress"]), np.zeros(len(f)))
        gs, st, mag = sc
        for (q, h, rows), (fe, ok, nstart, nent) in zip(self.groups, self.scratch):
            gs[rows] = 0.0
            par = len(rows) > PARALLEL_MIN
            (feb_element_pass if par else feb_element_pass_serial)(pos, vel, self.nodes, rows, self.bulk,
                                                                  self.shear, 1.0, gs, st, fe, ok, q, h)
            (feb_node_sums_mag if par else feb_node_sums_mag_serial)(f, mag, fe, ok, nstart, nent)

    def slave_stiffness(self, k: np.ndarray) -> None:
        """Move stiffness put on slave rows (contacts, Eq. 85) to the masters (their link
        masters), weighted by |N_a| at the slave (a bound of what Eq. 9 carries to each)."""
        w = np.abs(_slave_weights())
        for s in range(7):
            r = self.slaves[self.erows, s]
            on = r >= 0
            if not on.any():
                continue
            ks = k[r[on]]
            np.add.at(k, self.mnodes[self.erows[on]], ks[:, None] * w[s][None, :])
            k[r[on]] = 0.0

    def slave_forces(self, facc) -> None:
        """Forces on slave nodes (contacts, face loads) to the masters by Eq. (9) (to the link
        masters of linked nodes)."""
        feb_slave_forces(self.mnodes, self.slaves, self.erows, facc)

    def follow(self, *arrays) -> None:
        """Slave nodes take the masters' interpolated values of each (nv, 3) array given
        (velocities, displacements, positions in large strain)."""
        for arr in arrays:
            feb_slave_interp(self.nodes, self.slaves, self.erows, arr)
