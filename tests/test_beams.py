"""Beam structural elements (issue 28, part 3): the step kernel against a plain-Python twin, a
cantilever and a beam linked to a block through the engine, save/restore, VTK, histories, bad input.

The twin writes the Euler-Bernoulli end forces out term by term (axial EA/L (u_b − u_a), torsion
GJ/L (θ_b − θ_a), the shear and moment of the two bending planes from the slope-deflection
equations), in the element's axes, and moves the nodes with the same central-difference law,
sharing no code or constants with ``dec3d.kernels.beam``."""
from __future__ import annotations

import io

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.session import Session


def _sg(x):
    return (x > 0) - (x < 0)


def end_forces(E, nu, A, Iy, Iz, J, L, d):
    """Element end forces from the slope-deflection equations; d = (u, v, w, θx, θy, θz) at a and b."""
    ua, va, wa, txa, tya, tza, ub, vb, wb, txb, tyb, tzb = d
    G = E / 2 / (1 + nu)
    N = E * A / L * (ub - ua)
    T = G * J / L * (txb - txa)
    # x-y plane: deflection v, slope θz = dv/dx
    Mza = E * Iz / L * (4 * tza + 2 * tzb) + 6 * E * Iz / L ** 2 * (va - vb)
    Mzb = E * Iz / L * (2 * tza + 4 * tzb) + 6 * E * Iz / L ** 2 * (va - vb)
    Vy = (Mza + Mzb) / L
    # x-z plane: deflection w, slope −θy = dw/dx
    Mya = E * Iy / L * (4 * tya + 2 * tyb) - 6 * E * Iy / L ** 2 * (wa - wb)
    Myb = E * Iy / L * (2 * tya + 4 * tyb) - 6 * E * Iy / L ** 2 * (wa - wb)
    Vz = -(Mya + Myb) / L
    return [-N, Vy, Vz, -T, Mya, Mza, N, -Vy, -Vz, T, Myb, Mzb]


def twin_step(dt, g, alpha, damp, safety, N, S, B, last):
    n = len(N["pos"])
    F = [[0.0] * 3 for _ in range(n)]
    M = [[0.0] * 3 for _ in range(n)]
    for i in range(n):
        last[i] = list(N["force"][i]) + list(N["moment"][i])
        N["hforce"][i] = [0.0] * 3
        N["hmoment"][i] = [0.0] * 3
        h = N["host"][i]
        if h < 0:
            continue
        if N["hz"][i]:
            N["lf"][i] = [N["lf"][i][k] - N["klt"][i] * (N["vel"][i][k] - N["hvel"][i][k]) * dt for k in range(3)]
            F[i] = list(N["lf"][i])
            N["hforce"][i] = [-x for x in N["lf"][i]]
            continue
        c0 = [B["cen"][h][k] - B["vel"][h][k] * dt for k in range(3)]
        r = [N["hpos"][i][k] - c0[k] for k in range(3)]
        w = B["spin"][h]
        vh = [B["vel"][h][0] + w[1] * r[2] - w[2] * r[1], B["vel"][h][1] + w[2] * r[0] - w[0] * r[2],
              B["vel"][h][2] + w[0] * r[1] - w[1] * r[0]]
        N["hpos"][i] = [N["hpos"][i][k] + vh[k] * dt for k in range(3)]
        N["lf"][i] = [N["lf"][i][k] - N["klt"][i] * (N["vel"][i][k] - vh[k]) * dt for k in range(3)]
        N["lm"][i] = [N["lm"][i][k] - N["klr"][i] * (N["avel"][i][k] - w[k]) * dt for k in range(3)]
        F[i] = list(N["lf"][i])
        M[i] = list(N["lm"][i])
        hf = [-x for x in N["lf"][i]]
        N["hforce"][i] = hf
        r = [N["hpos"][i][k] - B["cen"][h][k] for k in range(3)]
        N["hmoment"][i] = [r[1] * hf[2] - r[2] * hf[1] - N["lm"][i][0], r[2] * hf[0] - r[0] * hf[2] - N["lm"][i][1],
                           r[0] * hf[1] - r[1] * hf[0] - N["lm"][i][2]]
    for e in range(len(S["na"])):
        a, b = S["na"][e], S["nb"][e]
        R = S["axes"][e]
        dloc = []
        for vec in (N["disp"][a], N["rot"][a], N["disp"][b], N["rot"][b]):
            dloc += [sum(R[p][q] * vec[q] for q in range(3)) for p in range(3)]
        fl = end_forces(*S["prop"][e][:6], S["l0"][e], dloc)
        S["fl"][e] = fl
        for node, off in ((a, 0), (b, 6)):
            for k in range(3):
                F[node][k] -= sum(R[p][k] * fl[off + p] for p in range(3))
                M[node][k] -= sum(R[p][k] * fl[off + 3 + p] for p in range(3))
    q = (dt / 2 / safety) ** 2 if safety > 0 else 0.0
    for i in range(n):
        m = max(N["mass"][i], N["rt"][i] * q) if safety > 0 else N["mass"][i]
        ri = max(N["inert"][i], N["rr"][i] * q) if safety > 0 else N["inert"][i]
        m = m if m > 0 else 1.0
        ri = ri if ri > 0 else 1.0
        N["imass"][i], N["iinert"][i] = m, ri
        for k in range(3):
            f = F[i][k] + N["fapp"][i][k] + N["mass"][i] * g[k]
            mo = M[i][k] + N["mapp"][i][k]
            N["force"][i][k], N["moment"][i][k] = f, mo
            for val, inertia, key, bit, lastv in ((f, m, "vel", k, last[i][k]),
                                                  (mo, ri, "avel", 3 + k, last[i][3 + k])):
                if (N["fix"][i] >> bit) & 1:
                    continue
                v = N[key][i][k]
                if damp == 2:
                    val = val - 0.5 * alpha * abs(val) * (_sg(v) - _sg(val - lastv))
                N[key][i][k] = v + val / inertia * dt
        for k in range(3):
            N["pos"][i][k] += N["vel"][i][k] * dt
            N["disp"][i][k] += N["vel"][i][k] * dt
            N["rot"][i][k] += N["avel"][i][k] * dt


def _case(seed):
    rng = np.random.default_rng(seed)
    n = 6
    pos = np.cumsum(rng.uniform(0.3, 0.6, (n, 3)), axis=0)
    N = {"pos": pos, "vel": rng.normal(0, 1e-3, (n, 3)), "disp": rng.normal(0, 1e-4, (n, 3)),
         "rot": rng.normal(0, 1e-4, (n, 3)), "avel": rng.normal(0, 1e-3, (n, 3)), "mass": rng.uniform(1, 3, n),
         "inert": rng.uniform(0.01, 0.1, n), "rt": rng.uniform(1e7, 1e8, n), "rr": rng.uniform(1e5, 1e6, n),
         "host": np.array([0, -1, -1, 1, -1, 0], np.int64), "hz": np.array([0, 0, 0, 0, 0, 1], np.int8),
         "hvel": rng.normal(0, 1e-3, (n, 3)), "hpos": pos + rng.normal(0, 1e-3, (n, 3)),
         "klt": rng.uniform(1e6, 1e7, n), "klr": rng.uniform(1e4, 1e5, n), "lf": rng.normal(0, 10, (n, 3)),
         "lm": rng.normal(0, 1, (n, 3)), "fix": np.array([0, 7, 56, 0, 9, 0], np.uint8),
         "fapp": rng.normal(0, 10, (n, 3)), "mapp": rng.normal(0, 1, (n, 3)), "force": rng.normal(0, 5, (n, 3)),
         "moment": rng.normal(0, 1, (n, 3)), "hforce": np.zeros((n, 3)), "hmoment": np.zeros((n, 3)),
         "imass": np.zeros(n), "iinert": np.zeros(n)}
    s = n - 1
    axes = []
    for e in range(s):
        x = pos[e + 1] - pos[e]
        x /= np.linalg.norm(x)
        y = np.cross(rng.normal(size=3), x)
        y /= np.linalg.norm(y)
        axes.append([x, y, np.cross(x, y)])
    S = {"na": np.arange(s, dtype=np.int64), "nb": np.arange(1, n, dtype=np.int64),
         "l0": np.linalg.norm(pos[1:] - pos[:-1], axis=1),
         "prop": np.column_stack([rng.uniform(1e10, 2e10, s), rng.uniform(0.1, 0.4, s), rng.uniform(1e-3, 2e-3, s),
                                  rng.uniform(1e-7, 2e-7, s), rng.uniform(1e-7, 3e-7, s), rng.uniform(2e-7, 4e-7, s),
                                  np.full(s, 7800.0)]),
         "axes": np.array(axes), "fl": np.zeros((s, 12))}
    B = {"vel": rng.normal(0, 1e-3, (2, 3)), "spin": rng.normal(0, 1e-2, (2, 3)), "cen": rng.normal(0, 1, (2, 3))}
    return N, S, B


@pytest.mark.parametrize("damp, safety", [(0, 0.5), (2, 0.5), (0, 0.0)])
def test_kernel_matches_twin(damp, safety):
    from dec3d.kernels.beam import beam_step

    N, S, B = _case(11 + damp)
    tw = [{k: [list(r) if np.ndim(r) else r for r in v.tolist()] for k, v in D.items()} for D in (N, S)]
    tb = {k: v.tolist() for k, v in B.items()}
    last = np.zeros((len(N["pos"]), 6))
    tlast = [[0.0] * 6 for _ in range(len(N["pos"]))]
    dt, g, alpha = 1e-4, np.array([0.0, 0.0, -9.81]), 0.8
    K = dict(N)             # the kernel takes a row sum per degree of freedom (a beam node's three are equal)
    K["rt"], K["rr"] = np.repeat(N["rt"][:, None], 3, axis=1), np.repeat(N["rr"][:, None], 3, axis=1)
    for _ in range(20):
        bad = beam_step(dt, g, alpha, damp, safety, *(K[k] for k in (
            "pos", "vel", "disp", "rot", "avel", "mass", "inert", "rt", "rr", "host", "hz", "hvel", "hpos",
            "klt", "klr", "lf", "lm", "fix", "fapp", "mapp", "force", "moment", "hforce", "hmoment", "imass", "iinert")),
            S["na"], S["nb"], S["l0"], S["prop"], S["axes"], S["fl"], B["vel"], B["spin"], B["cen"], last)
        assert bad == 0
        twin_step(dt, [0.0, 0.0, -9.81], alpha, damp, safety, tw[0], tw[1], tb, tlast)
    for k in ("pos", "vel", "rot", "avel", "force", "moment", "hforce", "hmoment", "lf", "lm", "imass", "iinert"):
        np.testing.assert_allclose(N[k], np.array(tw[0][k]), rtol=1e-9, atol=1e-12, err_msg=k)
    np.testing.assert_allclose(S["fl"], np.array(tw[1]["fl"]), rtol=1e-9, atol=1e-9)
    assert abs(S["fl"]).max() > 1.0


# ------------------------------------------------------------------ through the engine
CANTI = """model new
block create brick 10 11 10 11 10 11
block property density 2000
block fix
structure beam create by-line 0 0 0 2 0 0 segments 10
structure beam property young 200e9 poisson 0.3 cross-sectional-area 1e-3 moi-y 1e-6 moi-z 4e-6 moi-polar 2e-6
structure node fix velocity rotation range id 1
"""


def _run(text, tmp_path, s=None):
    s = s or Session(out_dir=tmp_path, stdout=io.StringIO())
    s.run_items(s.load_text(text))
    return s


def test_cantilever_bends_about_both_axes_and_twists(tmp_path):
    """Tip load P = 100 N along z and y and a torque T = 50 N·m: w = P L³ / 3 E I_y, v = P L³ / 3 E I_z,
    twist T L / G J (small-displacement closed forms, exact at the nodes of cubic elements)."""
    s = _run(CANTI + "structure node apply force 0 100 -100 moment-x 50 range id 11\nmodel solve ratio 1e-6\n",
             tmp_path)
    n = s.model.stores["beam_nodes"]
    tip = np.flatnonzero(n["id"] == 11)[0]
    E, G, L = 200e9, 200e9 / 2.6, 2.0
    assert n["disp"][tip, 2] == pytest.approx(-100 * L ** 3 / (3 * E * 1e-6), rel=1e-3)
    assert n["disp"][tip, 1] == pytest.approx(100 * L ** 3 / (3 * E * 4e-6), rel=1e-3)
    assert n["rot"][tip, 0] == pytest.approx(50 * L / (G * 2e-6), rel=1e-3)
    els = s.model.stores["beam_elements"]
    assert els["fl"][0, 4] == pytest.approx(-100 * L, rel=1e-3)       # root moment about y: P L


def test_beam_linked_to_a_block_carries_it(tmp_path):
    """A 1 m³ block (20 kN) hangs on a vertical beam through it, fixed at its top: the beam's axial
    force above the block is the weight, and the block comes to rest."""
    s = _run(HANG + "model cycle 3000\n", tmp_path)
    els = s.model.stores["beam_elements"]
    assert els["fl"][-1, 6] == pytest.approx(20000.0, rel=2e-3)
    assert abs(s.model.blocks["velocity"][0]).max() < 1e-4
    assert abs(s.model.blocks["mapp"][0]).max() < 1.0


HANG = """model new
block create brick -0.5 0.5 -0.5 0.5 -1 0
block property density 2000
model gravity 0 0 -10
structure beam create by-line 0 0 -0.9 0 0 2 segments 29
structure beam property young 200e9 poisson 0.3 cross-sectional-area 1e-3 moi-y 1e-7 moi-z 1e-7 moi-polar 2e-7
structure node fix velocity rotation range id 30
"""


def test_beam_linked_to_a_zoned_block_carries_it(tmp_path):
    """The same hanging block, zoned: the nodes inside follow their zones (translational links), whose
    gridpoints take the links' pull, and the beam above the block carries its weight."""
    text = HANG.replace("block property density 2000\n",
                        "block zone generate edgelength 0.5\nblock zone cmodel assign elastic\n"
                        "block zone property young 10e9 poisson 0.25 density 2000\n")
    s = _run(text + "model solve ratio 1e-6\n", tmp_path)
    nodes, els = s.model.stores["beam_nodes"], s.model.stores["beam_elements"]
    assert nodes["hz"].sum() == 10 and (nodes["hw"][nodes["hz"] == 1] >= 0).all()
    assert els["fl"][-1, 6] == pytest.approx(20000.0, rel=5e-3)
    v = s.model.vertices
    assert v["fapp"][:, 2].sum() == pytest.approx(els["fl"][-1, 6], rel=5e-3)
    _run("block delete\nmodel cycle 5\n", tmp_path, s)
    assert (nodes["host"] == -1).all() and not nodes["lf"].any()


def test_save_restore_vtk_history_fish(tmp_path):
    meshio = pytest.importorskip("meshio")
    text = CANTI + ("structure node apply force-z -100 range id 11\nstructure beam history name 'm1' moment-y "
                    "component-id 1\nstructure node history displacement-z component-id 11\nhistory interval 10\n"
                    "model cycle 300\n")
    a = _run(text, tmp_path)
    p = tmp_path / "b.sav"
    _run(f"model save '{p}'\nmodel cycle 200\nblock vtk 'bm'\n", tmp_path, a)
    b = _run(f"model restore '{p}'\nmodel cycle 200\n[x = struct.beam.moment(1, 1)]\n[w = struct.node.disp(11)]\n",
             tmp_path)
    np.testing.assert_array_equal(a.model.stores["beam_elements"]["fl"], b.model.stores["beam_elements"]["fl"])
    np.testing.assert_array_equal(a.model.stores["beam_nodes"]["rot"], b.model.stores["beam_nodes"]["rot"])
    hs = b.model.history_set
    assert len(hs.items) == 2 and hs.items[0].values[-1] == b.model.stores["beam_elements"]["fl"][0, 4]
    m = meshio.read(tmp_path / "bm_beams_0000.vtu")
    assert m.cells[0].type == "line" and m.cells[0].data.shape == (10, 2)
    np.testing.assert_array_equal(m.cell_data["moment_y_1"][0], a.model.stores["beam_elements"]["fl"][:, 4])


@pytest.mark.parametrize("line, where, what", [
    ("structure beam create by-line 0 0 0 1 0 0 segments 0", " 0", "segments"),
    ("structure beam property young -1", "-1", "young"),
    ("structure beam property moi-y -5 range id 1", "-5", "moi-y"),
])
def test_bad_values_refused_at_their_column(tmp_path, line, where, what):
    s = _run(CANTI, tmp_path)
    with pytest.raises(Dec3dError) as exc:
        _run(line + "\n", tmp_path, s)
    assert exc.value.location is not None and exc.value.location.line == 1
    assert exc.value.location.column == line.rindex(where) + 1 + (where[0] == " "), exc.value.format()
    assert what in exc.value.format()


def test_beam_without_section_is_refused_at_cycle(tmp_path):
    s = _run("model new\nblock create brick 0 1 0 1 0 1\nblock property density 1\n"
             "structure beam create by-line 0 0 2 1 0 2 segments 2\n", tmp_path)
    with pytest.raises(Dec3dError, match="lacks `young`"):
        _run("model cycle 1\n", tmp_path, s)


def test_dynamic_cantilever_vibrates_at_its_first_frequency(tmp_path):
    """Undamped (real masses: the beam bounds Δt), a tip load applied at once: the tip swings about the
    static deflection with the first period of the cantilever, 2π L² / (1.8751² √(E I / ρ A)) =
    0.044640 s (lumped masses on 8 elements and the nodes' rotary inertia make it 1.1 % longer; bar 2 %)."""
    from dec3d.physics.beams import beam_timestep

    s = _run("""model new
block create brick 10 11 10 11 10 11
block property density 2000
block fix
block mechanical damping none
structure beam create by-line 0 0 0 2 0 0 segments 8
structure beam property young 200e9 poisson 0.3 cross-sectional-area 1e-2 moi-y 1e-5 moi-z 1e-5 moi-polar 2e-5
structure node fix velocity rotation range id 1
structure node apply force-z -1000 range id 9
structure node history name 'w' displacement-z component-id 9
history interval 1
""", tmp_path)
    with pytest.raises(Dec3dError, match="beam has no density"):
        _run("model cycle 1\n", tmp_path, s)
    _run("structure beam property density 7800\nmodel solve time 0.07\n", tmp_path, s)
    assert s.model.rigid_engine.dt <= beam_timestep(s.model) < 1e-4
    h = s.model.history_set.items[0]
    t, y = np.array(h.times), np.array(h.values) + 1000 * 2.0 ** 3 / (3 * 200e9 * 1e-5)
    down = np.flatnonzero((y[:-1] > 0) & (y[1:] <= 0))
    tc = t[down] + (t[down + 1] - t[down]) * y[down] / (y[down] - y[down + 1])
    period = 2 * np.pi * 2.0 ** 2 / (1.875104 ** 2 * np.sqrt(200e9 * 1e-5 / (7800 * 1e-2)))
    assert len(tc) == 2 and tc[1] - tc[0] == pytest.approx(period, rel=0.02)
