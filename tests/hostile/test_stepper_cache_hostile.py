"""The zone stepper cache (``physics.zone_cache``) against changes between `model cycle` commands made by
means its inputs might not show: tables a strain-softening zone reads (edited by command and by FISH),
a model on part of the zones, gridpoint and zone initial conditions, joins, a block zoned between
commands, body forces, hidden blocks, dynamic mode, structures added between commands (and structures
made before their block is zoned). Each deck cycles in three commands with the changes between them;
with the cache its numbers must be those of a run whose stepper is made anew at every command, bit for
bit, and the change must do something (else the case tests nothing)."""
import io

import numpy as np
import pytest

import dec3d
from dec3d.physics import zone_cache

DECK = """model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block zone generate edgelength 0.4
block zone cmodel assign elastic
block zone property young 10e9 poisson 0.25 density 2500
block contact jmodel assign elastic
block contact material-table default property stiffness-normal 1e11 stiffness-shear 1e11
block gridpoint apply velocity 0 0 0 range position-z 0
model gravity 0 0 -10
"""
SOFT = DECK.replace("block zone property young 10e9 poisson 0.25 density 2500",
                    "table 'coh' add (0,2e3) (0.001,1e3)\nblock zone cmodel assign strain-softening\n"
                    "block zone property young 10e9 poisson 0.25 density 2500 cohesion 2e3 friction 30 tension 1e3 "
                    "table-cohesion 'coh'")
LINER = ("structure liner create by-block-face range position-z 2\nstructure liner property isotropic 1e9 0.25 "
         "thickness 0.1 density 2500 coupling-stiffness-normal 1e9 coupling-stiffness-shear 1e9")

#: case -> (deck, the changes before the 2nd and 3rd commands)
CASES = {
    "table-command": (SOFT, ["table 'coh' add (0.0005, 10)"]),
    "table-fish": (SOFT, ["fish define f\n table('coh', 0.0) = 5.0\nend\n[f]"]),
    "table-remade": (SOFT, ["table 'coh' delete\ntable 'coh' add (0,5) (1,5)"]),
    "cmodel-on-part": (DECK, ["block zone cmodel assign mohr-coulomb range position-z 1 2\n"
                              "block zone property cohesion 1e3 friction 30 tension 1e3 range position-z 1 2"]),
    "property-one-zone": (DECK, ["block zone property density 2600 range position 0.2 0.2 0.2 0.2 0.2 0.2"]),
    "gridpoint-velocity": (DECK, ["block gridpoint initialize velocity 0 0 1 range position-z 2"]),
    "gridpoint-displacement": (DECK, ["block gridpoint initialize displacement 0 0 0.1 range position-z 2"]),
    "zone-stress": (DECK, ["block zone initialize stress-zz -1e5"]),
    "join": (DECK, ["block join"]),
    "zone-another-block": (DECK, ["block create brick 0 1 0 1 2 3\nblock property density 2500 range position-z 2 3\n"
                                  "block zone generate edgelength 0.4 range position-z 2 3\n"
                                  "block zone cmodel assign elastic range position-z 2 3\n"
                                  "block zone property young 10e9 poisson 0.25 density 2500 range position-z 2 3"]),
    "body-force": (DECK, ["block zone apply force 0 0 -1e5 range position-z 1 2", "block zone apply-remove"]),
    "hide": (DECK, ["block hide range position-z 1 2", "block hide off range position-z 1 2"]),
    "dynamic": (DECK, ["model dynamic active on", "model dynamic active off"]),
    "free-and-hold": (DECK, ["block gridpoint free range position-z 0",
                             "block gridpoint apply velocity 0 0 0 range position-z 0"]),
    "liner-added": (DECK, [LINER]),
    "cable-added": (DECK, ["structure cable create by-line 0.5 0.5 0.1 0.5 0.5 1.9 segments 4\nstructure cable "
                           "property young 2e11 cross-sectional-area 1e-4 grout-stiffness 1e9 grout-cohesion 1e6"]),
    "save-restore": (DECK, ["model save 'c1'\nmodel new\nmodel restore 'c1'\nblock zone property density 3000"]),
}


def _state(s):
    m = s.model
    v, zs = m.vertices, m.store("zones")
    return {"pos": v["pos"].copy(), "velocity": v["velocity"].copy(), "disp": v["disp"].copy(),
            "imass": v["imass"].copy(), "mass": v["mass"].copy(), "stress": zs["stress"].copy(),
            "state": zs["state"].copy(), "time": np.array([m.time])}


def _run(tmp_path, deck, changes):
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command(deck)
    s.command("model cycle 4")
    for c in changes:
        s.command(c)
        s.command("model cycle 4")
    return _state(s)


def _same(a, b):
    return all(a[k].shape == b[k].shape and np.array_equal(a[k].view(np.uint8), b[k].view(np.uint8)) for k in a)


@pytest.mark.parametrize("case", list(CASES))
def test_changes_between_commands_give_the_bits_of_fresh_steppers(tmp_path, monkeypatch, case):
    deck, changes = CASES[case]
    monkeypatch.setattr(zone_cache, "ENABLED", True)
    cached = _run(tmp_path, deck, changes)
    unchanged = _run(tmp_path, deck, [])
    monkeypatch.setattr(zone_cache, "ENABLED", False)
    fresh = _run(tmp_path, deck, changes)
    assert _same(cached, fresh), case
    assert not _same(cached, unchanged), f"{case}: the change did nothing; the case tests nothing"
