"""`model budget`: how many blocks (and bytes) a command may make before it is refused.

Commands that can make blocks in numbers the deck does not state directly (a joint set
with a small spacing, a tunnel with many rings) estimate what they will make before doing
any work, and refuse with the estimate when it is over the budget; nothing is changed.
The budget belongs to the session (`model new` keeps it) and is raised or lowered by
`model budget`. Expressions have fixed limits of their own (`dec3d.fish.values`).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import ResourceError
from .registry import command
from .values import Num, P

#: bytes a block costs at the peak of a cut (measured: 100 000 blocks from a 10 m cube cut by
#: three joint sets took 0.47 GB above the starting process, ~4.7 KB each; rounded up)
BYTES_PER_BLOCK = 5 * 1024
GIB = 1024 ** 3


@dataclass
class Budget:
    blocks: int = 1_000_000
    memory_gib: float = 4.0

    def max_blocks(self) -> int:
        """Blocks allowed by both limits."""
        return min(self.blocks, int(self.memory_gib * GIB / BYTES_PER_BLOCK))


def budget(session) -> Budget:
    """The session's budget (the default until `model budget` changes it)."""
    b = getattr(session, "budget", None)
    if not isinstance(b, Budget):
        b = Budget()
        session.budget = b
    return b


def check_blocks(session, new: int, what: str, where) -> None:
    """Refuse a command that would make `new` blocks when the model's blocks and they exceed the budget."""
    b = budget(session)
    have = int(session.model.blocks.n)
    total = have + int(new)
    if total <= b.max_blocks():
        return
    gib = total * BYTES_PER_BLOCK / GIB
    raise ResourceError(
        f"{what} would make about {_count(new)} new blocks ({_count(total)} in all, about {_count(gib)} GiB); "
        f"the budget allows {b.blocks:,} blocks and {b.memory_gib:g} GiB", where,
        hint="raise it with `model budget blocks <n> memory <GiB>` if the machine has the memory")


def _count(n) -> str:
    """1,234,567 up to a billion; 1.23e+12 beyond (an estimate has no more digits than that)."""
    if n >= 1e9:
        return f"{float(n):.3g}"
    return f"{n:,.1f}" if isinstance(n, float) else f"{n:,}"


@command("model budget",
         keywords=[P("blocks", Num(integer=True, lo=1, hi=1e12), "largest number of blocks a command may leave",
                     default=None),
                   P("memory", Num(lo=0, lo_open=True, hi=2**20), "memory the blocks may take, GiB "
                     f"(estimated at {BYTES_PER_BLOCK // 1024} KiB a block)", default=None, units="GiB")],
         doc="Set the budget that commands making many blocks are checked against (dec3d).",
         details="`block cut joint-set` and `block create tunnel` work out how many blocks they would make "
                 "before doing any work and stop with the estimate when the model would hold more than "
                 f"`blocks` blocks (default {Budget.blocks:,}) or the blocks would take more than `memory` GiB "
                 f"(default {Budget.memory_gib:g}, at {BYTES_PER_BLOCK // 1024} KiB a block). The budget "
                 "belongs to the session: `model new` keeps it. Without keywords it prints the budget. "
                 "Inline expressions have fixed limits: integers of 64 bits, strings of 1 000 000 "
                 "characters, finite reals.",
         examples=["model budget blocks 5000000 memory 16", "model budget"])
def model_budget(session, call):
    b = budget(session)
    if call.args["blocks"] is not None:
        b.blocks = int(call.args["blocks"])
    if call.args["memory"] is not None:
        b.memory_gib = float(call.args["memory"])
    session.write(f"budget: {b.blocks:,} blocks, {b.memory_gib:g} GiB (at most {b.max_blocks():,} blocks)")
