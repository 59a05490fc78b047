"""block.contact.near(v): the contact nearest a point (3DEC 5's c_near in demifang's
grav_normal_and_shear deck), on three unit cubes in a column: contacts at z = 1 and z = 2."""
import pytest

from dec3d.errors import Dec3dError

SETUP = ("block create brick 0 1 0 1 0 1\nblock create brick 0 1 0 1 1 2\nblock create brick 0 1 0 1 2 3\n"
         "block contact property stiffness-normal 1e9 stiffness-shear 1e9\n")


def test_near_picks_the_contact_closest_to_the_point(session):
    session.command(SETUP + "fish define pick(p)\n  local c = block.contact.near(p)\n"
                    "  pick = block.contact.b1(c) * 10 + block.contact.b2(c)\nend\n"
                    "[low = pick(vector(0.5, 0.5, 0.2))]\n[high = pick(vector(3, 3, 2.4))]\n"
                    "[mid = pick(vector(0.5, 0.5, 1.4))]")
    v = session.variables
    assert (v["low"], v["mid"], v["high"]) == (12, 12, 23)


def test_near_without_contacts_is_zero_and_needs_a_vector(session):
    session.command("block create brick 0 1 0 1 0 1\n[none = block.contact.near(vector(0, 0, 0))]")
    assert session.variables["none"] == 0
    with pytest.raises(Dec3dError, match="takes a vector"):
        session.command("[bad = block.contact.near(1)]")
