"""Discrete fracture networks: generation, measures, files, save/restore, `block cut dfn`, bad input."""
import io
import math

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.geometry import dfn_gen, dfn_measure
from dec3d.session import Session


def _session(tmp_path):
    return Session(out_dir=tmp_path, stdout=io.StringIO())


def _run(s, text):
    s.run_items(s.load_text(text))
    return s


BOX = [0, 10, 0, 10, 0, 10]


# ------------------------------------------------------------------ exact clipping against closed forms
@pytest.mark.parametrize("center, normal, r, expect", [
    ((0, 5, 5), (0, 0, 1), 2.0, 2 * math.pi),                    # centre on a face: half the disk
    ((0, 0, 5), (0, 0, 1), 2.0, math.pi),                        # on an edge: a quarter
    ((5, 5, 5), (1, 1, 1), 2.0, 4 * math.pi),                    # inside: all of it
    ((1, 5, 5), (0, 0, 1), 2.0, 4 * math.pi - (4 * math.acos(0.5) - math.sqrt(3))),  # minus a segment
    ((5, 5, 12), (0, 0, 1), 3.0, 0.0),                           # above the box
    ((5, 5, 5), (0, 0, 1), 100.0, 100.0),                        # the whole section, 10 x 10
])
def test_clipped_area_closed_forms(center, normal, r, expect):
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    a = dfn_measure.clipped_areas(np.array([center], float), n[None], np.array([r]), BOX)[0]
    assert a == pytest.approx(expect, rel=1e-12, abs=1e-12)


def test_clipped_area_against_a_fine_polygon():
    """Independent check: the disk as a 20000-gon clipped by the six half-spaces (3D Sutherland-Hodgman)."""
    rng = np.random.default_rng(5)
    for _ in range(5):
        c = rng.uniform(-2, 12, 3)
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        r = rng.uniform(2, 6)
        a = np.cross([0.3, 0.5, 0.7], n)
        u = a / np.linalg.norm(a)
        w = np.cross(n, u)
        phi = np.linspace(0, 2 * np.pi, 20000, endpoint=False)
        poly = [c + r * (math.cos(p) * u + math.sin(p) * w) for p in phi]
        for k in range(3):
            for sgn, lim in ((1, 10.0), (-1, 0.0)):
                out = []
                for i in range(len(poly)):
                    p, q = poly[i], poly[(i + 1) % len(poly)]
                    fp, fq = sgn * (p[k] - lim), sgn * (q[k] - lim)
                    if fp <= 0:
                        out.append(p)
                    if fp * fq < 0:
                        out.append(p + fp / (fp - fq) * (q - p))
                poly = out
                if not poly:
                    break
        ref = 0.0 if len(poly) < 3 else 0.5 * abs(np.dot(np.sum([np.cross(poly[i], poly[(i + 1) % len(poly)])
                                                                 for i in range(len(poly))], axis=0), n))
        got = dfn_measure.clipped_areas(c[None], n[None], np.array([r]), BOX)[0]
        assert got == pytest.approx(ref, rel=1e-6, abs=1e-6)


def test_disk_intersections_and_clusters():
    c = np.array([[0, 0, 0], [0, 0, 0.5], [3, 0, 0], [10, 10, 10], [0.9, 0, 0]], float)
    n = np.array([[0, 0, 1], [1, 0, 0], [0, 0, 1], [0, 0, 1], [0, 1, 0]], float)
    r = np.array([1.0, 1.0, 1.0, 1.0, 0.05])
    # 0 and 1 cross (perpendicular through the same axis); 2 is coplanar with 0 but 3 m away (r sum 2);
    # 4 (radius 0.05 at x = 0.9, normal y) crosses 0 inside its rim; 3 is far
    lab, pairs = dfn_measure.clusters(c, n, r)
    assert sorted(map(tuple, pairs.tolist())) == [(0, 1), (0, 4)]
    assert lab.tolist() == [0, 0, 1, 2, 0]
    # a disk whose plane meets the other's but beyond its rim: no intersection
    assert not dfn_measure.disks_intersect(np.array([[0, 0, 0.]]), np.array([[0, 0, 1.]]), np.array([1.0]),
                                           np.array([[1.5, 0, 0.]]), np.array([[1, 0, 0.]]), np.array([1.0]))[0]


def test_scanline_and_traces():
    c = np.array([[5, 5, 5], [5, 5, 8]], float)
    n = np.array([[1, 0, 0], [0, 0, 1]], float)
    r = np.array([1.0, 1.0])
    assert dfn_measure.scanline_hits(c, n, r, [0, 5, 5], [10, 5, 5]).tolist() == [True, False]
    assert dfn_measure.p10(c, n, r, [0, 5, 5.5], [10, 5, 5.5]) == pytest.approx(0.1)
    # plane x = 5 holds disk 0 (parallel: no trace); disk 1's trace is its diameter along y, 2 m
    p21, length, area = dfn_measure.p21(c, n, r, [5, 5, 5], [1, 0, 0], BOX)
    assert (length, area) == (pytest.approx(2.0), pytest.approx(100.0))


# ------------------------------------------------------------------ generation
def _fisher_template():
    t = dfn_gen.default_template()
    t["orientation"] = {"kind": "fisher", "dip": math.radians(40), "ddir": math.radians(120), "kappa": 20.0}
    t["size"] = {"kind": "power-law", "exponent": 3.5}
    t["size_limits"] = [2.0, 20.0]
    return t


def test_same_seed_same_fractures():
    t = _fisher_template()
    a = dfn_gen.generate(t, [0, 50, 0, 50, 0, 50], 7, p32=0.2)
    b = dfn_gen.generate(t, [0, 50, 0, 50, 0, 50], 7, p32=0.2)
    c = dfn_gen.generate(t, [0, 50, 0, 50, 0, 50], 8, p32=0.2)
    for x, y in zip(a, b):
        assert np.array_equal(x, y)
    assert not np.array_equal(a[0][:10], c[0][:10])
    # the first fractures of a PCG64(7) stream are fixed on every machine
    assert a[2][:3].tolist() == pytest.approx([1.18562, 7.39035, 1.12532], abs=1e-5)


def test_generated_statistics():
    t = _fisher_template()
    c, n, r = dfn_gen.generate(t, [0, 50, 0, 50, 0, 50], 3, p32=0.5)
    assert dfn_measure.p32(c, n, r, [0, 50, 0, 50, 0, 50]) == pytest.approx(0.5, rel=0.02)
    dip, ddir, kappa = dfn_measure.fisher_stats(n)
    assert (math.degrees(dip), math.degrees(ddir), kappa) == (pytest.approx(40, rel=0.05),
                                                             pytest.approx(120, rel=0.05), pytest.approx(20, rel=0.05))
    assert dfn_measure.powerlaw_mle(2 * r, 2.0, 20.0) == pytest.approx(3.5, abs=0.1)
    assert (2 * r >= 2.0).all() and (2 * r <= 20.0).all()


@pytest.mark.parametrize("size, limits", [({"kind": "uniform"}, [2.0, 6.0]),
                                          ({"kind": "log-normal", "mean": 4.0, "std": 1.0}, [0.5, 50.0]),
                                          ({"kind": "gauss", "mean": 4.0, "std": 1.0}, [0.5, 50.0])])
def test_other_size_laws(size, limits):
    t = dfn_gen.default_template()
    t["size"], t["size_limits"] = size, limits
    _, _, r = dfn_gen.generate(t, BOX, 1, count=20000)
    d = 2 * r
    assert d.min() >= limits[0] and d.max() <= limits[1]
    mean = 4.0
    assert d.mean() == pytest.approx(mean, rel=0.02)
    if size["kind"] != "uniform":
        assert d.std() == pytest.approx(1.0, rel=0.05)


def test_bootstrapped_and_limits(tmp_path):
    (tmp_path / "poles.txt").write_text("id dip ddir quantity\n1 30 90 3\n2 80 200 1\n")
    s = _run(_session(tmp_path), f"""model new
fracture template create 'b' orientation bootstrapped '{tmp_path / 'poles.txt'}' size uniform size-limits 1 2
fracture generate template 'b' fracture-count 4000 generation-box 0 10 0 10 0 10
""")
    n = s.model.stores["fractures"]["normal"]
    dip = np.degrees(np.arccos(n[:, 2]))
    assert set(np.round(dip).astype(int)) == {30, 80}
    assert (np.abs(dip - 30) < 1e-6).mean() == pytest.approx(0.75, abs=0.03)


# ------------------------------------------------------------------ commands, files, state
DECK = """model new
block create brick 0 10 0 10 0 10
fracture template create 't' orientation fisher 60 90 15 size power-law 3 size-limits 2 10
fracture generate template 't' dfn 'rock' fracture-count 40 seed 2
"""


def test_export_import_round_trip_and_save(tmp_path):
    s = _run(_session(tmp_path), DECK + """fracture export file 'rock.csv' format csv
fracture export file 'rock'
fracture import from-file 'rock.csv' dfn 'csv'
fracture import from-file 'rock.dat' dfn 'txt'
fracture vtk 'disks'
model save 'm'
""")
    fs = s.model.stores["fractures"]
    d = fs["dfn"]
    for other in (2, 3):
        for k in ("center", "normal", "radius", "set"):
            np.testing.assert_allclose(fs[k][d == other], fs[k][d == 1], rtol=1e-12, atol=1e-12)
    assert (tmp_path / "disks.pvd").exists() and (tmp_path / "disks_0000.vtu").exists()
    vtu = (tmp_path / "disks_0000.vtu").read_text()
    assert 'NumberOfCells="120"' in vtu and "dip_direction" in vtu
    s2 = _run(_session(tmp_path), "model restore 'm'\n")
    f2 = s2.model.stores["fractures"]
    np.testing.assert_array_equal(f2["center"], fs["center"])
    assert s2.model.settings.fractures["dfns"] == {"1": "rock", "2": "csv", "3": "txt"}


def test_malformed_file_names_its_line(tmp_path):
    (tmp_path / "bad.dat").write_text("; header\ndisk 1 0 0 0 30 40 2\ndisk 2 0 0 zero 30 40 2\n")
    with pytest.raises(Dec3dError, match=r"'bad.dat' line 3: z `zero` is not a number") as exc:
        _run(_session(tmp_path), "model new\nfracture import from-file 'bad.dat'\n")
    assert exc.value.location.line == 2


@pytest.mark.parametrize("line, match, at", [
    ("fracture template create 'a' orientation fisher 40 120 0", "kappa must be positive", "fisher"),
    ("fracture template create 'a' size-limits 5 2", "not above the minimum 5 \\(reversed", "5 2"),
    ("fracture template create 'a' size power-law 0.8", "no finite mean", "power-law"),
    ("fracture generate mass-density 50 generation-box 0 100 0 100 0 100 maximum 10000",
     "P32 50 would need about 2.07e\\+07 fractures, more than the maximum 10000", "50"),
    ("fracture generate generation-box 0 1 0 1 0 1", "exactly one of", "fracture"),
])
def test_bad_input_is_refused_with_its_place(tmp_path, line, match, at):
    with pytest.raises(Dec3dError, match=match) as exc:
        _run(_session(tmp_path), "model new\n" + line + "\n")
    assert exc.value.location.line == 2
    assert exc.value.location.column == line.index(at) + 1


# ------------------------------------------------------------------ cutting
def _parallel_csv(tmp_path, zs, radius=50.0):
    rows = ["id,x,y,z,nx,ny,nz,radius,set"] + [f"{i + 1},5,5,{z},0,0,1,{radius},1" for i, z in enumerate(zs)]
    (tmp_path / "par.csv").write_text("\n".join(rows) + "\n")


def test_parallel_full_size_disks_give_n_plus_one_blocks(tmp_path):
    zs = [1.0, 2.5, 4.0, 7.0, 9.5]
    _parallel_csv(tmp_path, zs)
    s = _run(_session(tmp_path), "model new\nblock create brick 0 10 0 10 0 10\n"
                                 "fracture import from-file 'par.csv' dfn 'p'\nblock cut dfn name 'p' jointset-id 7\n")
    b = s.model.blocks
    assert b.n == len(zs) + 1 and s.results["blocks_made"] == len(zs)
    z = np.concatenate(([0.0], zs, [10.0]))
    np.testing.assert_allclose(np.sort(b["volume"]), np.sort(100.0 * np.diff(z)), rtol=1e-13)
    f = s.model.faces
    on = f["jointset"] == 7
    assert on.sum() == 2 * len(zs) and np.allclose(np.abs(f["normal"][on][:, 2]), 1.0)
    assert sorted(set(f["fracture"][on].tolist())) == [1, 2, 3, 4, 5]


def test_partly_crossed_block_is_cut_through_and_others_not(tmp_path):
    """3DEC: blocks are split completely; a disk reaching into one block only cuts that one."""
    (tmp_path / "one.csv").write_text("id,x,y,z,nx,ny,nz,radius\n1,2,5,5,1,0,0,1.0\n")
    s = _run(_session(tmp_path), "model new\nblock create brick 0 10 0 10 0 10\n"
                                 "block cut joint-set dip 0 origin 0 0 6.5\n"   # a block below z 6.5, one above
                                 "fracture import from-file 'one.csv'\nblock cut dfn id 1\n")
    b = s.model.blocks
    assert b.n == 3
    np.testing.assert_allclose(np.sort(b["volume"]), np.sort([2 * 10 * 6.5, 8 * 10 * 6.5, 350.0]), rtol=1e-13)


def test_generated_dfn_cut_conserves_volume(tmp_path):
    s = _run(_session(tmp_path), DECK + "block cut dfn name 'rock'\n")
    v = s.model.blocks["volume"]
    assert s.model.blocks.n > 20
    assert abs(v.sum() - 1000.0) / 1000.0 < 1e-9
    assert v.min() > 0


def test_jointset_range_addresses_the_new_contacts(tmp_path):
    _parallel_csv(tmp_path, [5.0])
    s = _run(_session(tmp_path), """model new
block create brick 0 10 0 10 0 10
block cut joint-set dip 90 dip-direction 90 origin 5 0 0
fracture import from-file 'par.csv' dfn 'p'
block cut dfn name 'p' jointset-id 4
block contact jmodel assign mohr
block property density 2000
model cycle 1
block contact property friction 33 range jointset-id 4
""")
    cs = s.model.stores["contacts"]
    from dec3d.commands.fracture_measure import jointset_id
    mask = jointset_id(s, "contact", {"id": 4})
    # four blocks 2 x 2: two face contacts across the DFN joint z = 5, two across x = 5, two along the
    # middle edge; the range picks the two on the joint
    assert cs.n == 6 and mask.sum() == 2
    assert np.allclose(np.abs(cs["normal"][mask][:, 2]), 1.0)


def test_fish_intrinsics(tmp_path):
    s = _run(_session(tmp_path), """model new
fracture template create 'a' orientation fisher 30 200 100000 size uniform size-limits 2 4
fracture generate template 'a' fracture-count 5 generation-box 0 1 0 1 0 1
[n = fracture.num()]
[d = fracture.dip(1)]
[dd = fracture.ddir(1)]
[dia = fracture.diameter(2)]
[nz = fracture.normal(1)->z]
[px = fracture.pos(3)->x]
""")
    fs = s.model.stores["fractures"]
    v = s.variables
    assert v["n"] == 5
    assert (v["d"], v["dd"]) == (pytest.approx(30, abs=0.5), pytest.approx(200, abs=0.5))
    assert v["dia"] == pytest.approx(2 * fs["radius"][1]) and v["px"] == pytest.approx(fs["center"][2, 0])
    assert v["nz"] == pytest.approx(math.cos(math.radians(v["d"])))
    with pytest.raises(Dec3dError, match="no fracture with id 9"):
        _run(s, "[x = fracture.dip(9)]\n")


def test_intersections_command_and_cluster_in_vtk(tmp_path):
    (tmp_path / "five.csv").write_text("id,x,y,z,nx,ny,nz,radius\n1,0,0,0,0,0,1,1\n2,0,0,0.5,1,0,0,1\n"
                                       "3,3,0,0,0,0,1,1\n4,10,10,10,0,0,1,1\n5,0.9,0,0,0,1,0,0.05\n")
    s = _run(_session(tmp_path), "model new\nfracture import from-file 'five.csv'\n"
                                 "fracture intersections compute\nfracture vtk 'five'\n")
    r = s.results
    assert (r["intersections"], r["clusters"], r["largest_cluster"], r["isolated"]) == (2, 3, 3, 2)
    assert s.model.stores["fractures"]["cluster"].tolist() == [0, 0, 1, 2, 0]
    import meshio

    mesh = meshio.read(tmp_path / "five_0000.vtu")
    assert mesh.cell_data["cluster"][0].tolist() == [0, 0, 1, 2, 0]
    assert len(mesh.points) == 5 * 24
    np.testing.assert_allclose(np.linalg.norm(mesh.points[:24] - [0, 0, 0], axis=1), 1.0)


def test_cut_over_the_budget_is_refused_and_nothing_is_cut(tmp_path):
    s = _run(_session(tmp_path), DECK)
    before = s.model.blocks.n, s.model.vertices["pos"].copy(), s.model.next_block_id
    with pytest.raises(Dec3dError, match=r"this DFN made \d+ blocks after \d+ of its 40 disks, over the budget of 45 "
                                         r"blocks; nothing was cut") as exc:
        _run(s, "model budget blocks 45\nblock cut dfn name 'rock'\n")
    assert exc.value.location.line == 2
    assert s.model.blocks.n == before[0] and s.model.next_block_id == before[2]
    np.testing.assert_array_equal(s.model.vertices["pos"], before[1])
    _run(s, "model budget blocks 100000\nblock cut dfn name 'rock'\n")
    assert s.model.blocks.n > 45


def test_cuts_that_would_split_zoned_blocks_are_refused_and_change_nothing(tmp_path):
    """A joint set or a disk through a zoned block is refused before anything is cut (its zones would
    not follow the cut: the piece left without zones and the other holding zones past its faces);
    blocks out of the cut's reach are still cut, and a zoned block the planes miss is no obstacle."""
    (tmp_path / "two.csv").write_text("id,x,y,z,nx,ny,nz,radius\n1,0.5,0.5,0.5,0,0,1,5.0\n2,2.5,0.5,0.3,0,0,1,5.0\n")
    base = ("model new\nblock create brick 0 1 0 1 0 1\nblock create brick 2 3 0 1 0 1\n"
            "block zone generate edgelength 0.5 range position-x 2 3\n")
    s = _run(_session(tmp_path), base)
    before = {k: a.copy() for k, a in s.model.blocks.to_arrays().items()}
    nz = s.model.store("zones").n
    for line, col in (("block cut joint-set dip 0 origin 0 0 0.5", 1),
                      ("fracture import from-file 'two.csv'\nblock cut dfn id 1", 1)):
        with pytest.raises(Dec3dError, match=r"would split zoned or FE blocks \(2\)") as e:
            _run(s, line)
        assert e.value.location.column == col
        after = s.model.blocks.to_arrays()
        assert all(np.array_equal(before[k], after[k]) for k in before) and s.model.store("zones").n == nz
    _run(s, "block cut joint-set dip 0 origin 0 0 0.5 range position-x 0 1")   # the rigid block only
    assert s.model.blocks.n == 3 and s.model.store("zones").n == nz
    _run(s, "block cut joint-set dip 90 dip-direction 90 origin 1.5 0 0")       # between the blocks: no split
    assert s.model.blocks.n == 3
