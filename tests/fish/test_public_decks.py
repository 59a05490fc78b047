"""Every `fish define` of the public decks parses and compiles; intrinsics dec3d lacks are named
(compile still succeeds: they fail only when run, as "not supported yet")."""
import pytest

from conftest import DECKS
from dec3d.fish import FishRuntime, compile_function, parse_block
from dec3d.lang.parser import parse_deck

pytestmark = pytest.mark.skipif(not DECKS.is_dir(), reason="needs the shared decks (set DEC3D_SHARED)")

MODERN = sorted(DECKS.glob("*.dat")) if DECKS.is_dir() else []


class _Quiet:
    variables: dict = {}

    def write(self, text):
        pass


def test_every_fish_define_of_the_modern_decks_compiles(capsys):
    compiled, unsupported = 0, {}
    for path in MODERN:
        deck = parse_deck(path.read_text(encoding="utf-8", errors="replace"), str(path))
        for block in deck.fish:
            fdef = parse_block(block, deck.filename, deck.source_lines)
            fn = compile_function(FishRuntime(_Quiet()), fdef)
            compiled += 1
            if fn.unsupported:
                unsupported[f"{path.name[:50]}:{block.line} {block.name}"] = sorted(fn.unsupported)
    with capsys.disabled():
        print(f"\n{compiled} FISH functions compiled; {len(unsupported)} use intrinsics not implemented yet:")
        for k, v in unsupported.items():
            print(f"  {k}: {', '.join(v)}")
    assert compiled >= 25


def test_fish_only_functions_of_the_decks_run(session):
    """The SAFEGO property functions and the servo reset use no model intrinsics: they run as written."""
    deck = DECKS / "yopi1838__Hanze_SAFEGO__1WB_EUCENTRE__1WB_SIN-01__04_Block_contact_properties.dat"
    text = deck.read_text(encoding="utf-8", errors="replace")
    end = text.index("end", text.index("fish def steel_prop")) + 3
    session.command(text[:end] + "\n@joint_prop\n@foundation_prop\n@steel_prop")
    v = session.variables
    # joint_prop: knj = Emortar/thick = 914e6/0.01; frictj = atan(0.42) in degrees; Gt = 0.025*(2*0.238)^0.7*1000
    assert v["knj"] == pytest.approx(914e6 / 0.01, rel=1e-12)
    assert v["frictj"] == pytest.approx(22.78240571, rel=1e-8)
    assert v["gt"] == pytest.approx(0.025 * (2 * 0.238) ** 0.7 * 1000, rel=1e-12)
    assert v["dens_found"] == 2000 and v["e_steel"] == 3e10
