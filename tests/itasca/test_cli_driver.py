"""`dec3d run script.py` (a Python driver with `import itasca` bound to a fresh model, under the output
folder rules of decks) and decks calling Python files (refused unless --allow-python)."""
import sys

import pytest

from dec3d.cli import main

DRIVER = '''import itasca as it
from itasca import blockarray as ba
import itasca.block.contact
from it_fixture import fresh_it  # noqa: F401  (autouse: no model bound, a fresh working folder)

it.command("python-reset-state false")
it.command("""
model new
block create brick 0 1 0 1 0 1
block create brick 0 1 0 1 1 2
block property density 2000
block contact jmodel assign mohr
block contact property stiffness-normal 1e9 ...
    stiffness-shear 1e9 friction 30
model gravity 0 0 -10
block fix range position-z 0 0.5
""")
steps = []
def record(*args):
    steps.append(it.step())
it.set_callback("record", 1.0)
it.cycle(50)
c = list(it.block.contact.list())[0]
print("RESULT", len(steps), round(c.force_norm()), ba.pos().shape, itasca.block.contact is it.block.contact)
it.command("model save 'state.sav'")
'''


@pytest.fixture
def folder(tmp_path):
    (tmp_path / "drv.py").write_text(DRIVER)
    return tmp_path


def test_run_a_python_driver_into_the_output_folder(folder, capsys):
    out = folder / "out"
    assert main(["run", str(folder / "drv.py"), "--out", str(out), "-q"]) == 0
    text = capsys.readouterr().out
    assert "RESULT 50 19999 (2, 3) True" in text
    assert (out / "state.sav").exists() and not (folder / "state.sav").exists()
    # the default output folder is the script's
    assert main(["run", str(folder / "drv.py"), "-q"]) == 0
    assert (folder / "state.sav").exists()
    assert "itasca" not in sys.modules or sys.modules["itasca"].__name__ == "dec3d.itasca"


def test_a_deck_calling_python_is_refused_unless_allowed(folder, capsys):
    deck = folder / "deck.dat"
    deck.write_text("model new\nprogram call 'drv.py'\n")
    assert main(["run", str(deck), "--out", str(folder / "o"), "-q"]) == 2
    err = capsys.readouterr().err
    assert f"{deck}:2:1: error: `drv.py` is a Python file" in err and "--allow-python" in err
    assert "nothing was run" in err
    assert not (folder / "o" / "state.sav").exists()
    assert main(["run", str(deck), "--out", str(folder / "o"), "-q", "--allow-python"]) == 0
    assert "RESULT 50 19999" in capsys.readouterr().out
    assert (folder / "o" / "state.sav").exists()


def test_a_failing_command_or_syntax_error_in_a_driver(folder, capsys):
    bad = folder / "bad.py"
    bad.write_text('import itasca as it\nit.command("""\nmodel new\nblock frobnicate 3\n""")\n')
    assert main(["run", str(bad), "-q"]) == 1
    err = capsys.readouterr().err
    # the error points into the script: the line of the bad command inside the triple-quoted text
    assert f"{bad}:2: it.command failed" in err and f"{bad}:4:7: error: unknown command `block frobnicate`" in err
    one = folder / "one.py"
    one.write_text('import itasca as it\nx = 1\nit.command("block frobnicate 3")\nit.command("model " + "nw")\n')
    assert main(["run", str(one), "-q"]) == 1
    assert f"{one}:3:19: error: unknown command `block frobnicate`" in capsys.readouterr().err
    one.write_text('import itasca as it\nit.command("model " + "nw")\n')
    assert main(["run", str(one), "-q"]) == 1
    assert "<command>:1:7: error:" in capsys.readouterr().err        # a text built at run time: its own lines
    syn = folder / "syn.py"
    syn.write_text("import itasca as it\nit.command('model new'\n")
    assert main(["run", str(syn), "-q"]) == 2
    err = capsys.readouterr().err
    assert f"{syn}:2:" in err and "nothing was run" in err
    boom = folder / "boom.py"
    boom.write_text("import itasca as it\n\ndef f():\n    return 1 / 0\n\nf()\n")
    assert main(["run", str(boom), "-q"]) == 1
    err = capsys.readouterr().err
    assert "ZeroDivisionError" in err and 'boom.py", line 4, in f' in err and "dec3d/cli.py" not in err
    # a callback's error: the user's callback frame, then the script line that cycled; no dec3d frames
    cb = folder / "cb.py"
    cb.write_text('import itasca as it\nit.command("block create brick 0 1 0 1 0 1\\nblock property density 1000")\n\ndef watch():\n'
                  '    if it.step() == 3:\n        raise RuntimeError("stop here")\n\n'
                  'it.set_callback(watch, 1.0)\nit.cycle(10)\n')
    assert main(["run", str(cb), "-q"]) == 1
    err = capsys.readouterr().err
    assert 'cb.py", line 6, in watch' in err and 'cb.py", line 9, in <module>' in err
    assert "raised at step 3: RuntimeError: stop here" in err and "dec3d/physics" not in err and "runpy" not in err
    # an error in a Python file a deck calls stops the deck at the call
    deck = folder / "d.dat"
    deck.write_text("model new\ncall 'boom.py'\n")
    assert main(["run", str(deck), "-q", "--allow-python"]) == 1
    err = capsys.readouterr().err
    assert f"{deck}:2:1: error: the Python file `boom.py` raised ZeroDivisionError" in err and "(line 4:" in err


def test_the_top_level_itasca_shim_is_dec3d_itasca():
    import dec3d.itasca
    import itasca
    from itasca import blockarray

    assert itasca is dec3d.itasca and blockarray is dec3d.itasca.blockarray
    import itasca.block.contact as c

    assert c is dec3d.itasca.block.contact


STYLE = '''import itasca as it
import os
import numpy as np

it.command("python-reset-state false")
it.command("program automatic-model-save active off")
os.makedirs("tables", exist_ok=True)                      # the script's own files: beside it
with open(os.path.join("tables", "pulse.txt"), "w") as f:
    f.write("pulse\\n3\\t0\\n0 0\\n1 2\\n2 0\\n")
spacing = np.loadtxt("spacing.csv")                       # a sibling input, read by Python
it.command("call 'geometry.dat'")                          # a sibling deck, read by dec3d
it.command("table 'p' import 'tables/pulse.txt'")
it.command("""
fish define top_z
    top_z = block.pos.z(2)
end
[height = top_z + {sp}]
""".format(sp=float(spacing)))
print("HEIGHT", it.fish.get("height"), it.block.count())
'''


def test_a_driver_in_the_style_of_public_3dec_scripts(tmp_path, capsys):
    (tmp_path / "style.py").write_text(STYLE)
    (tmp_path / "spacing.csv").write_text("0.25\n")
    (tmp_path / "geometry.dat").write_text("block create brick 0 1 0 1 0 1\nblock create brick 0 1 0 1 1 2\n")
    out = tmp_path / "results"
    assert main(["run", str(tmp_path / "style.py"), "--out", str(out), "-q"]) == 0
    assert "HEIGHT 1.75 2" in capsys.readouterr().out
    assert (tmp_path / "tables" / "pulse.txt").exists()
    bad = tmp_path / "auto.py"
    bad.write_text('import itasca as it\nit.command("program automatic-model-save active on")\n')
    assert main(["run", str(bad), "-q"]) == 1
    assert "automatic-model-save active on` is not supported" in capsys.readouterr().err


STUDY = '''import dec3d
import itasca as it

for phi in (20, 40):
    m = dec3d.Model(out_dir="runs/phi%d" % phi)
    with m.bound():
        it.command("block create brick 0 1 0 1 0 1")
        it.command("model save 'end.sav'")
it.command("model save 'main.sav'")
'''


def test_models_a_driver_makes_write_under_the_runs_output_folder(tmp_path):
    (tmp_path / "study.py").write_text(STUDY)
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "study.py"), "--out", str(out), "-q"]) == 0
    assert (out / "runs" / "phi20" / "end.sav").exists() and (out / "runs" / "phi40" / "end.sav").exists()
    assert (out / "main.sav").exists() and not (tmp_path / "runs").exists()


def test_dec3d_check_names_python_files(folder, capsys):
    deck = folder / "deck.dat"
    deck.write_text("model new\nprogram call 'drv.py'\n")
    assert main(["check", str(deck)]) == 1
    out = capsys.readouterr().out
    assert "deck.dat:2:1: error: `drv.py` is a Python file" in out and "--allow-python" in out
    assert main(["check", str(folder / "drv.py")]) == 2
    assert "is a Python driver, not a deck" in capsys.readouterr().err
