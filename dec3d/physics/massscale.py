"""Density (mass) scaling of the rigid bodies (3DEC theory text, "Mass (Density) Scaling" and
Eq. 87): the inertial masses and scalar inertias of the groups for a time step, by Eq. (87) or by
body from the Gershgorin row sums of the contact stiffness (``kernels.bodyscale``). Mixed into
``rigid.RigidEngine``, which provides ``model``, ``settings()``, ``scaling()``, ``mass_scaling()``,
``full_inertia()``, ``timestep()``, ``contacts`` and ``subcontacts``."""
from __future__ import annotations

import numpy as np

from dec3d.kernels import bodyscale
from dec3d.physics.jmodels import contact_stiffness
from dec3d.kernels.motion import block_timestep

from .bodies import inertial_masses
from .cables import block_stiffness
from .dynamic import stiffness_timestep

_I = np.int64

#: default ``safety`` of density scaling by body, per damping mode: local (and combined) damping
#: takes the sign of a half-step-old velocity, which at ω Δt near 1.6 lags enough to sustain a
#: rocking cycle (a joined column failed to settle at 0.8, settled at 0.75); the viscous adaptive
#: damping settles there (dec3d's measurements, bench/README.md)
SAFETY = {"local": 0.7, "combined": 0.7, "global": 0.8, "none": 0.8}

#: by body, the Δt in use stays at a detection unless the stiffnesses ask for less than this part
KEEP_DT = 0.8

#: ... for the default scaling (masses only raised); at 0.7 DY5's slide ran 2 % fast after its settle
SAFETY_RAISED = 0.5


class DensityScaling:
    def body_safety(self) -> float:
        """The safety s of density scaling by body: ω_max Δt ≤ 2 s (``_body_masses``)."""
        s = self.settings()
        return float(s["safety"] or (SAFETY_RAISED if self.scaling() == "raised" else SAFETY.get(s["damping"], 0.7)))

    def _stiffness_sums(self, gstart, gmember) -> np.ndarray:
        """Per group, Σ over its sub-contacts of max(kn, ks)·area [N/m] (Eq. 87's K)."""
        b = self.model.blocks
        cs, ss = self.contacts, self.subcontacts
        kb = np.zeros(b.n)
        if ss.n:
            c = ss["contact"]
            k = np.maximum(*contact_stiffness(cs, ss))[c] * ss["area"]
            kb += np.bincount(cs["a"][c], k, minlength=b.n) + np.bincount(cs["b"][c], k, minlength=b.n)
        kb += block_stiffness(self.model)[0]          # grout of cables hosted by the block
        return np.add.reduceat(kb[gmember], gstart[:-1]) if len(gmember) else np.zeros(0)

    def _masses(self, gstart, gmember, gmass, giscalar, dt_fixed, near=None, gprin=None):
        """(Δt, inertial masses, scaled scalar inertias) of the groups; density scaling when on.
        ``near``: by body, the Δt in use, kept unless the stiffnesses ask for less than
        ``KEEP_DT`` of it (``_body_masses``)."""
        s = self.settings()
        frac = float(s["frac"])
        if not self.mass_scaling() or not len(gmass):
            dt = dt_fixed if dt_fixed is not None else stiffness_timestep(self.timestep(), self.rayleigh_beta())
            return dt, gmass.copy(), giscalar.copy()
        if self.scaling() in ("body", "raised"):
            return self._body_masses(gstart, gmember, gmass, giscalar, dt_fixed, near, gprin)
        kg = self._stiffness_sums(gstart, gmember)
        if dt_fixed is None and s["scale_timestep"]:
            dt_fixed = float(s["scale_timestep"])
        if dt_fixed is not None:
            dt = dt_fixed
        else:
            on = kg > 0
            # Δt of Eq. (87) for a typical body (median mass and stiffness); lighter or stiffer
            # bodies get a larger inertial mass, heavier ones keep theirs
            dt = (block_timestep(float(np.median(gmass[on])), float(np.median(kg[on])), frac)
                  if on.any() else self.timestep())
        im, isc = inertial_masses(gmass, giscalar, kg, dt, frac)
        return dt, im, isc

    def _body_masses(self, gstart, gmember, gmass, giscalar, dt_fixed, near=None, gprin=None):
        """Density scaling by body (``mass-scale body``): every body's inertial mass and scalar
        inertia set from the Gershgorin row sums of the contact stiffness around it (kernel
        ``bodyscale.body_row_sums``) so that each body has the same critical step, and the
        largest natural frequency ω_max of the scaled system obeys ω_max Δt ≤ 2 × safety:

            m_i = R_t (Δt / 2s)²,   I_i = R_r (Δt / 2s)²   (bodies without contacts keep m and I).

        Δt: the one at which the body of median m / R_t keeps its real mass (or the step given
        with `mass-scale ... timestep`). This is the 3DEC theory text's nodal step (Eq. 84, mass
        over the sum of the stiffnesses around the node, here bounded over the six degrees of freedom
        of a rigid body) used the way "Mass (Density) Scaling" uses it: inertial masses chosen so
        that every part of the model has the same step. With full inertia (Euler's equations) the
        principal moments take the larger of the two ratios m_i / m, I_i / I."""
        s = self.settings()
        safety = self.body_safety()
        b = self.model.blocks
        cs, ss = self.contacts, self.subcontacts
        ng = len(gstart) - 1
        gid = np.full(b.n, -1, dtype=_I)
        gid[gmember] = np.repeat(np.arange(ng), np.diff(gstart))
        mc = b["mass"][gmember][:, None] * b["centroid"][gmember]
        gcen = np.add.reduceat(mc, gstart[:-1], axis=0) / gmass[:, None]
        rho = np.sqrt(giscalar / gmass)
        held = (b["fixity"] | b["apply_fix"])[gmember[gstart[:-1]]].astype(_I)
        rt = np.zeros(ng)
        rr = np.zeros(ng)
        bodyscale.threaded(cs.n)(gid, gcen, rho, held, cs["a"], cs["b"], cs["normal"],
                                 *contact_stiffness(cs, ss),
                                 ss["contact"], ss["pos"], ss["area"], rt, rr)
        # grout of cables hosted by the bodies: translational and (bounded by k |r|²) rotational rows
        kt, kr = block_stiffness(self.model)
        if kt.any():
            g = gid >= 0
            rows = np.flatnonzero(g & (kt > 0))
            rt += np.bincount(gid[rows], kt[rows], minlength=ng)
            r2 = np.sum((b["centroid"][rows] - gcen[gid[rows]]) ** 2, axis=1)
            # Σ k |r + d|² ≤ Σ k |r|² + 2 |d| √(Σ k · Σ k |r|²) + |d|² Σ k (d: block centroid − body centroid)
            rr += np.bincount(gid[rows], kr[rows] + kt[rows] * r2 + 2.0 * np.sqrt(kt[rows] * kr[rows] * r2),
                              minlength=ng)
        if dt_fixed is None and s["scale_timestep"]:
            dt_fixed = float(s["scale_timestep"])
        on = rt > 0
        #: whether the last body scaling had contacts to set Δt from (``steps._Run.masses``)
        self.body_dt_from_contacts = bool(on.any())
        if dt_fixed is not None:
            dt = dt_fixed
        elif on.any():
            dt = 2.0 * safety * float(np.median(np.sqrt(gmass[on] / rt[on])))
            # the masses below keep any Δt stable, so in a run Δt never grows (a block sliding or tipping
            # off its contacts got ever longer steps: R1, F1 blew up) and falls only when clearly asked:
            # the joint law takes velocity × the Δt in use, a changing Δt leaves closures v ΔΔt off the
            # geometry (a block on a spring settled 0.17 % short)
            if near is not None and near > 0 and dt >= KEEP_DT * near:
                dt = near
        else:
            dt = self.timestep()
        f = (dt / (2.0 * safety)) ** 2
        im = np.where(on, rt * f, gmass)
        isc = np.where(rr > 0, rr * f, giscalar)
        if self.scaling() == "raised":
            # the default of static runs: densities only increased (3DEC theory text, "Mass
            # (Density) Scaling"), so no body is lighter than it is; a block that loses most of
            # its contact stiffness (tipping onto an edge, sliding off) keeps its real inertia
            im = np.maximum(im, gmass)
            isc = np.maximum(isc, giscalar)
        if self.full_inertia():
            # Euler's equations turn the body with its principal moments × im / m (kernels.motion):
            # the smallest of them must reach the scalar bound isc, else ω_max Δt exceeds 2s (a
            # 10 × 10 × 5 m block on an incline, I_min = 0.46 of the scalar inertia, ran at
            # ω_max Δt = 2.1 with s = 0.8 and fell through its base)
            imin = giscalar if gprin is None else np.minimum(giscalar, np.asarray(gprin).min(axis=1))
            ratio = np.maximum(im / gmass, isc / imin)
            im, isc = gmass * ratio, giscalar * ratio
        return dt, im, isc

