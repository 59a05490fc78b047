"""Grouted cable structural elements (issue 28, part 1): the step kernel against a plain-Python twin,
force transfer to a rigid block, pre-tension, save/restore, bad input.

The twin below is written from the cable page's formulas (axial ΔF = EA/L ΔL held within the yield
forces, grout force per length k_g × relative axial displacement held within c_g + σ tan φ p, times
the tributary half length, local/combined damping, inertial mass max(m, R (Δt/2s)²)), one node and
one element at a time, sharing no code or constants with ``dec3d.kernels.cable``."""
from __future__ import annotations

import io
import math

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.session import Session


# ------------------------------------------------------------------ the twin
def twin_step(dt, g, alpha, damp, safety, N, S, B):
    """One step on dicts of plain lists: N nodes, S segments, B blocks (vel, spin, cen)."""
    n = len(N["pos"])
    prev = [list(f) for f in N["force"]]
    rel = [[0.0, 0.0, 0.0] for _ in range(n)]
    host_v = [None] * n             # the host point's velocity over the step
    axis = [[0.0, 0.0, 0.0] for _ in range(n)]      # sum of the unit vectors of the node's segments
    for i in range(n):
        h = N["host"][i]
        if h < 0:
            continue
        if N["hz"][i]:          # a zoned host: its host point's velocity is given
            host_v[i] = list(N["hvel"][i])
            rel[i] = [(N["vel"][i][k] - N["hvel"][i][k]) * dt for k in range(3)]
            continue
        c_old = [B["cen"][h][k] - B["vel"][h][k] * dt for k in range(3)]
        r = [N["hpos"][i][k] - c_old[k] for k in range(3)]
        w = B["spin"][h]
        wxr = [w[1] * r[2] - w[2] * r[1], w[2] * r[0] - w[0] * r[2], w[0] * r[1] - w[1] * r[0]]
        vh = [B["vel"][h][k] + wxr[k] for k in range(3)]
        host_v[i] = vh
        for k in range(3):
            N["hpos"][i][k] += vh[k] * dt
            rel[i][k] = (N["vel"][i][k] - vh[k]) * dt
    force = [[0.0, 0.0, 0.0] for _ in range(n)]
    hforce = [[0.0, 0.0, 0.0] for _ in range(n)]
    rowsum = [0.0] * n
    for e in range(len(S["na"])):
        a, b = S["na"][e], S["nb"][e]
        E, A, yt, yc, kg, cg, phi, per, _rho, eps_r = S["prop"][e]
        d = [N["pos"][b][k] - N["pos"][a][k] for k in range(3)]
        L = math.sqrt(sum(x * x for x in d))
        t = [x / L for x in d]
        k_ax = E * A / S["l0"][e]
        flags = S["state"][e] & (8 | 16 | 32)
        for k in range(3):
            axis[a][k] += t[k]
            axis[b][k] += t[k]
        stretch = L - S["lcur"][e]
        S["lcur"][e] = L
        if flags & 32 or (eps_r > 0 and (L - S["l0"][e]) / S["l0"][e] > eps_r):
            # a broken element: no axial force, no grout, no stiffness, ever again
            S["fa"][e] = 0.0
            S["gf"][e] = [0.0, 0.0]
            S["state"][e] = flags | 32
            continue
        if S["tact"][e]:
            S["fa"][e] = S["tapp"][e]
        else:
            S["fa"][e] = S["fa"][e] + k_ax * stretch
            if yt > 0 and S["fa"][e] > yt:
                S["fa"][e], flags = yt, flags | 1 | 8
            elif yc > 0 and S["fa"][e] < -yc:
                S["fa"][e], flags = -yc, flags | 2 | 8
        for k in range(3):
            force[a][k] += S["fa"][e] * t[k]
            force[b][k] -= S["fa"][e] * t[k]
        rowsum[a] += 2 * k_ax
        rowsum[b] += 2 * k_ax
        trib = S["l0"][e] / 2
        for end, node in ((0, a), (1, b)):
            if N["host"][node] < 0 or kg <= 0:
                S["gf"][e][end] = 0.0
                continue
            rowsum[node] += kg * trib
            slip = sum(rel[node][k] * t[k] for k in range(3))
            f = S["gf"][e][end] - kg * trib * slip
            strength = (cg + max(N["conf"][node], 0.0) * math.tan(phi) * per) * trib
            if abs(f) > strength:
                f = math.copysign(strength, f)
                flags |= 4 | 16
            S["gf"][e][end] = f
            for k in range(3):
                force[node][k] += f * t[k]
                hforce[node][k] -= f * t[k]
        S["state"][e] = flags
    for i in range(n):
        # density-scaled (safety > 0) or real mass; a massless node gets 1 kg
        mi = (max(N["mass"][i], rowsum[i] * (dt / (2 * safety)) ** 2) if safety else N["mass"][i]) or 1.0
        N["imass"][i] = mi
        size = math.sqrt(sum(x * x for x in axis[i]))
        if N["host"][i] >= 0 and N["fix"][i] == 0 and size > 0:
            # linked to the host across the cable: Newton's law along the cable direction u only; across it
            # the node takes the host point's velocity and the host the force
            u = [x / size for x in axis[i]]
            total = [force[i][k] + N["fapp"][i][k] + N["mass"][i] * g[k] for k in range(3)]
            along = sum(total[k] * u[k] for k in range(3))
            v_along = sum(N["vel"][i][k] * u[k] for k in range(3))
            sv = int(v_along > 0) - int(v_along < 0)
            F = along
            if damp == 1:
                F -= alpha * abs(along) * sv
            elif damp == 2:
                dF = along - sum(prev[i][k] * u[k] for k in range(3))
                F -= alpha * abs(along) * (sv - (int(dF > 0) - int(dF < 0))) / 2
            v_along += F / mi * dt
            hv = host_v[i]
            hv_along = sum(hv[k] * u[k] for k in range(3))
            for k in range(3):
                hforce[i][k] += total[k] - along * u[k]
                force[i][k] = along * u[k]
                N["vel"][i][k] = v_along * u[k] + hv[k] - hv_along * u[k]
                N["pos"][i][k] += N["vel"][i][k] * dt
                N["disp"][i][k] += N["vel"][i][k] * dt
            N["force"][i] = force[i]
            N["hforce"][i] = hforce[i]
            h = N["host"][i]
            if not N["hz"][i]:
                r = [N["hpos"][i][k] - B["cen"][h][k] for k in range(3)]
                f = hforce[i]
                N["hmoment"][i] = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
            else:
                N["hmoment"][i] = [0.0, 0.0, 0.0]
            continue
        for k in range(3):
            F = force[i][k] + N["fapp"][i][k] + N["mass"][i] * g[k]
            force[i][k] = F
            if N["fix"][i] & (1 << k):
                continue
            v = N["vel"][i][k]
            sv = int(v > 0) - int(v < 0)
            if damp == 1:
                F -= alpha * abs(F) * sv
            elif damp == 2:
                dF = F - prev[i][k]
                F -= alpha * abs(F) * (sv - (int(dF > 0) - int(dF < 0))) / 2
            N["vel"][i][k] = v + F / mi * dt
        for k in range(3):
            N["pos"][i][k] += N["vel"][i][k] * dt
            N["disp"][i][k] += N["vel"][i][k] * dt
        N["force"][i] = force[i]
        N["hforce"][i] = hforce[i]
        h = N["host"][i]
        if h >= 0 and not N["hz"][i]:
            r = [N["hpos"][i][k] - B["cen"][h][k] for k in range(3)]
            f = hforce[i]
            N["hmoment"][i] = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
        else:
            N["hmoment"][i] = [0.0, 0.0, 0.0]


def _random_case(seed):
    rng = np.random.default_rng(seed)
    n = 9
    pos = np.cumsum(rng.uniform(0.3, 0.6, (n, 3)), axis=0)
    N = {"pos": pos, "vel": rng.normal(0, 1e-3, (n, 3)), "disp": np.zeros((n, 3)),
         "mass": rng.uniform(0, 2, n), "host": np.array([0, 0, 1, 1, -1, 0, 1, -1, 1], np.int64),
         "hpos": pos + rng.normal(0, 1e-3, (n, 3)), "fix": np.array([1, 0, 0, 7, 0, 0, 2, 0, 0], np.uint8),
         "fapp": rng.normal(0, 100, (n, 3)), "conf": rng.uniform(-1e5, 1e6, n), "force": rng.normal(0, 50, (n, 3)),
         "hforce": np.zeros((n, 3)), "hmoment": np.zeros((n, 3)), "imass": np.zeros(n),
         "hz": np.array([0, 1, 0, 0, 0, 0, 1, 0, 0], np.int8), "hvel": rng.normal(0, 1e-3, (n, 3))}
    s = n - 1
    prop = np.column_stack([rng.uniform(1e9, 2e9, s), rng.uniform(1e-4, 2e-4, s), rng.choice([0.0, 5e3], s),
                            rng.choice([0.0, 4e3], s), rng.uniform(1e6, 1e7, s), rng.uniform(1e3, 5e3, s),
                            rng.uniform(0, 0.6, s), rng.uniform(0.01, 0.05, s), rng.uniform(0, 8000, s),
                            np.zeros(s)])
    # rupture: element 4 is past its limit at once, element 6 was broken before, element 1 never breaks
    prop[4, 9] = 1e-6
    prop[6, 9] = 0.5
    prop[1, 9] = 10.0
    l0 = np.linalg.norm(pos[1:] - pos[:-1], axis=1) * rng.uniform(0.99, 1.01, s)
    l0[4] *= 0.97                                   # (stretched 2 % at least: past its 1e-6)
    S = {"na": np.arange(s, dtype=np.int64), "nb": np.arange(1, n, dtype=np.int64), "l0": l0,
         "lcur": l0 * rng.uniform(0.999, 1.001, s), "prop": prop, "fa": rng.normal(0, 1e4, s),
         "gf": rng.normal(0, 10, (s, 2)), "state": np.array([0, 0, 0, 0, 0, 0, 32 | 8, 0], np.int32),
         "tapp": np.full(s, 5e3),
         "tact": np.array([0, 0, 1, 0, 0, 0, 0, 0], np.uint8)}
    B = {"vel": rng.normal(0, 1e-3, (2, 3)), "spin": rng.normal(0, 1e-2, (2, 3)), "cen": rng.normal(0, 1, (2, 3))}
    return N, S, B


@pytest.mark.parametrize("damp, safety", [(0, 0.5), (1, 0.5), (2, 0.5), (0, 0.0)])
def test_kernel_matches_twin(damp, safety):
    from dec3d.kernels.cable import cable_step, empty_scratch

    N, S, B = _random_case(7 + damp + int(10 * safety))
    tw = ({k: [list(r) if np.ndim(r) else r for r in v.tolist()] for k, v in N.items()},
          {k: [list(r) if np.ndim(r) else r for r in v.tolist()] for k, v in S.items()},
          {k: v.tolist() for k, v in B.items()})
    dt, g, alpha = 1e-3, np.array([0.0, 0.0, -9.81]), 0.8
    for _ in range(25):
        bad = cable_step(dt, g, alpha, damp, safety, N["pos"], N["vel"], N["disp"], N["mass"], N["host"], N["hpos"],
                         N["fix"], N["fapp"], N["conf"], N["force"], N["hforce"], N["hmoment"], N["imass"],
                         N["hz"], N["hvel"], S["na"], S["nb"], S["l0"], S["lcur"], S["prop"], S["fa"], S["gf"],
                         S["state"], S["tapp"], S["tact"], B["vel"], B["spin"], B["cen"], empty_scratch(len(N["pos"])))
        assert bad == 0
        twin_step(dt, [0.0, 0.0, -9.81], alpha, damp, safety, *tw)
    for k in ("pos", "vel", "disp", "hpos", "force", "hforce", "hmoment", "imass"):
        # (forces of ~1e4 N that nearly cancel at a node agree to round-off in N, not relatively)
        np.testing.assert_allclose(N[k], np.array(tw[0][k]), rtol=1e-10, atol=1e-8 if "force" in k else 1e-12,
                                   err_msg=k)
    for k in ("fa", "gf", "lcur"):
        np.testing.assert_allclose(S[k], np.array(tw[1][k]), rtol=1e-10, atol=1e-9, err_msg=k)
    assert S["state"].tolist() == tw[1]["state"]
    assert (S["state"] & 16).any() and (S["state"] & 8).any()   # grout slipped and an element yielded
    assert (S["state"] & 32).nonzero()[0].tolist() == [4, 6]     # two broken elements, carrying nothing
    assert not S["fa"][[4, 6]].any() and not S["gf"][[4, 6]].any()


# ------------------------------------------------------------------ through the engine
def _session(tmp_path):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    return s


def _run(s, text):
    s.run_items(s.load_text(text))
    return s


HANG = """model new
block create brick -0.5 0.5 -0.5 0.5 -1 0
block property density 2000
model gravity 0 0 -10
structure cable create by-line 0 0 -0.9 0 0 2 segments 29
structure cable property young 200e9 cross-sectional-area 1e-4 grout-stiffness 1e8 grout-cohesion 1e9
structure node fix velocity range id 30
"""


def test_block_hangs_on_its_cable(tmp_path):
    """A 1 m³ block (20 kN) without contacts hangs on a cable grouted through it, fixed at its top
    node: the elements above the block carry the weight, the block's moment stays nil."""
    s = _run(_session(tmp_path), HANG + "model cycle 4000\n")
    nodes, segs = s.model.stores["cable_nodes"], s.model.stores["cable_segments"]
    top = segs["fa"][segs["nb"] == np.flatnonzero(nodes["id"] == 30)[0]][0]
    assert top == pytest.approx(20000.0, rel=1e-3)
    assert abs(s.model.blocks["velocity"][0]).max() < 1e-4
    # the block's applied force is the grout's pull, the weight balanced
    assert s.model.blocks["fapp"][0, 2] == pytest.approx(20000.0, rel=1e-3)
    assert abs(s.model.blocks["mapp"][0]).max() < 1e-6


def test_pretension_is_held(tmp_path):
    s = _run(_session(tmp_path), HANG + "structure cable apply tension value 3e4 range id 29\nmodel cycle 50\n")
    segs = s.model.stores["cable_segments"]
    assert segs["fa"][segs["id"] == 29][0] == 3e4
    _run(s, "structure cable apply tension active off\nmodel cycle 1\n")
    assert segs["tact"].sum() == 0


def test_save_restore_continues_the_same_run(tmp_path):
    a = _run(_session(tmp_path), HANG + "model cycle 300\n")
    path = tmp_path / "c.sav"
    _run(a, f"model save '{path}'\nmodel cycle 200\n")
    b = _run(_session(tmp_path), f"model restore '{path}'\nmodel cycle 200\n")
    for k in ("fa", "gf"):
        np.testing.assert_array_equal(a.model.stores["cable_segments"][k], b.model.stores["cable_segments"][k])
    np.testing.assert_array_equal(a.model.stores["cable_nodes"]["pos"], b.model.stores["cable_nodes"]["pos"])
    np.testing.assert_array_equal(a.model.blocks["centroid"], b.model.blocks["centroid"])


@pytest.mark.parametrize("line, where, what", [
    ("structure cable create by-line 0 0 0 1 0 0 segments 0", " 0", "segments"),
    ("structure cable property young -1", "-1", "young"),
    ("structure cable property grout-cohesion -5 range id 1", "-5", "grout-cohesion"),
])
def test_bad_values_refused_at_their_column(tmp_path, line, where, what):
    s = _run(_session(tmp_path), HANG)
    with pytest.raises(Dec3dError) as exc:
        _run(s, line + "\n")
    assert exc.value.location is not None and exc.value.location.line == 1
    assert exc.value.location.column == line.rindex(where) + 1 + (where[0] == " "), exc.value.format()
    assert what in exc.value.format()


def test_cable_in_no_block_is_refused(tmp_path):
    s = _run(_session(tmp_path), HANG)
    with pytest.raises(Dec3dError, match="lies in no block") as exc:
        _run(s, "structure cable create by-line 5 5 5 6 6 6 segments 3\n")
    assert exc.value.location.line == 1
    assert s.model.stores["cable_segments"].n == 29       # nothing was added


def test_no_cable_no_property(tmp_path):
    s = _run(_session(tmp_path), "model new\nblock create brick 0 1 0 1 0 1\n")
    with pytest.raises(Dec3dError, match="there is no cable"):
        _run(s, "structure cable property young 1e9\n")


def test_deleted_host_leaves_no_grout(tmp_path):
    s = _run(_session(tmp_path), HANG + "model cycle 20\nblock delete\nmodel cycle 20\n")
    assert "notice: 10 cable node(s) lay in the deleted blocks" in s.stdout.getvalue()
    segs = s.model.stores["cable_segments"]
    assert (s.model.stores["cable_nodes"]["host"] == -1).all()
    assert not segs["gf"].any() and np.isfinite(segs["fa"]).all()


def test_block_vtk_writes_the_cables_as_lines(tmp_path):
    meshio = pytest.importorskip("meshio")
    s = _run(_session(tmp_path), HANG + "model cycle 200\nblock vtk 'hang'\n")
    m = meshio.read(tmp_path / "hang_cables_0000.vtu")
    assert m.cells[0].type == "line" and m.cells[0].data.shape == (29, 2)
    segs = s.model.stores["cable_segments"]
    np.testing.assert_array_equal(m.cell_data["axial_force"][0], segs["fa"])
    assert m.point_data["grouted"].sum() == 10          # the nodes at z = -0.9 … 0 lie in the block
    assert "hang_cables_0000.vtu" in (tmp_path / "hang.pvd").read_text()


def test_cable_histories_sample_and_survive_save(tmp_path):
    text = HANG + ("structure cable history name 'top' force component-id 29\n"
                   "structure node history name 'uz' displacement-z position 0 0 -0.9\n"
                   "history interval 100\nmodel cycle 1000\n")
    s = _run(_session(tmp_path), text)
    from dec3d.physics.history import histories
    hs = histories(s.model)
    top, uz = hs.find("top"), hs.find("uz")
    assert len(top.values) == 10 and top.values[-1] == s.model.stores["cable_segments"]["fa"][28]
    assert uz.values[-1] == s.model.stores["cable_nodes"]["disp"][0, 2] < 0
    _run(s, f"model save '{tmp_path / 'h.sav'}'\n")
    b = _run(_session(tmp_path), f"model restore '{tmp_path / 'h.sav'}'\nmodel cycle 100\n")
    assert len(histories(b.model).find("top").values) == 11
    with pytest.raises(Dec3dError, match="no cable element with id 99"):
        _run(b, "structure cable history force component-id 99\n")


def test_undamped_run_needs_a_cable_density_and_the_cable_bounds_the_step(tmp_path):
    s = _run(_session(tmp_path), HANG + "block mechanical damping none\n")
    with pytest.raises(Dec3dError, match="cable has no density"):
        _run(s, "model cycle 1\n")
    _run(s, "structure cable property density 7800\nmodel cycle 10\n")
    from dec3d.physics.cables import cable_timestep
    # the nodes' real masses: 2 s √(m / R) for the stiffest node, below the block's own step
    assert s.model.rigid_engine.dt <= cable_timestep(s.model) < 1e-4
    nodes = s.model.stores["cable_nodes"]
    np.testing.assert_allclose(nodes["imass"], nodes["mass"])


def test_zoned_block_hangs_on_its_cable(tmp_path):
    """The same hanging block, zoned: the nodes follow their zones, the grout's pull goes to the
    gridpoints, and the elements above the block carry its weight (20 kN)."""
    text = HANG.replace("block property density 2000\n",
                        "block zone generate edgelength 0.5\nblock zone cmodel assign elastic\n"
                        "block zone property young 10e9 poisson 0.25 density 2000\n")
    s = _run(_session(tmp_path), text + "model cycle 12000\n")
    nodes, segs = s.model.stores["cable_nodes"], s.model.stores["cable_segments"]
    assert nodes["hz"].sum() == 10 and (nodes["hw"][nodes["hz"] == 1] >= 0).all()
    top = segs["fa"][segs["nb"] == np.flatnonzero(nodes["id"] == 30)[0]][0]
    # (the long free chain above the block, density-scaled, settles slowly: 0.5 % left after 12 000 steps)
    assert top == pytest.approx(20000.0, rel=1e-2)
    v = s.model.vertices
    assert v["fapp"][:, 2].sum() == pytest.approx(top, rel=1e-3)    # the grout's pull is on the gridpoints
    assert abs(v["velocity"]).max() < 1e-6


# ------------------------------------------------------------------ rupture (tensile-failure-strain)
PULL = """model new
block create brick -0.5 0.5 -0.5 0.5 -1 0
block property density 2000
block fix
structure cable create by-line -0.4 0 -0.5 1.6 0 -0.5 segments 4
structure cable property young 200e9 cross-sectional-area 1e-4 grout-stiffness 0 tensile-failure-strain 0.01
structure node fix velocity range id 1
structure node fix velocity range id 5
structure node initialize velocity-x 2e-2 range id 5
"""


def _pull_until_rupture(s, steps=3000):
    """Cycle one step at a time until an element ruptures; (elongation of the 2 m bar the step saw,
    axial forces one step before)."""
    nodes, segs = s.model.stores["cable_nodes"], s.model.stores["cable_segments"]
    for _ in range(steps):
        before = segs["fa"].copy()
        elong = nodes["pos"][4, 0] - nodes["pos"][0, 0] - 2.0      # (the kernel's forces are at the step's start)
        _run(s, "model cycle 1\n")
        if (segs["state"] & 32).any():
            return elong, before
    raise AssertionError("no rupture")


@pytest.mark.parametrize("yield_t, peak", [(0.0, 200e9 * 1e-4 * 0.01), (1.5e5, 1.5e5)])
def test_pulled_cable_ruptures_at_its_strain_limit(tmp_path, yield_t, peak):
    """A 2 m bar (EA = 2e7 N, 4 elements) pulled at one end at 2e-5 m a step: by hand it breaks when its
    elongation passes ε_r L = 0.01 × 2 m = 0.02 m, with E A ε_r = 2e5 N (elastic) or the yield force
    1.5e5 N (yielded since ε = 0.0075) in it just before; after, the elements carry nothing."""
    s = _run(_session(tmp_path), PULL + f"structure cable property yield-tension {yield_t}\n")
    elong, before = _pull_until_rupture(s)
    assert 0.02 < elong <= 0.02 + 2e-5 + 1e-12          # the first step past the limit
    np.testing.assert_allclose(before, peak, rtol=1e-6)
    segs = s.model.stores["cable_segments"]
    assert (segs["state"] & 32).all() and not segs["fa"].any() and not segs["gf"].any()
    _run(s, "model cycle 10\nstructure cable list\n")
    assert not segs["fa"].any()                           # and for good
    assert s.stdout.getvalue().count("ruptured") == 4


def test_the_weakest_element_breaks_and_the_rest_unload(tmp_path):
    """Element 2 with half the limit breaks alone at 0.005 × 2 m = 0.01 m of elongation (all four are
    equally stretched); the pull stopped, the others come back to no force; VTK, FISH and a restored
    save show the rupture."""
    s = _run(_session(tmp_path), PULL + "structure cable property tensile-failure-strain 0.005 range id 2\n")
    elong, before = _pull_until_rupture(s)
    assert 0.01 < elong <= 0.01 + 2e-5 + 1e-12
    np.testing.assert_allclose(before, 2e7 * 0.005, rtol=1e-6)
    segs = s.model.stores["cable_segments"]
    assert (segs["state"] & 32).tolist() == [0, 32, 0, 0]
    _run(s, "structure node initialize velocity-x 0 range id 5\nmodel cycle 3000\n")
    assert abs(segs["fa"]).max() < 1e-3 * 1e5            # the broken bar rests: nothing left in it
    _run(s, "[st = struct.cable.state(2)]\n[s1 = struct.cable.state(1)]\n")
    assert s.variables["st"] & 32 and not s.variables["s1"] & 32
    meshio = pytest.importorskip("meshio")
    _run(s, "block vtk 'pull'\n")
    m = meshio.read(tmp_path / "pull_cables_0000.vtu")
    assert m.cell_data["ruptured"][0].tolist() == [0, 1, 0, 0]
    _run(s, f"model save '{tmp_path / 'r.sav'}'\n")
    b = _run(_session(tmp_path), f"model restore '{tmp_path / 'r.sav'}'\nmodel cycle 5\n")
    bs = b.model.stores["cable_segments"]
    assert (bs["state"] & 32).tolist() == [0, 32, 0, 0] and bs["fa"][1] == 0.0
    assert bs["prop"][1, 9] == 0.005


def test_hybrid_bolt_takes_the_strain_limit(tmp_path):
    s = _run(_session(tmp_path), PULL.replace("structure cable create", "structure hybrid create")
             .replace("structure cable property", "structure hybrid property"))
    assert (s.model.stores["cable_segments"]["prop"][:, 9] == 0.01).all()
    with pytest.raises(Dec3dError) as exc:
        _run(s, "structure cable property tensile-failure-strain -0.1\n")
    assert exc.value.location.column == len("structure cable property tensile-failure-strain ") + 1


# ------------------------------------------------------------------ excavation, dynamic mode
def test_excavated_zoned_host_frees_its_nodes_once(tmp_path):
    """`block excavate` of the zoned block a cable is grouted in: its 10 nodes are reported once, carry
    no grout force from then on (never a NaN), and the grout's pull is taken back off the gridpoints."""
    text = HANG.replace("block property density 2000\n",
                        "block zone generate edgelength 0.5\nblock zone cmodel assign elastic\n"
                        "block zone property young 10e9 poisson 0.25 density 2000\n")
    s = _run(_session(tmp_path), text + "model cycle 300\n")
    v = s.model.vertices
    assert abs(v["fapp"][:, 2].sum()) > 100                 # the grout pulls on the gridpoints
    _run(s, "block excavate\nmodel cycle 200\nmodel cycle 200\n")
    out = s.stdout.getvalue()
    assert out.count("10 cable node(s) lay in the excavated blocks") == 1
    nodes, segs = s.model.stores["cable_nodes"], s.model.stores["cable_segments"]
    assert (nodes["host"] == -1).all() and not nodes["hz"].any() and not nodes["hforce"].any()
    assert not segs["gf"].any() and np.isfinite(segs["fa"]).all() and np.isfinite(nodes["pos"]).all()
    assert abs(v["fapp"]).max() < 1e-6                       # nothing left behind for a later fill


def test_undamped_dynamic_bar_overshoots_twice_its_static_stretch(tmp_path):
    """Dynamic mode, real masses: a 2 m bar (grout-free, EA = 2e7 N, ρ = 7800) fixed at one end, loaded at
    once by 1e4 N at the other swings between 0 and twice F L / EA = 1e-3 m (undamped: dynamic factor 2),
    with the period of its first axial mode, 4 L / √(E/ρ) = 1.580 ms (20 lumped elements: within 1 %)."""
    s = _run(_session(tmp_path), """model new
block create brick -0.5 0.5 -0.5 0.5 -1 0
block property density 2000
block fix
model dynamic active on
structure cable create by-line 0 0 -0.5 2 0 -0.5 segments 20
structure cable property young 200e9 cross-sectional-area 1e-4 grout-stiffness 0 density 7800
structure node fix velocity range id 1
structure node apply force-x 1e4 range id 21
structure node history name 'u' displacement-x component-id 21
history interval 1
model solve time 3.3e-3
""")
    h = s.model.history_set.find("u")
    t, u = np.array(h.times), np.array(h.values)
    assert u.max() == pytest.approx(2 * 1e4 * 2.0 / 2e7, rel=0.02) and u.min() > -1e-6
    up = np.flatnonzero((u[:-1] < 5e-4) & (u[1:] >= 5e-4))      # crossings of the static stretch, rising
    assert len(up) == 2
    assert t[up[1]] - t[up[0]] == pytest.approx(4 * 2.0 / np.sqrt(200e9 / 7800), rel=0.01)


def test_a_save_without_the_strain_limit_column_reads_as_never_rupturing(tmp_path):
    """Files written before `tensile-failure-strain` hold nine property columns: restored, the tenth
    reads 0 (never ruptures) and the cable cycles as before."""
    from dec3d.model.cables import cable_stores

    s = _run(_session(tmp_path), HANG)
    segs = s.model.stores["cable_segments"]
    old = segs["prop"][:, :9].copy()
    segs.resize_field("prop", (9,))
    _, segs = cable_stores(s.model)
    assert segs["prop"].shape[1] == 10 and not segs["prop"][:, 9].any()
    np.testing.assert_array_equal(segs["prop"][:, :9], old)
    _run(s, "model cycle 20\n")
    assert not (segs["state"] & 32).any()
