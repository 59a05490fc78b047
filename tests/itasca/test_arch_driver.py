"""A masonry arch built the way public 3DEC Python drivers build theirs (command strings through
it.command), read back through it.block.contact, against the same text run as a .dat deck by a Session."""
import numpy as np

import dec3d
import dec3d.itasca as it
from arch import arch_commands
from it_fixture import fresh_it  # noqa: F401  (autouse: no model bound, a fresh working folder)

G = 9.81


def _support_reaction(model=None):
    """Force the abutments exert on the voussoirs [N], from the contacts between the two groups."""
    r = np.zeros(3)
    for c in it.block.contact.list(model):
        a_fixed, b_fixed = c.end1().in_group("abutment"), c.end2().in_group("abutment")
        if a_fixed != b_fixed:
            f = c.force()                       # on block B
            r += -f if b_fixed else f
    return r


def test_arch_through_it_command_matches_the_deck_and_carries_its_weight(tmp_path):
    text = arch_commands() + "model cycle 1000\n"
    it.command(text)
    assert it.block.count() == 7 and it.block.contact.count() == 6
    # each voussoir's weight reaches the abutments: the reaction balances the weight (statics of the ring)
    weight = G * sum(b.mass() for b in it.block.list() if b.in_group("voussoir"))
    assert weight > 0
    r = _support_reaction()
    np.testing.assert_allclose(r, [0, 0, weight], rtol=0, atol=1e-6 * weight)
    # the same commands as a deck file run by a Session: the same contact forces, to the bit
    deck = tmp_path / "arch.dat"
    deck.write_text(text)
    s = dec3d.Session(out_dir=tmp_path)
    s.call(deck)
    other = dec3d.Model(session=s)
    mine = [(c.id(), c.force_norm(), *c.force_shear()) for c in it.block.contact.list()]
    theirs = [(c.id(), c.force_norm(), *c.force_shear()) for c in it.block.contact.list(other)]
    assert mine == theirs
    # the array module gives the same numbers as the objects
    fn = it.contactarray.force_norm()
    np.testing.assert_array_equal(fn, [m[1] for m in mine])
    np.testing.assert_array_equal(it.contactarray.ids(), [m[0] for m in mine])
    # the normal forces are compressive and every voussoir is at rest
    assert (fn > 0).all()
    assert np.abs(it.blockarray.vel()).max() < 1e-9
