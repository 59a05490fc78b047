"""The REPL driven through its input: history, completion, help, recovery after an error."""
import contextlib
import io

from prompt_toolkit.document import Document
from prompt_toolkit.input import create_pipe_input
from prompt_toolkit.output import DummyOutput

from dec3d.repl import RegistryCompleter, run_repl


def drive(keys: str, tmp_path, history=None):
    out = io.StringIO()
    with create_pipe_input() as inp, contextlib.redirect_stdout(out):
        inp.send_text(keys)
        inp.close()          # Ctrl-D at the end of the input
        rc = run_repl(out_dir=tmp_path, history_file=history, input=inp, output=DummyOutput())
    return rc, out.getvalue()


def test_error_does_not_end_the_session(tmp_path):
    rc, text = drive("model gravty 0 0 -1\n[a = 4]\n[io.out(string(a*2))]\n", tmp_path)
    assert rc == 0
    assert "unknown command `model gravty`" in text and "^" in text
    assert "\n8\n" in text          # the command after the error ran


def test_help_shows_the_command_page(tmp_path):
    _, text = drive("help model grav\nhelp\nhelp model\n", tmp_path)
    assert "model gravity" in text and "model gravity 0 0 -9.81" in text
    assert "Commands:" in text and "Subcommands:" in text and "gravity" in text


def test_help_is_rendered_not_raw_markdown(tmp_path):
    _, text = drive("help model grav\n", tmp_path)
    text = text.split("\n", 1)[1]                       # after the greeting
    lines = [ln.strip() for ln in text.splitlines()]
    assert "model gravity" in lines                     # the heading, without its `#`
    assert not any(ln.startswith("#") for ln in lines)
    assert "```" not in text and "`" not in text and "|---" not in text and "| g |" not in text
    assert any(ln.startswith("g ") and "m/s²" in ln for ln in lines)   # the table's row, rendered


def test_help_fish_define_says_what_happens(tmp_path):
    _, text = drive("help fish define\nhelp fish def\n", tmp_path)
    assert "does not support" not in text
    assert text.count("compiled when the deck is read") == 2 and "not supported yet" in text


def test_continuation_and_fish_block(tmp_path):
    _, text = drive("model title ...\n'two lines'\nfish define f\n  x = 1\nend\n[io.out('after')]\n", tmp_path)
    assert "error" not in text and "after" in text


def test_history_is_persistent(tmp_path):
    hist = tmp_path / "hist"
    drive("model gravity 0 0 -9.81\n", tmp_path, history=hist)
    assert "model gravity 0 0 -9.81" in hist.read_text()
    # a second session starts with the same history: Up then Enter runs it again
    _, text = drive("\x1b[A\r[io.out('done')]\n", tmp_path, history=hist)
    assert "error" not in text and "done" in text


def test_exit_command_ends_the_session(tmp_path):
    _, text = drive("exit\n[io.out('never')]\n", tmp_path)
    assert "never" not in text


def completions(text):
    return [c.text for c in RegistryCompleter().get_completions(Document(text), None)]


def test_completion_marks_what_does_not_run():
    notes = {c.text: c.display_meta_text for c in RegistryCompleter().get_completions(Document("block "), None)}
    assert notes["copy"] == "not supported yet"
    assert notes["create"] == "" and notes["contact"] == ""
    top = {c.text: c.display_meta_text for c in RegistryCompleter().get_completions(Document(""), None)}
    assert top["plot"] == "" and top["model"] == ""           # plots are pictures (dec3d.plot)
    kws = {c.text: c.display_meta_text for c in RegistryCompleter().get_completions(Document("block history velocity "), None)}
    assert kws["zone-id"] == "" and kws["gridpointid"] == "" and kws["block-id"] == ""
    ckws = {c.text: c.display_meta_text
            for c in RegistryCompleter().get_completions(Document("block contact history force-normal "), None)}
    assert ckws["contact-id"] == "not supported yet" and ckws["position"] == ""
    fish = {c.text: c.display_meta_text for c in RegistryCompleter().get_completions(Document("fish "), None)}
    assert fish["define"] == "FISH function definition" and fish["list"] == "" and fish["callback"] == ""
    assert fish["debug"] == "not supported yet"


def test_completion_of_words_and_keywords():
    assert completions("mo") == ["model"]
    assert "gravity" in completions("model g") and "large-strain" in completions("model ")
    assert completions("prog log-file 'x' ap") == ["append"]
    assert completions("model configure dy") == ["dynamic"]
    assert "gravity" in completions("help model gr")
