"""The growable store and the group tables."""
import numpy as np
import pytest

from dec3d.model.groups import GroupTable, group_field
from dec3d.model.model import Model
from dec3d.model.store import Field, Store


def make():
    return Store("things", {"x": Field((3,), np.float64, 0.0), "k": Field((), np.int64, -1),
                            "group": group_field()}, capacity=2)


def test_append_grows_by_doubling_and_fills_defaults():
    s = make()
    sl = s.append(3)
    assert (sl.start, sl.stop, s.n, s.capacity) == (0, 3, 3, 4)
    assert (s["k"] == -1).all() and s["x"].shape == (3, 3)
    s.append(2)
    assert s.capacity == 8 and s.n == 5


def test_compact_returns_remap_and_keeps_order():
    s = make()
    s.append(5)
    s["k"][:] = [10, 11, 12, 13, 14]
    remap = s.compact(np.array([True, False, True, False, True]))
    assert list(remap) == [0, -1, 1, -1, 2]
    assert list(s["k"]) == [10, 12, 14]
    # spare rows are reset: appending again gives defaults
    s.append(1)
    assert s["k"][-1] == -1


def test_resize_field_and_load_arrays():
    s = make()
    s.append(2)
    s["group"][:, 0] = [4, 5]
    s.resize_field("group", (3,))
    assert s["group"].tolist() == [[4, -1, -1], [5, -1, -1]]
    t = make()
    t.load_arrays(s.to_arrays())
    assert t.n == 2 and t["group"].shape == (2, 3)
    with pytest.raises(KeyError):
        t.add_field("x", Field())
    with pytest.raises(ValueError):
        s.compact(np.ones(5, dtype=bool))


def test_groups_slots_and_case():
    m = Model()
    s = make()
    s.append(4)
    g = GroupTable()
    g.assign(s, [0, 1], "Rock")
    g.assign(s, [1, 2], "top", slot="Layer")
    assert g.slot_names("things") == ["Default", "Layer"]
    assert s["group"].tolist() == [[0, -1], [0, 1], [-1, 1], [-1, -1]]
    assert g.code("ROCK") == 0 and g.name(0) == "Rock"
    g.assign(s, [1], "soil")             # replaces Rock in the default slot
    assert s["group"][1].tolist() == [2, 1]
    g.remove(s, [0, 1, 2, 3], "top")     # from every slot
    assert s["group"][:, 1].tolist() == [-1, -1, -1, -1]
    again = GroupTable.from_dict(g.to_dict())
    assert again.names == g.names and again.slots == g.slots
    assert m.groups.names == []
