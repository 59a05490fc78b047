"""A `model cycle` command's run is freed when the command ends, by reference counting alone: the run and its
steps used to hold each other, so every command's run — with its zone stepper, hundreds of MB at 1e6 zones —
lived on until Python's cyclic collector happened to run (a FISH loop of `model cycle` commands grew by one
stepper per command)."""
import gc
import io

import dec3d
from dec3d.physics.steps import _Run
from dec3d.physics.zones import ZoneStepper


def _alive(kind):
    # (type(), not isinstance: a dead weak proxy among the objects raises on isinstance)
    return sum(type(o) is kind for o in gc.get_objects())


def test_each_cycle_command_frees_the_previous_run_and_its_zone_stepper(tmp_path):
    s = dec3d.Session(out_dir=tmp_path, stdout=io.StringIO())
    s.command("model new\nblock create brick 0 1 0 1 0 1\nblock zone generate edgelength 0.5\n"
              "block zone cmodel assign elastic\nblock zone property bulk 5e9 shear 3e9 density 2500\n"
              "block create brick 0 1 0 1 1 2\nblock property density 2500\nmodel gravity 0 0 -10\n"
              "block gridpoint apply velocity 0 0 0 range position-z 0\n")
    gc.collect()
    gc.disable()
    try:
        before_runs, before_steppers = _alive(_Run), _alive(ZoneStepper)
        for _ in range(4):
            s.command("model cycle 2")
        # the last command's run only (the engine keeps its steps, ``RigidEngine.steps``), and its stepper
        assert before_runs == 0 and _alive(_Run) == 1
        assert _alive(ZoneStepper) == before_steppers + 1
        assert s.model.rigid_engine.steps[0].run.done == 2
    finally:
        gc.enable()
    assert s.model.step == 8
