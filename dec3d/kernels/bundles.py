"""Named bundles of arrays handed to the cycle kernels (``cycle.run_steps``,
``motion.rigid_motion_groups``) instead of long positional lists.

Each bundle is a namedtuple (numba takes them as arguments, each field typed on its own; a
kernel compiled for a bundle is cached like any other). The host builds them from the model's
declared stores (``dec3d.physics.steps``: block store, contact and sub-contact stores, the
rigid groups of the run); the arrays are the stores' own, so a kernel writing a field writes
the store. Field names say what each array is; shapes (nb blocks, ng groups, nv vertices,
nc contacts, ns sub-contacts):

``Bodies``: mass (nb,) kg gravitational; fixity (nb,) uint8 (bits 0-2 velocity, 3-5 rotation);
force, moment, fapp, mapp, vel, spin, centroid, disp (nb, 3); vstart, vcount (nb,) int64 vertex
ranges into vpos (nv, 3) m.

``Groups``: rigid bodies made of joined blocks (a lone block is a group of one), CSR start
(ng+1,) into member (block rows, leader first); mass (ng,) kg real, imass (ng,) kg inertial
(density scaling), iscalar (ng,) kg·m² scalar (scaled) inertia, prin (ng, 3) kg·m² unscaled
principal moments, axes (ng, 3, 3) principal axes as columns, centroid (ng, 3) m.

``Contacts``: a, b (nc,) block rows; normal (nc, 3); pos (nc, 3) reference points; own (nc,)
= arange(nc) (each point's contact, for the point mover); jmodel (nc,) joint model codes;
prop (nc, NPROP) joint properties (``kernels.joints``).

``SubContacts``: contact (ns,) owner; pos (ns, 3); area (ns,) m²; fn (ns,) N; fs (ns, 3) N;
un (ns,) m; udil (ns,) m; us (ns, 3) m; state (ns,) joint state bits; hist (ns, NJHIST) the joint
models' own history (``kernels.joints``); ppf (ns,) the pore-pressure force [N] (``kernels.water``).

``Damping``: mode (int, ``motion.DAMP_*``), alpha (local/combined coefficient, or Rayleigh's
mass term [1/s]), servo (``Servo``: the adaptive global damping state, persists across runs),
prev (ng, 6) each group's unbalanced force (3) and moment (3) of the previous step (combined
damping's force rate), valid while servo.hist[0] is 1.

``Servo`` (every field a (1,) float64 array, so a kernel can update it in place):
alpha current adaptive viscous coefficient α_v [1/s]; work damping work Σ P Δt over the current
window [J]; dek Σ |ΔE_k| over the window [J]; nwin steps in the window; ratio target ratio R;
window window length [steps]; factor servo factor f; lastr last measured R (diagnostic); hist 1
when ``Damping.prev`` holds the previous unbalanced forces of these same groups; calls number of
motion calls. The model saves the fields in this order (``settings.mechanical.servo``).

``Bounds``: the motion bound that ends a batch for a detection: radius (nb,) m largest
centroid-to-vertex distance, acc (nb,) m motion summed since the last detection, trigger m,
motion (2,) as ``cycle._run_steps`` documents.

``Fused``: what ``motion.rigid_motion_groups`` does besides the motion when the cycle kernel hands
it over (one parallel loop per step instead of three): start (nb+1,), ent (2 ns,) the sub-contacts
of every block (``jointlaw.block_lists``), pos (ns, 3) the sub-contact points, sg (ns, 3) the force
on B of each sub-contact (the block sums, ``jointlaw.block_sum``, before the motion); radius (nb,) m
as in ``Bounds`` and step (nb,) m, filled with each member's step motion |v| Δt + |ω| Δt r.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

Bodies = namedtuple("Bodies", "mass fixity force moment fapp mapp vel spin centroid disp vstart vcount vpos")
Groups = namedtuple("Groups", "start member mass imass iscalar prin axes centroid")
Contacts = namedtuple("Contacts", "a b normal pos own jmodel prop")
SubContacts = namedtuple("SubContacts", "contact pos area fn fs un udil us state hist ppf")
Servo = namedtuple("Servo", "alpha work dek nwin ratio window factor lastr hist calls")
Damping = namedtuple("Damping", "mode alpha servo prev")
Bounds = namedtuple("Bounds", "radius acc trigger motion")
Fused = namedtuple("Fused", "start ent pos sg radius step")

#: the number of servo entries a model saves (``Servo``'s fields, in order)
NSERVO = len(Servo._fields)


def new_servo(ratio=0.5, window=10, factor=1.1, alpha0=0.0) -> Servo:
    """A fresh adaptive-damping servo: α_v ``alpha0`` (0: the kernel's start rule), target ratio,
    window [steps] and factor; the rest zero."""
    s = Servo(*(np.zeros(1) for _ in Servo._fields))
    s.alpha[0] = alpha0
    s.ratio[0] = ratio
    s.window[0] = window
    s.factor[0] = factor
    return s


def servo_values(servo: Servo) -> list[float]:
    """The servo as a list of NSERVO floats (field order), as a model saves it."""
    return [float(a[0]) for a in servo]


def load_servo(servo: Servo, values) -> None:
    """Put saved values (``servo_values``) back into ``servo``, in place."""
    for a, x in zip(servo, values):
        a[0] = x


def new_damping(mode: int, alpha: float, ng: int, servo: Servo | None = None) -> Damping:
    """A damping bundle for ``ng`` groups (a fresh servo unless one is given; no force history)."""
    return Damping(int(mode), float(alpha), servo if servo is not None else new_servo(),
                   np.zeros((int(ng), 6)))

# --- the 4-node zone step (``kernels/zone_step.zone_step``) ---------------------------------
#: ``ZoneMesh``: the zone entries of the step, nr of them: g4 (nr, 4) int32 gridpoint rows of
#: each entry's zone, n4 (nr, 4) int32 their averaging nodes (NMD), rows (nr,) zone rows (empty:
#: entry k is zone row k), zset (nr,) the entry's mixed-discretization set or -1 (empty when there
#: is none), weight (nr,) overlay weight (empty: all 1), nset the number of sets.
ZoneMesh = namedtuple("ZoneMesh", "g4 n4 rows zset weight nset")
#: ``ZonePlan``: chunks and scatter plans (``zone_elastic.ElasticPlan``): pstart, pk the chunks of
#: entries; fbits … fpslot the gridpoint-force plan, nbits … npslot the averaging-node plan.
ZonePlan = namedtuple("ZonePlan", "pstart pk fbits fbase fpstart fptgt fpslot nbits nbase npstart nptgt npslot")
#: ``ZoneMaterial``: per zone row cmodel (int8 model codes), prop (nz, NZPROP), hist (nz, NZHIST),
#: bulk, shear (nz,) Pa, stress (nz, 6) Pa, state (nz,) plastic bits; tab the ``Tables`` bundle.
ZoneMaterial = namedtuple("ZoneMaterial", "cmodel prop hist bulk shear stress state tab")
#: ``ZoneScratch``: nodesum, nodevol, nodedsp (nvert,); sa (slots, 2), sb (slots, 4); evs, vols
#: (entries in sets); dsp (nr,); geo (nr, 13) each entry's face area vectors and volume, worked
#: out by the step's first sweep and read by the later ones (empty: a step of one sweep).
ZoneScratch = namedtuple("ZoneScratch", "nodesum nodevol nodedsp sa sb evs vols dsp geo")
