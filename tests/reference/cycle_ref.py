"""Slow reference of one mechanical step (``kernels.cycle.run_steps``: 3DEC theory Fig. 13, the
calculation cycle), written from the equations, in plain Python: it calls no kernel.

1. every sub-contact: relative velocity (Eq. 15), displacement increments (Eqs. 20-22), the joint
   law (``rigid_ref.coulomb_ref``, Eqs. 24-43 with the ERRATA), and the force on B = Fⁿ n + Fˢ at
   the sub-contact point, on A the negative, with the moments about each centroid (Eqs. 28-32);
2. the motion of every group (``rigid_ref.motion_groups_ref``, Eqs. 44-52);
3. the contact and sub-contact points move with the mean displacement of their two blocks (Eq. 11,
   ``contactmap_ref.move_points``).
"""
import numpy as np

from .contactmap_ref import move_points
from .rigid_ref import coulomb_ref, motion_groups_ref

FAILED = 1          # state bit of a sub-contact that has failed (the kernels' ST_FAILED)


def subcontact_forces_ref(dt, centroid, vel, spin, force, moment, ca, cb, cn, law, sub):
    """law[c] = (model name, property dict of coulomb_ref); sub: dict of sub-contact arrays
    (contact, pos, area, fn, fs, un, udil, us, state), updated in place; force/moment accumulate."""
    for s in range(len(sub["contact"])):
        c = sub["contact"][s]
        a, b, n = ca[c], cb[c], np.asarray(cn[c], float)
        x = sub["pos"][s]
        ra, rb = x - centroid[a], x - centroid[b]
        v = vel[b] + np.cross(spin[b], rb) - vel[a] - np.cross(spin[a], ra)          # Eq. 15
        du = v * dt
        dun = float(du @ n)
        model, p = law[c]
        fn, fs, un, udil, us, failed, _ = coulomb_ref(p, model, sub["area"][s], dun, du - dun * n,
                                                      sub["un"][s], sub["udil"][s], sub["fs"][s],
                                                      sub["us"][s], bool(sub["state"][s] & FAILED))
        sub["fn"][s], sub["fs"][s], sub["un"][s], sub["udil"][s], sub["us"][s] = fn, fs, un, udil, us
        sub["state"][s] = FAILED if failed else 0
        f = fn * n + fs
        force[b] += f
        force[a] -= f
        moment[b] += np.cross(rb, f)
        moment[a] -= np.cross(ra, f)


def step_ref(dt, gravity, damp_mode, alpha, servo, full, groups, blocks, verts, contacts, law, sub, vmax, out):
    """One step of the cycle. groups: dict gstart gmember gmass gimass giscalar gprin gaxes gcentroid;
    blocks: dict mass fixity force moment fapp mapp vel spin centroid disp vstart vcount; verts: (nv, 3);
    contacts: dict a b normal pos. Everything is updated in place; returns motion_groups_ref's value."""
    B, G = blocks, groups
    subcontact_forces_ref(dt, B["centroid"], B["vel"], B["spin"], B["force"], B["moment"],
                          contacts["a"], contacts["b"], contacts["normal"], law, sub)
    bad = motion_groups_ref(dt, gravity, damp_mode, alpha, servo, full, G["gstart"], G["gmember"], G["gmass"],
                            G["gimass"], G["giscalar"], G["gprin"], G["gaxes"], G["gcentroid"], B["mass"],
                            B["fixity"], B["force"], B["moment"], B["fapp"], B["mapp"], B["vel"], B["spin"],
                            B["centroid"], B["disp"], B["vstart"], B["vcount"], verts, vmax, out)
    own = np.arange(len(contacts["a"]))
    args = (dt, contacts["a"], contacts["b"])
    contacts["pos"][...] = move_points(*args, own, contacts["pos"], B["centroid"], B["vel"], B["spin"])
    sub["pos"][...] = move_points(*args, sub["contact"], sub["pos"], B["centroid"], B["vel"], B["spin"])
    return bad
