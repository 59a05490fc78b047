"""Every deck in examples/ runs."""
import pytest

from conftest import ROOT
from dec3d.cli import main

# decks called by another example are run through their caller
# the slow decks whose own tests below run them through `dec3d run` as well are not run again here
RUN_BY_THEIR_TESTS = {"deformable/tunnel_mc.dat", "deformable/tunnel_jointed_mc.dat", "feblock/tunnel_liner.dat",
                      "support/bolted_tunnel.dat", "support/lined_tunnel.dat", "tutorial/tunnel.dat"}
EXAMPLES = sorted(p for p in (ROOT / "examples").rglob("*.dat")
                  if p.name != "settings.dat" and p.relative_to(ROOT / "examples").as_posix() not in RUN_BY_THEIR_TESTS)


def _cli_run(deck, out):
    assert main(["run", str(deck), "--out", str(out), "-q"]) == 0
    _check_pictures(out)


def _check_pictures(out):
    """Every picture an example writes shows something: more than 2 % of its pixels are not the
    background (the colour of its corner), and it has more than two colours."""
    import matplotlib.image as mpimg
    import numpy as np

    for png in sorted(out.rglob("*.png")):
        img = mpimg.imread(str(png))[:, :, :3]
        drawn = (np.abs(img - img[0, 0]).sum(axis=2) > 0.1).mean()
        assert drawn > 0.02, f"{png.name}: blank picture"
        assert len(np.unique(img.reshape(-1, 3), axis=0)) > 2, f"{png.name}: one colour"


def test_tutorial_pictures(tmp_path):
    """The tutorial decks write the pictures docs/tutorial.md shows; the tunnel's plastic-state picture
    shows yielded zones (colours of the legend besides `none`) and its vertical stress picture a range
    of colours."""
    import matplotlib.image as mpimg
    import numpy as np

    from dec3d.plot.render import STATE_COLOURS

    _cli_run(ROOT / "examples" / "tutorial" / "tunnel.dat", tmp_path)
    for name in ("tunnel_szz", "tunnel_state", "tunnel_displacement", "tunnel_joints"):
        assert (tmp_path / f"{name}.png").exists()
    img = (mpimg.imread(str(tmp_path / "tunnel_state.png"))[:, :, :3] * 255).round()
    yielded = [c for t, c in STATE_COLOURS.items() if t != "none"]
    hits = sum(int((np.abs(img - [int(c[i:i + 2], 16) for i in (1, 3, 5)]).sum(axis=2) < 10).sum()) for c in yielded)
    assert hits > 500


@pytest.mark.parametrize("deck", EXAMPLES, ids=lambda p: str(p.relative_to(ROOT / "examples")))
def test_example_runs(deck, tmp_path):
    _cli_run(deck, tmp_path)


def test_language_example_results(tmp_path):
    from dec3d.session import run_deck

    s = run_deck(ROOT / "examples" / "language" / "main.dat", out_dir=tmp_path)
    assert s.model.settings.gravity == (0.0, 0.0, -9.81)
    assert s.model.settings.title == "Language tour" and s.model.settings.configure == ["dynamic"]
    assert s.variables["rho"] == 2650.0 and "density_of_granite" in s.fish


def test_masonry_wall_holds_below_friction_and_slides_above(tmp_path):
    """The top course holds a push of 0.3 x its weight (tan 35° = 0.70) and slides under 0.9 x."""
    import numpy as np

    from dec3d.session import run_deck

    run_deck(ROOT / "examples" / "rigid" / "masonry_wall.dat", out_dir=tmp_path)
    data = np.genfromtxt(tmp_path / "top.csv", delimiter=",", names=True)
    step, ux = data[data.dtype.names[0]], data[data.dtype.names[-1]]
    push = step[0] + 2000                                  # the second push starts here
    held = ux[step <= push]
    assert np.abs(held).max() < 5e-5                       # elastic only: tens of µm
    assert ux[-1] > 2e-3 and np.all(np.diff(ux[step > push + 500]) > 0)   # sliding on
    assert (tmp_path / "wall.pvd").read_text().count("<DataSet") >= 10
    # the snapshots carry what moved: between two snapshots the point displacement grows by exactly
    # what the points moved, and the top course has slid (> 2 mm) in the last one
    import meshio

    first, last = (meshio.read(tmp_path / f"wall_{k:04d}.vtu") for k in (0, 20))
    du = last.point_data["displacement"] - first.point_data["displacement"]
    np.testing.assert_allclose(du, last.points - first.points, atol=1e-12)
    assert last.point_data["displacement"][:, 0].max() > 2e-3


def test_tunnel_mc_stages_show_the_plastic_zone(tmp_path):
    """examples/deformable/tunnel_mc.dat: the heading, the staged (heading + bench) and the
    full-face excavation each write their zones with the plastic state. The plastic zone is a ring
    about the tunnel (all of it within 2.5 radii, no tension yield at 0.5 MPa tensile strength once
    the bench is out),
    the zones that yielded at the heading stage are still marked after the bench (the past bits
    are kept through `model save`), and the full-face run, restored from the unexcavated state,
    ends with the same zones as the staged one and a plastic zone of about the same size."""
    import meshio
    import numpy as np

    _cli_run(ROOT / "examples" / "deformable" / "tunnel_mc.dat", tmp_path)
    assert all((tmp_path / f"{n}.sav").exists() for n in ("initial", "heading", "staged"))
    got = {}
    for name in ("heading", "staged", "full_face"):
        m = meshio.read(tmp_path / f"{name}_0000.vtu")
        state = np.concatenate(m.cell_data["plastic_state"])
        zid = np.concatenate(m.cell_data["zone_id"])
        c = np.concatenate([m.points[b.data].mean(axis=1) for b in m.cells])
        r = np.hypot(c[:, 0], c[:, 2])
        got[name] = (state, zid, c, r)
        assert (state != 0).sum() > 300 and r[state != 0].max() < 2.5
        if name != "heading":                  # (the heading's floor, the bench's top, may yield in tension)
            assert not (state & 10).any()
    s_h, id_h, c_h, r_h = got["heading"]
    assert ((r_h < 0.95) & (c_h[:, 2] < -0.05)).any() and not ((r_h < 0.95) & (c_h[:, 2] > 0.05)).any()
    s_s, id_s, _, r_s = got["staged"]
    assert r_s.min() > 0.95                                            # the bench is gone too
    yielded_then = set(id_h[s_h != 0]) & set(id_s)
    assert yielded_then and yielded_then <= set(id_s[s_s != 0])
    s_f, id_f, _, _ = got["full_face"]
    assert sorted(id_f) == sorted(id_s)
    assert abs(int((s_f != 0).sum()) - int((s_s != 0).sum())) < 0.2 * (s_s != 0).sum()


def test_tunnel_liner_carries_the_rest_of_the_load(tmp_path):
    """examples/feblock/tunnel_liner.dat (the FE-block text's tunnel liner): after the excavation
    with half its reaction kept and then released, the FE liner takes load from the rock: every
    liner-rock sub-contact is in compression or open (fn >= 0) and together they carry more than
    0.5 MN on the 2 m slice; the liner is squeezed (mean hoop stress compressive) and moves by a
    bounded, finite amount (0.05 to 2 mm: rock joints of 10 GPa/m under 2.7-5.4 MPa); the wedge over
    the crown has come down further once the liner was in (the rest of the load), and the roof
    history has stopped changing (last 10 % of the samples within 1 % of its final value). The
    blocks VTK carries the liner's node displacements. The deck is deterministic: a second run
    writes the same history file, byte for byte."""
    import csv

    import meshio
    import numpy as np

    from dec3d.model.model import KIND_FE
    from dec3d.session import run_deck

    deck = ROOT / "examples" / "feblock" / "tunnel_liner.dat"
    s = run_deck(deck, out_dir=tmp_path)
    m = s.model
    b, v = m.blocks, m.vertices
    fe = b["kind"] == KIND_FE
    assert fe.sum() == 16 and m.store("feblocks").n == 32
    cs, ss = m.store("contacts"), m.store("subcontacts")
    fe_of_id = {int(i): bool(f) for i, f in zip(b["id"], fe)}
    mixed = np.array([fe_of_id[int(a)] != fe_of_id[int(c)] for a, c in zip(cs["ida"], cs["idb"])])
    sub = mixed[ss["contact"]]
    assert sub.sum() > 100
    assert ss["fn"][sub].min() >= 0.0 and ss["fn"][sub].sum() > 0.5
    liner = fe[v["block"]] & v["zoned"]
    d = v["disp"][liner]
    assert np.isfinite(d).all() and 5e-5 < np.abs(d).max() < 2e-3
    es = m.store("feblocks")
    c = es["centroid"][: es.n]
    r = np.hypot(c[:, 0], c[:, 2])
    t = np.stack([-c[:, 2] / r, c[:, 0] / r], axis=1)        # hoop direction in x-z
    sxx, szz, sxz = es["stress"][: es.n, 0], es["stress"][: es.n, 2], es["stress"][: es.n, 4]
    hoop = t[:, 0] ** 2 * sxx + 2 * t[:, 0] * t[:, 1] * sxz + t[:, 1] ** 2 * szz
    assert hoop.mean() < -0.05                               # MPa, compression
    rows = list(csv.reader(open(tmp_path / "roof.csv")))
    step = np.array([int(x[0]) for x in rows[1:]])
    roof = np.array([float(x[2]) for x in rows[1:]])
    crown = np.array([float(x[3]) if x[3] else np.nan for x in rows[1:]])
    start = step[np.isfinite(crown)][0]                     # the liner goes in
    assert roof[-1] < 1.5 * roof[step < start][-1] < 0.0     # down, and further down with the liner
    tail = roof[int(0.9 * len(roof)):]
    assert np.abs(tail - roof[-1]).max() < 0.01 * abs(roof[-1])
    assert crown[-1] < 0 and np.isfinite(crown[step >= start]).all()
    vtk = meshio.read(tmp_path / "liner_0000.vtu")
    np.testing.assert_allclose(vtk.point_data["displacement"][liner], d)
    fevtk = meshio.read(tmp_path / "liner_fe_0000.vtu")      # the liner as quadratic hexahedra
    assert [cb.type for cb in fevtk.cells] == ["hexahedron20"] and len(fevtk.cells[0].data) == 32
    st = fevtk.cell_data["stress"][0]                        # XX YY ZZ XY YZ XZ, element means
    assert np.isfinite(st).all()
    cen = fevtk.points[fevtk.cells[0].data[:, :8]].mean(axis=1)
    rr = np.hypot(cen[:, 0], cen[:, 2])
    tt = np.stack([-cen[:, 2] / rr, cen[:, 0] / rr], axis=1)
    vhoop = tt[:, 0] ** 2 * st[:, 0] + 2 * tt[:, 0] * tt[:, 1] * st[:, 5] + tt[:, 1] ** 2 * st[:, 2]
    np.testing.assert_allclose(np.sort(vhoop), np.sort(hoop), rtol=1e-9, atol=1e-9)
    again = tmp_path / "again"
    _cli_run(deck, again)                                   # and as `dec3d run` runs it
    assert (again / "roof.csv").read_bytes() == (tmp_path / "roof.csv").read_bytes()


@pytest.fixture(scope="module")
def jointed_tunnel_runs(tmp_path_factory):
    """examples/deformable/tunnel_jointed_mc.dat run twice, each into its own folder (the first
    as `dec3d run` runs it)."""
    from dec3d.session import run_deck

    deck = ROOT / "examples" / "deformable" / "tunnel_jointed_mc.dat"
    outs = [tmp_path_factory.mktemp(f"tunnel_jointed_{k}") for k in range(2)]
    _cli_run(deck, outs[0])
    run_deck(deck, out_dir=outs[1])
    return outs


def _zones(path):
    """zone id -> (plastic state, distance of the centroid from the tunnel axis), and the mesh."""
    import meshio
    import numpy as np

    m = meshio.read(path)
    state = np.concatenate(m.cell_data["plastic_state"])
    zid = np.concatenate(m.cell_data["zone_id"])
    c = np.concatenate([m.points[b.data].mean(axis=1) for b in m.cells])
    return dict(zip(zid.tolist(), zip(state.tolist(), np.hypot(c[:, 0], c[:, 2]).tolist()))), m


def test_tunnel_jointed_mc_yields_slips_and_converges_like_kirsch(jointed_tunnel_runs):
    """examples/deformable/tunnel_jointed_mc.dat, each excavation stage against the saved initial state:
    zones yield around the opening (newly yielded zones within 2 radii) and none beyond 5 radii;
    joints slip near the opening (sub-contacts within 2 radii slipping, with shear displacements five
    times the initial ones, and those still slipping at the end all within 3 radii); the crown moves
    down by 1 to 10 times the elastic Kirsch convergence (plane strain, far field σh = 8 MPa across,
    σv = 12 MPa: u = a/(4G) [(σh + σv) − (σh − σv)(3 − 4ν)] = 2.56 mm: the jointed, yielding rock
    converges more); everything is finite, and two runs write
    the same bytes."""
    import meshio
    import numpy as np

    out, again = jointed_tunnel_runs
    files = sorted(p.name for p in out.iterdir())
    assert {"initial.sav", "heading.sav", "staged.sav", "full_face_contacts_0000.vtu"} <= set(files)
    for name in files:
        assert (out / name).read_bytes() == (again / name).read_bytes(), name
    K, G, a = 3.9e9, 2.8e9, 1.0
    nu = (3 * K - 2 * G) / (2 * (3 * K + G))
    kirsch = a / (4 * G) * ((8e6 + 12e6) - (8e6 - 12e6) * (3 - 4 * nu))
    assert kirsch == pytest.approx(2.56e-3, rel=0.01)
    init, m0 = _zones(out / "initial_0000.vtu")
    c0 = meshio.read(out / "initial_contacts_0000.vtu")
    r0 = np.hypot(c0.points[:, 0], c0.points[:, 2])
    us0 = c0.point_data["shear_displacement_magnitude"]
    crown = (np.abs(m0.points[:, 0]) < 1e-6) & (np.abs(m0.points[:, 2] - a) < 1e-6)
    assert crown.any()
    for stage in ("heading", "staged", "full_face"):
        zones, m = _zones(out / f"{stage}_0000.vtu")
        for arr in (*m.point_data.values(), *(np.concatenate(v) for v in m.cell_data.values())):
            assert np.all(np.isfinite(arr))
        new = np.array([r for z, (s, r) in zones.items() if s and not init[z][0]])
        assert (new < 2 * a).sum() > 100, stage
        far = np.array([r for z, (s, r) in zones.items() if r > 5 * a])
        assert far.size > 100 and not any(s for z, (s, r) in zones.items() if r > 5 * a), stage
        c = meshio.read(out / f"{stage}_contacts_0000.vtu")
        for arr in c.point_data.values():
            assert np.all(np.isfinite(arr))
        r = np.hypot(c.points[:, 0], c.points[:, 2])
        slip = c.point_data["slip"] != 0
        assert (slip & (r < 2 * a)).sum() > 20, stage
        # the joints still slipping at the end of the stage are those next to the opening (the
        # "failed" bit, in `slip`, is also left on joints farther out by the excavation's transient)
        now = (c.point_data["state"] & 2) != 0
        assert now.sum() > 10 and r[now].max() < 3 * a, stage
        us = c.point_data["shear_displacement_magnitude"]
        assert us[r < 2 * a].max() > 5 * us0[r0 < 2 * a].max(), stage
        # the same gridpoints (points are not renumbered by the excavation: match by position)
        p = m.points
        top = (np.abs(p[:, 0]) < 1e-6) & (np.abs(p[:, 2] - a) < 1e-6)
        uz = m.point_data["displacement"][top, 2].mean() - m0.point_data["displacement"][crown, 2].mean()
        assert -10 * kirsch < uz < -kirsch, (stage, uz)


def test_bolted_tunnel_holds_the_crown(tmp_path):
    """examples/support/bolted_tunnel.dat: unsupported, the crown slab (between vertical joints, under
    the bedding plane) falls (more than 0.1 m in 1500 steps, still moving); bolted at once, it settles
    less than 2 mm and the crown bolt carries about its weight (0.9 × 1 × 1 m of rock, about 23 kN,
    shared with the neighbouring bolts and the dowels); the bolts are written as lines with their
    axial force."""
    import csv

    import meshio
    import numpy as np

    _cli_run(ROOT / "examples" / "support" / "bolted_tunnel.dat", tmp_path)
    unsup = [float(r[2]) for r in list(csv.reader(open(tmp_path / "crown_unsupported.csv")))[1:]]
    bolted = [float(r[2]) for r in list(csv.reader(open(tmp_path / "crown_bolted.csv")))[1:]]
    assert unsup[-1] < -0.1 and unsup[-1] < unsup[-2]
    assert -2e-3 < bolted[-1] < 0 and abs(bolted[-1] - bolted[-10]) < 1e-5
    m = meshio.read(tmp_path / "tunnel_bolted_cables_0000.vtu")
    f = m.cell_data["axial_force"][0]
    assert m.cells[0].data.shape == (40, 2) and 5e3 < f.max() < 2.5e4 and np.isfinite(f).all()
