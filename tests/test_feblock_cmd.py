"""`model configure feblock`, `feblock generate`, `feblock list`: the mesh installed in brick
blocks (the FE-block text's fem_beam.dat geometry, the tunnel-liner prisms), a closed outward
triangulated surface with mid-face slave nodes, gridpoint conditions on FE nodes, block deletion,
save/restore, and the errors for bad input."""
import hashlib
import io
import json
import zipfile

import numpy as np
import pytest

from dec3d.errors import Dec3dError
from dec3d.kernels.feblock import YNODE, feb_slave_interp
from dec3d.session import Session

BEAM = """model new
model configure feblock
block create brick 0 10 0 1 0 1
feblock generate 1 1 1
"""


def _surface(model, row):
    b, f, fv = model.blocks, model.faces, model.face_vertices
    f0, nf = int(b["face_start"][row]), int(b["face_count"][row])
    assert (f["nvert"][f0:f0 + nf] == 3).all()
    tri = np.array([fv["vertex"][f["vstart"][k]:f["vstart"][k] + 3] for k in range(f0, f0 + nf)])
    return tri


def _closed_and_outward(model, row, volume):
    tri = _surface(model, row)
    edges = {}
    for t in tri:
        for k in range(3):
            e = (int(t[k]), int(t[(k + 1) % 3]))
            edges[e] = edges.get(e, 0) + 1
    assert all(c == 1 for c in edges.values())
    assert all((b, a) in edges for a, b in edges)               # every edge used once each way: closed
    p = model.vertices["pos"]
    a, b_, c = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    vol = np.einsum("ij,ij->i", a, np.cross(b_, c)).sum() / 6.0   # divergence theorem: > 0 when outward
    assert abs(vol - volume) < 1e-9 * volume


def test_fem_beam_geometry(session):
    session.command(BEAM + "feblock list")
    m = session.model
    es = m.store("feblocks")
    assert es.n == 10
    assert m.blocks["kind"][0] == 2                              # KIND_FE
    assert abs(es["volume"][:10].sum() - 10.0) < 1e-12 and np.allclose(es["volume"][:10], 1.0)
    v = m.vertices
    masters = ~v["feslave"][: v.n]
    # corners 11 x 4, mid-edges 10 x 4 along x and 11 x 4 across: 128 shared master nodes
    assert masters.sum() == 128 and (~masters).sum() == 42
    assert v["zoned"][: v.n].all()
    # every element is the unit cube [e, e+1] x [0, 1] x [0, 1] with its nodes in Table 1 order
    for e in range(10):
        x = v["pos"][es["nodes"][e]]
        assert np.allclose(x, (YNODE + 1) / 2 + [e, 0, 0], atol=1e-12)
    # neighbours share their four corner and four mid-edge nodes of the common face
    assert (es["nodes"][0][[1, 2, 5, 6]] == es["nodes"][1][[0, 3, 4, 7]]).all()
    # slave nodes sit where the masters' interpolation puts them
    pos = v["pos"].copy()
    feb_slave_interp(es["nodes"], es["slaves"], np.arange(10, dtype=np.int64), pos)
    assert np.allclose(pos, v["pos"], atol=1e-14)
    assert (es["slaves"][:, 6] == -1).all()                      # no centre node
    assert (es["slaves"][0, :6] >= 0).sum() == 5 and (es["slaves"][4, :6] >= 0).sum() == 4
    _closed_and_outward(m, 0, 10.0)
    assert abs(m.blocks["volume"][0] - 10.0) < 1e-9
    out = session.output.getvalue()
    assert "FE blocks 1, elements 10" in out and "128" in out and "42" in out and "2x2x2" in out


def test_integration_and_divisions(session):
    session.command("model configure feblock\nblock create brick 0 2 0 1 0 0.5\n"
                    "feblock generate 0.5 0.4 1 integration 3")
    es = session.model.store("feblocks")
    # 2 / 0.5 = 4, 1 / 0.4 = 2.5 -> 3 (rounded half up), 0.5 / 1 -> 1
    assert es.n == 12 and (es["nq"][:12] == 3).all()
    assert abs(es["volume"][:12].sum() - 1.0) < 1e-12


def test_liner_prism_blocks(session):
    """The tunnel-liner deck's prisms (8-vertex hexahedra on an arc): `feblock generate 20 2.5 20`
    gives one element through the thickness and across, eight along the tunnel."""
    cmds = ["model configure feblock"]
    th = np.radians([0.0, 180.0 / 7, 2 * 180.0 / 7])
    for t1, t2 in zip(th[:-1], th[1:]):
        p = [(4 * np.cos(t1), 4 * np.sin(t1)), (4 * np.cos(t2), 4 * np.sin(t2)),
             (3.8 * np.cos(t2), 3.8 * np.sin(t2)), (3.8 * np.cos(t1), 3.8 * np.sin(t1))]
        f1 = " ".join(f"{x:.12g} -10 {z:.12g}" for x, z in p)
        f2 = " ".join(f"{x:.12g} 10 {z:.12g}" for x, z in p)
        cmds.append(f"block create prism face-1 {f1} face-2 {f2} group 'liner'")
    cmds.append("block create brick 10 11 0 1 0 1 group 'rock'")
    cmds.append("block hide range group 'liner' not")
    cmds.append("feblock generate 20 2.5 20")
    session.command("\n".join(cmds))
    m = session.model
    es = m.store("feblocks")
    assert es.n == 16
    kinds = m.blocks["kind"][: m.blocks.n]
    assert list(kinds) == [2, 2, 0]                              # the hidden rock block is untouched
    for r in (0, 1):
        mine = es["block"][: es.n] == r
        assert mine.sum() == 8
        _closed_and_outward(m, r, float(es["volume"][: es.n][mine].sum()))
        assert abs(es["volume"][: es.n][mine].sum() - m.blocks["volume"][r]) < 1e-9


def test_gridpoint_conditions_reach_fe_nodes(session):
    session.command(BEAM + "block gridpoint apply velocity 0 0 0 range pos-x 0\n"
                    "block gridpoint apply force-z [-100.0/3.0] range pos-x 10 pos-z 1")
    v = session.model.vertices
    held = np.flatnonzero(v["apply_fix"][: v.n] == 7)
    assert np.allclose(v["pos"][held, 0], 0.0)
    assert (~v["feslave"][held]).sum() == 8                      # 4 corners + 4 mid-edge nodes of the root face
    loaded = np.flatnonzero(v["fapp"][: v.n, 2] != 0)
    assert len(loaded) == 3 and np.allclose(v["fapp"][loaded, 2], -100.0 / 3)
    assert not v["feslave"][loaded].any()


def test_delete_block_drops_its_elements(session):
    session.command("model configure feblock\nblock create brick 0 1 0 1 0 1\nblock create brick 2 3 0 1 0 1\n"
                    "feblock generate 0.5 0.5 0.5\nblock delete range id 1")
    m = session.model
    es = m.store("feblocks")
    assert es.n == 8 and (es["block"][:8] == 0).all()
    v0, nv = int(m.blocks["vert_start"][0]), int(m.blocks["vert_count"][0])
    nodes = es["nodes"][:8]
    assert nodes.min() >= v0 and nodes.max() < v0 + nv
    assert np.allclose(m.vertices["pos"][nodes].min(axis=(0, 1)), [2, 0, 0])


def test_save_restore_round_trip_and_bad_file(tmp_path):
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(BEAM + "model save 'beam'")
    t = Session(out_dir=tmp_path, stdout=io.StringIO())
    t.command("model restore 'beam'")
    a, b = s.model.store("feblocks"), t.model.store("feblocks")
    assert b.n == 10
    for key in ("nodes", "slaves", "nq", "volume", "block", "id"):
        assert np.array_equal(a[key][:10], b[key][:10])
    assert np.array_equal(s.model.vertices["feslave"][: s.model.vertices.n],
                          t.model.vertices["feslave"][: t.model.vertices.n])
    # a file whose element nodes point outside the vertices is refused, naming the problem
    src = tmp_path / "beam.sav"
    with zipfile.ZipFile(src) as z:
        members = {n: z.read(n) for n in z.namelist()}
    meta = json.loads(members["meta.json"])
    arr = np.load(io.BytesIO(members["feblocks.nodes.npy"]))
    arr[3, 5] = 10 ** 6
    buf = io.BytesIO()
    np.lib.format.write_array(buf, arr, version=(1, 0), allow_pickle=False)
    members["feblocks.nodes.npy"] = buf.getvalue()
    meta["sha256"]["feblocks.nodes"] = hashlib.sha256(buf.getvalue()).hexdigest()
    members["meta.json"] = json.dumps(meta, sort_keys=True, indent=1).encode()
    members.pop("signature.json")       # as a file from before signatures: the index check must catch it
    with zipfile.ZipFile(tmp_path / "bad.sav", "w") as z:
        for n, data in members.items():
            z.writestr(n, data)
    u = Session(out_dir=tmp_path, stdout=io.StringIO())
    with pytest.raises(Dec3dError, match="FE element node rows point outside the vertices"):
        u.command("model restore 'bad'")


def test_needs_configure(session):
    session.command("block create brick 0 1 0 1 0 1")
    for cmd in ("feblock generate 1 1 1", "feblock list", "feblock change density 2000"):
        with pytest.raises(Dec3dError, match=r"needs `model configure feblock` first"):
            session.command(cmd)
    assert "feblocks" not in session.model.stores
    assert session.model.blocks["kind"][0] == 0


def test_non_brick_block_is_an_error_naming_it_and_nothing_changes(session):
    session.command("model configure feblock\nblock create brick 0 1 0 1 0 1\n"
                    "block create tetrahedron 2 0 0 3 0 0 2 1 0 2 0 1")
    nv = session.model.vertices.n
    with pytest.raises(Dec3dError, match=r"block 2 is not an 8-vertex hexahedron \(4 vertices, 4 faces\)"):
        session.command("feblock generate 0.5 0.5 0.5")
    assert session.model.vertices.n == nv
    assert "feblocks" not in session.model.stores or session.model.store("feblocks").n == 0
    assert (session.model.blocks["kind"][:2] == 0).all()
    # in a range without the tetrahedron it works
    session.command("feblock generate 0.5 0.5 0.5 range id 1")
    assert session.model.store("feblocks").n == 8


def test_zoned_block_and_bad_sizes_are_errors(session):
    session.command("model configure feblock\nblock create brick 0 1 0 1 0 1\nblock zone generate edgelength 0.5")
    with pytest.raises(Dec3dError, match=r"block 1 is zoned"):
        session.command("feblock generate 1 1 1")
    for bad in ("feblock generate 1 1", "feblock generate 1 0 1", "feblock generate 1 1 1 integration 4"):
        with pytest.raises(Dec3dError):
            session.command(bad)


def test_generate_twice_leaves_fe_blocks_as_they_are(session):
    session.command(BEAM + "feblock generate 0.5 0.5 0.5")
    assert session.model.store("feblocks").n == 10


def test_generated_fem_beam_relaxes_to_the_calculix_deflection(session):
    """The seed's fem_beam.dat up to `model solve`, then a relaxation loop over the model's own
    stores (element props by ZP_* columns, gridpoint conditions from `block gridpoint apply`,
    masters moved, slaves interpolated): with 3x3x3 integration the tip deflection is CalculiX
    C3D20's 0.3996 m within 0.2 %, and within 1 % of WL^3/(3EI) = 0.4 m. (The deformable step of
    the engine is not used here: it is another module's.)"""
    from dec3d.kernels.feblock import feb_step, feb_stiffness
    from dec3d.model.zones import ZMODEL_ELASTIC, ZP_BULK, ZP_SHEAR

    session.command(BEAM.replace("feblock generate 1 1 1", "feblock generate 1 1 1 integration 3")
                    + "block gridpoint apply vel 0 0 0 range pos-x 0\n"
                      "block gridpoint apply force-z [-1.0*100.0/3.0] range pos-x 10 pos-z 1")
    m = session.model
    es, v = m.store("feblocks"), m.vertices
    E, nu = 1e6, 0.2
    es["cmodel"][:] = ZMODEL_ELASTIC
    es["prop"][:, ZP_BULK] = E / (3 * (1 - 2 * nu))
    es["prop"][:, ZP_SHEAR] = E / (2 * (1 + nu))
    rows = np.arange(es.n, dtype=np.int64)
    nodes = np.ascontiguousarray(es["nodes"])
    bulk = np.ascontiguousarray(es["prop"][:, ZP_BULK])
    shear = np.ascontiguousarray(es["prop"][:, ZP_SHEAR])
    nq = int(es["nq"][0])
    assert nq == 3
    pos = np.ascontiguousarray(v["pos"])
    kd = np.zeros(v.n)
    assert feb_stiffness(pos, nodes, rows, bulk, shear, kd, nq) == -1
    master = ~v["feslave"]
    mass = np.where(master, kd / 2 * 1.1, 1.0)
    held = (v["apply_fix"][:, None] >> np.arange(3)) & 1 == 1
    held |= ~master[:, None]
    vel = np.where(held, v["vapp"], 0.0)
    disp = np.zeros((v.n, 3))
    gs = np.ascontiguousarray(es["gstress"])
    st = np.ascontiguousarray(es["stress"])
    fscale = np.abs(v["fapp"]).max()
    for step in range(1, 200001):
        f = v["fapp"].copy()
        feb_step(pos, vel, nodes, rows, bulk, shear, 1.0, gs, st, f, nq)
        f[held] = 0.0
        if step % 500 == 0 and np.abs(f).max() < 1e-7 * fscale:
            break
        f -= 0.8 * np.abs(f) * np.sign(vel)
        vel += f / mass[:, None]
        vel[held] = 0.0
        disp += vel
    else:
        raise AssertionError("did not converge")
    feb_slave_interp(nodes, np.ascontiguousarray(es["slaves"]), rows, disp)
    tip = np.flatnonzero(np.all(abs(v["pos"] - [10, 1, 1]) < 1e-9, axis=1))
    assert len(tip) == 1
    u = -disp[tip[0], 2]
    assert abs(u - 0.3996) < 0.002 * 0.3996 and abs(u - 0.4) < 0.01 * 0.4, u
    # the slave at the centre of the tip face moved with the beam end
    cen = np.flatnonzero(np.all(abs(v["pos"] - [10, 0.5, 0.5]) < 1e-9, axis=1))
    assert v["feslave"][cen[0]] and abs(-disp[cen[0], 2] - u) < 0.01 * u


# ----------------------------------------------------------------------------- feblock read
def _beam_file(tmp_path, corners_only=False, name="beam.fem"):
    """The fem_beam mesh (10 unit cubes along x) as the text's ASCII format."""
    grid, pts, elems = {}, [], []
    for e in range(10):
        ids = []
        for y in (YNODE[:8] if corners_only else YNODE):
            p = ((y + 1) / 2 + [e, 0, 0]).round(6)
            k = tuple(p)
            if k not in grid:
                grid[k] = len(pts) + 1
                pts.append(p)
            ids.append(grid[k])
        elems.append(ids)
    lines = ["fem beam, 10 elements", f"{len(pts)} {len(elems)}"]
    lines += [" ".join(f"{c:g}" for c in p) for p in pts]
    lines += [" ".join(str(i) for i in ids) for ids in elems]
    (tmp_path / name).write_text("\n".join(lines) + "\n")
    return lines


@pytest.mark.parametrize("corners_only", [False, True])
def test_read_mesh_file(tmp_path, corners_only):
    _beam_file(tmp_path, corners_only)
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("model configure feblock\nblock create brick 20 21 0 1 0 1\nfeblock read 'beam.fem' group 'beam'")
    m = s.model
    es = m.store("feblocks")
    assert es.n == 10 and (es["block"][:10] == 1).all()
    assert m.blocks["kind"][1] == 2 and m.blocks["kind"][0] == 0
    v0, nv = int(m.blocks["vert_start"][1]), int(m.blocks["vert_count"][1])
    assert (~m.vertices["feslave"][v0:v0 + nv]).sum() == 128 and m.vertices["feslave"][v0:v0 + nv].sum() == 42
    for e in range(10):
        assert np.allclose(m.vertices["pos"][es["nodes"][e]], (YNODE + 1) / 2 + [e, 0, 0], atol=1e-12)
    _closed_and_outward(m, 1, 10.0)
    assert abs(m.blocks["volume"][1] - 10.0) < 1e-9
    assert m.groups.names[m.blocks["group"][1, 0]] == "beam"


def test_read_mesh_file_errors(tmp_path):
    lines = _beam_file(tmp_path)
    nn = int(lines[1].split()[0])

    def bad(name, text, match):
        (tmp_path / name).write_text(text)
        s = Session(out_dir=tmp_path, stdout=io.StringIO())
        s.command("model configure feblock\nblock create brick 20 21 0 1 0 1")
        nv = s.model.vertices.n
        with pytest.raises(Dec3dError, match=match):
            s.command(f"feblock read '{name}'")
        assert s.model.blocks.n == 1 and s.model.vertices.n == nv
        assert "feblocks" not in s.model.stores or s.model.store("feblocks").n == 0

    body = "\n".join(lines)
    bad("t1.fem", "\n".join(lines[:-3]), r"t1\.fem:\d+: the file ends after .* element lines")
    bad("t2.fem", "title\n10 x\n", r"t2\.fem:2: the header line must be two integers")
    bad("t3.fem", body.replace(lines[5], "1.0 abc 2"), r"t3\.fem:6: node 4: expected three coordinates")
    e1 = 2 + nn
    bad("t4.fem", body.replace(lines[e1], lines[e1] + " 7"), rf"t4\.fem:{e1 + 1}: element 1: 21 node numbers")
    bad("t5.fem", body.replace(lines[e1], "999 " + " ".join(lines[e1].split()[1:])),
        rf"t5\.fem:{e1 + 1}: element 1: node 999 is not between 1 and {nn}")
    ids = lines[e1 + 2].split()
    ids[:16] = ids[4:8] + ids[:4] + ids[12:16] + ids[8:12]         # mirrored top to bottom: inverted element
    bad("t6.fem", body.replace(lines[e1 + 2], " ".join(ids)), rf"t6\.fem:{e1 + 3}: element 3 has a non-positive Jacobian")
    bad("t7.fem", "only a title\n", r"t7\.fem:1: the file ends before the header")
    s = Session(out_dir=tmp_path, stdout=io.StringIO())
    with pytest.raises(Dec3dError, match=r"needs `model configure feblock` first"):
        s.command("feblock read 'beam.fem'")


def test_vtk_of_fe_elements_reads_back(tmp_path, session):
    """Quadratic hexahedra (VTK 25): meshio sees ten hexahedron20 cells with the element nodes,
    displacements and stresses; VTK's own cell volume (pyvista) is the element volume, so the
    node order is VTK's."""
    import meshio

    from dec3d.io.fevtk import write_feblocks_vtu

    session.command(BEAM)
    m = session.model
    es, v = m.store("feblocks"), m.vertices
    v["disp"][:, 2] = 0.01 * v["pos"][:, 0] ** 2                 # a bent beam (small strain: positions stay)
    es["stress"][:10] = np.arange(60, dtype=float).reshape(10, 6)
    es["gstress"][:10, :8] = 1.0
    path = write_feblocks_vtu(m, tmp_path / "fe.vtu")
    mesh = meshio.read(path)
    assert [c.type for c in mesh.cells] == ["hexahedron20"] and mesh.cells[0].data.shape == (10, 20)
    rows = mesh.point_data["vertex_row"]
    assert len(rows) == 128 and not v["feslave"][rows].any()
    assert np.allclose(mesh.points, v["pos"][rows])
    conn = mesh.cells[0].data
    assert np.array_equal(rows[conn], es["nodes"][:10])
    assert np.allclose(mesh.point_data["displacement"][:, 2], 0.01 * v["origin"][rows, 0] ** 2)
    assert np.allclose(mesh.cell_data["stress"][0], es["stress"][:10][:, [0, 1, 2, 3, 5, 4]])   # XX YY ZZ XY YZ XZ
    assert np.allclose(mesh.cell_data["stress_gauss_mean"][0], 1.0)
    assert np.array_equal(mesh.cell_data["element_id"][0], np.arange(1, 11))
    pv = pytest.importorskip("pyvista")
    grid = pv.read(path)
    assert (np.asarray(grid.celltypes) == 25).all()
    vol = grid.compute_cell_sizes(length=False, area=False)["Volume"]
    feb_vol = np.zeros(10)
    from dec3d.kernels.feblock import feb_volume
    feb_volume(np.ascontiguousarray(v["pos"]), np.ascontiguousarray(es["nodes"]), np.arange(10, dtype=np.int64),
               feb_vol)
    assert np.allclose(vol, feb_vol, rtol=1e-6)


def test_cycling_fe_blocks_without_material_is_refused_naming_the_block(session):
    session.command(BEAM)
    pos = session.model.vertices["pos"].copy()
    for cmd in ("model cycle 10", "model solve"):
        with pytest.raises(Dec3dError, match=r"FE blocks 1 have no element with a constitutive model"):
            session.command(cmd)
    assert np.array_equal(session.model.vertices["pos"], pos) and session.model.step == 0


def test_feblock_change_sets_material_per_element_range(session):
    from dec3d.model.zones import ZMODEL_ELASTIC, ZP_BULK, ZP_DENSITY, ZP_SHEAR

    session.command(BEAM + "feblock change cmodel elastic young 1e6 poisson 0.2 density 2000\n"
                    "feblock change density 2500 range position-x 5 10\nfeblock change poisson 0.25 range id 1")
    es = session.model.store("feblocks")
    assert (es["cmodel"][:10] == ZMODEL_ELASTIC).all()
    K, G = es["prop"][:10, ZP_BULK], es["prop"][:10, ZP_SHEAR]
    assert np.allclose(K[1:], 1e6 / (3 * 0.6)) and np.allclose(G[1:], 1e6 / 2.4)
    E = 9 * K[0] * G[0] / (3 * K[0] + G[0])
    nu = (3 * K[0] - 2 * G[0]) / (2 * (3 * K[0] + G[0]))
    assert abs(E - 1e6) < 1e-6 and abs(nu - 0.25) < 1e-12               # young kept, poisson changed
    dens = es["prop"][:10, ZP_DENSITY]
    assert np.allclose(dens[:5], 2000) and np.allclose(dens[5:], 2500)     # centroids 5.5 ... 9.5 in range
    with pytest.raises(Dec3dError, match="not both pairs"):
        session.command("feblock change bulk 1e6 young 1e6")
    with pytest.raises(Dec3dError, match="needs cmodel, young"):
        session.command("feblock change")


def test_feblock_change_young_alone_needs_poisson_and_changes_nothing(session):
    session.command(BEAM)
    with pytest.raises(Dec3dError, match="young and poisson are both needed: element 1 has no elastic moduli"):
        session.command("feblock change cmodel elastic young 1e6")
    assert (session.model.store("feblocks")["cmodel"][:10] == 0).all()


def test_block_zone_cmodel_and_property_reach_fe_elements_as_the_seed_deck_uses_them(session):
    """fem_beam.dat: `block zone cmodel assign el` and `block zone prop dens 2000 young [E] poiss 0.2`."""
    from dec3d.model.zones import ZMODEL_ELASTIC, ZP_BULK, ZP_DENSITY, ZP_SHEAR

    session.command(BEAM + "block zone cmodel assign el\nblock zone prop dens 2000 young 1e6 poiss 0.2")
    es = session.model.store("feblocks")
    assert (es["cmodel"][:10] == ZMODEL_ELASTIC).all()
    assert np.allclose(es["prop"][:10, ZP_BULK], 1e6 / 1.8) and np.allclose(es["prop"][:10, ZP_SHEAR], 1e6 / 2.4)
    assert np.allclose(es["prop"][:10, ZP_DENSITY], 2000)
    assert "selected no zone" not in session.output.getvalue()


def test_one_element_thick_mesh_with_reduced_integration_warns(session):
    session.command(BEAM)
    assert "one element thick" in session.output.getvalue() and "integration 3" in session.output.getvalue()
    session.command("block create brick 0 1 5 6 0 1\nfeblock generate 1 1 1 integration 3 range id 2")
    assert session.output.getvalue().count("one element thick") == 1
