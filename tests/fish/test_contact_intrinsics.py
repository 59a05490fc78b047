"""FISH contact and sub-contact intrinsics on two stacked unit cubes (density 1000 kg/m³, g = 10 m/s²):
the lower one fixed, the upper one resting on it. Once settled the contact carries the upper cube's
weight, m g = 1000 × 1 × 10 = 1e4 N, along the normal (0, 0, 1) from block 1 to block 2."""
import pytest

from dec3d.errors import ExpressionError

SETUP = ("block create brick 0 1 0 1 0 1\nblock create brick 0 1 0 1 1 2\nblock property density 1000\n"
         "block contact jmodel assign elastic\n"
         "block contact property stiffness-normal 1e9 stiffness-shear 1e9\n"
         "model gravity 0 0 -10\nblock fix range position-z 0 1\n")


def test_contacts_before_any_cycle_and_their_geometry(session):
    session.command(SETUP + "block contact group 'joint'\n"
                    "fish define look\n  local cl = block.contact.list\n  global nc = list.size(cl)\n"
                    "  global c = cl(1)\n  global b1 = block.contact.b1(c)\n  global b2 = block.contact.b2(c)\n"
                    "  global nz = block.contact.normal.z(c)\n  global pz = block.contact.pos.z(c)\n"
                    "  global g = block.contact.group(c)\n  global isg = block.contact.isgroup(c, 'JOINT')\n"
                    "  global nsub = list.size(block.contact.subcontactlist(c))\n"
                    "  local sl = block.contact.subcontactlist(c)\n"
                    "  global same = block.subcontact.contact(sl(1)) == c\n"
                    "  global f = block.contact.find(2, 1) == c\nend\n@look")
    v = session.variables
    assert v["nc"] == 1 and (v["b1"], v["b2"]) == (1, 2)
    assert v["nz"] == pytest.approx(1.0, abs=1e-12) and v["pz"] == pytest.approx(1.0, abs=1e-9)
    assert v["g"] == "joint" and v["isg"] is True
    assert v["nsub"] >= 4 and v["same"] is True and v["f"] is True
    assert repr(v["c"]) == "contact(1,2)"


def test_settled_contact_carries_the_weight(session):
    session.command(SETUP + "model cycle 3000\n"
                    "fish define forces\n  local fsum = 0.0\n  local asum = 0.0\n  local dm = 0.0\n"
                    "  loop foreach local sc block.subcontact.list\n    fsum = fsum + block.subcontact.force.norm(sc)\n"
                    "    asum = asum + block.subcontact.area(sc)\n"
                    "    dm = dm + math.abs(block.subcontact.force.shear.mag(sc) - math.abs(block.subcontact.force.shear(sc)))\n"
                    "    dm = dm + math.abs(block.subcontact.disp.shear.mag(sc) - math.abs(block.subcontact.disp.shear(sc)))\n"
                    "  endloop\n  global fs = fsum\n  global ar = asum\n  global dm_ = dm\n"
                    "  local cl = block.contact.list\n"
                    "  global fc = block.contact.force.norm(cl(1))\n"
                    "  global fsh = math.abs(block.contact.force.shear(cl(1)))\nend\n@forces")
    v = session.variables
    assert v["fc"] == pytest.approx(1e4, rel=1e-2)         # m g of the upper cube
    assert v["fs"] == pytest.approx(v["fc"], rel=1e-12)    # the contact's force is its sub-contacts' sum
    assert v["ar"] == pytest.approx(1.0, rel=1e-6)         # the contact face is 1 m²
    assert v["fsh"] < 1e-6 * v["fc"]                        # no shear under vertical load
    assert v["dm_"] == 0.0                                   # the .mag intrinsics are the vectors' lengths


def test_contact_pointer_errors(session):
    session.command(SETUP + "[cl = block.contact.list]\n[c = cl(1)]\n[sl = block.contact.subcontactlist(c)]\n[s = sl(1)]")
    cases = [("[q = block.contact.b1(1)]", "`block.contact.b1` takes a contact (from block.contact.list), "
                                           "not a integer"),
             ("[q = block.subcontact.area(c)]", "`block.subcontact.area` takes a sub-contact"),
             ("[q = block.contact.pos(s)]", "`block.contact.pos` takes a contact (from block.contact.list), "
                                            "not a sub-contact")]
    for text, msg in cases:
        with pytest.raises(ExpressionError) as e:
            session.command(text)
        assert msg in e.value.message, text
        assert e.value.location.column == 6
    session.command("block delete range id 2")
    with pytest.raises(ExpressionError) as e:
        session.command("[n = block.contact.num]\n[q = block.contact.pos.z(c)]")
    assert "the contact of blocks 1 and 2 is gone" in e.value.message
    assert session.variables["n"] == 0


def test_contact_pointers_survive_a_save_file(session):
    session.command(SETUP + "[cl = block.contact.list]\n[c = cl(1)]\nmodel save 'k'\nmodel new\nmodel restore 'k'\n"
                    "[b = block.contact.b2(c)]")
    assert session.variables["b"] == 2 and repr(session.variables["c"]) == "contact(1,2)"


def test_contact_walks_and_subcontact_stress(session):
    session.command(SETUP + "model cycle 3000\n"
                    "fish define walk\n  global nc = 0\n  global ns = 0\n  global smax = 0.0\n"
                    "  local c = block.contact.head\n  loop while c # 0\n    nc = nc + 1\n"
                    "    local sl = block.contact.subcontactlist(c)\n    local s = sl(1)\n    loop while s # 0\n"
                    "      ns = ns + 1\n"
                    "      smax = math.max(smax, block.subcontact.stress.norm(s))\n"
                    "      s = block.subcontact.next(s)\n    endloop\n    c = block.contact.next(c)\n  endloop\n"
                    "end\n@walk\n[t = block.contact.type(block.contact.head)]")
    v = session.variables
    cs = session.model.stores["contacts"]
    ss = session.model.stores["subcontacts"]
    assert v["nc"] == cs.n == 1 and v["ns"] == int(cs["sub_count"][0]) == ss.n
    assert v["smax"] == pytest.approx(max(ss["fn"][k] / ss["area"][k] for k in range(ss.n)), rel=1e-12)
    assert v["t"] == int(cs["type"][0])


def test_contact_and_subcontact_properties_read_back_in_command_units(session):
    """`block contact property` values come back through block.contact.prop / block.subcontact.prop as the
    command took them: friction in degrees (kept as its tangent), an unset residual friction as the friction."""
    session.command(SETUP + "block contact jmodel assign mohr\n"
                    "block contact property stiffness-normal 2e9 stiffness-shear 1e9 friction 30 cohesion 1e5\n"
                    "fish define first\n  local cl = block.contact.list\n  first = cl(1)\nend\n"
                    "fish define props\n  local c = first\n  local sl = block.contact.subcontactlist(c)\n"
                    "  global kn = block.contact.prop(c, 'stiffness-normal')\n"
                    "  global phi = block.subcontact.prop(sl(1), 'friction')\n"
                    "  global phir = block.subcontact.prop(sl(list.size(sl)), 'Friction-Residual')\n"
                    "  global coh = block.contact.prop(c, 'cohesion')\n  global ten = block.contact.prop(c, 'tension')\n"
                    "end\n@props")
    v = session.variables
    assert (v["kn"], v["coh"], v["ten"]) == (2e9, 1e5, 0.0)
    assert v["phi"] == pytest.approx(30.0, rel=1e-12) and v["phir"] == pytest.approx(30.0, rel=1e-12)
    for text, msg in [("[q = block.contact.prop(first, 'G_I')]",
                       "`block.contact.prop`: joint model `mohr` has no property 'G_I' (it has cohesion,"),
                      ("[q = block.contact.prop(first, 3)]",
                       "`block.contact.prop` takes a property name (a string), not a integer"),
                      ("[q = block.subcontact.prop(first, 'friction')]",
                       "`block.subcontact.prop` takes a sub-contact")]:
        with pytest.raises(ExpressionError) as e:
            session.command(text)
        assert msg in e.value.message
