"""3DEC 7-9 commands dec3d knows by name, implemented or not.

Binding a command listed here that no module registers gives "`<command>` is not
supported yet" rather than "unknown command". Sources: Itasca's 3DEC 7/9 command
reference as summarised in shared/reference/3dec_command_reference.md (K corpus
and public decks). Implemented commands are registered by their own modules and
take precedence over these names.
"""
from __future__ import annotations

from .registry import REGISTRY, RangeElement
from .values import Num, P, Text

_GROUPS = {
    "model": "calm clean configure creep cycle deterministic domain dynamic energy fluid gravity "
             "history large-strain list mechanical new orientation-tracking precision random range restore "
             "result save solve step thermal title update-interval",
    "program": "call continue directory echo echo-line encrypt exit floating-point-check license list load log "
               "log-file mail notice pause playback quit return system threads undo warning",
    "block": "analyze-stability apply apply-remove attach contact copy create cut delete densify dynamic "
             "excavate export face fill fix fluid fragment free generate gridpoint group hide history import "
             "initialize insitu join join-by-contact contact-persistence list mechanical merge-finish merge-start "
             "property relax result structure thermal to-flac3d to-pfc to-udec tolerance trace vtk zone",
    "block create": "brick drum polyhedron prism tetrahedron tunnel",
    "block cut": "dfn fracture geometry joint-set tunnel",
    "block contact": "apply area-minimum compute-stiffness delete-open generate-subcontacts group group-subcontact "
                     "history jmodel join list material-table persistence property property-distribution "
                     "record-shear reset tolerance vertex-vertex",
    "block contact jmodel": "assign list load",
    "block contact material-table": "add apply default list remove",
    "block face": "apply apply-remove group history initialize list triangulate",
    "block gridpoint": "apply apply-remove fix free group history initialize list trace",
    "block zone": "apply cmodel delete fluid generate generate-new group history initialize list property "
                  "property-distribution thermal",
    "block zone cmodel": "assign list",
    "block mechanical": "damping energy list mass-scale safety-factor timestep timestep-update",
    "feblock": "delete generate gravity group list",
    "fish": "automatic-create callback create debug define history list operator result set trace",
    "history": "delete export interval label list name purge rename results",
    "table": "",
    "geometry": "", "dfn": "", "flowknot": "", "flowplane": "", "structure": "", "data": "", "python-reset": "",
    "zone": "", "fracture": "", "domain": "",
}

#: range elements of 3DEC that dec3d does not implement yet (implemented ones are registered elsewhere)
_RANGE_UNSUPPORTED = ("annulus", "polygon", "rectangle", "ellipse", "named-range", "extra", "fish",
                      "jmodel", "cmodel-name", "by", "extent", "state", "direction", "distance")


def install(registry=REGISTRY) -> None:
    for group, children in _GROUPS.items():
        registry.know(group)
        for c in children.split():
            registry.know(f"{group} {c}")
    # `block create group 'g' poly ...`: group/slot may precede the shape word
    registry.node_keywords("block create", [P("group", Text(), "group name of the new block(s)"),
                                            P("slot", Text(), "group slot"),
                                            P("face-group", Text(), "group of the new faces"),
                                            P("region", Num(integer=True), "3DEC 5 region number, still written by "
                                              "some generators (`r=0`); selected by `range region`")])
    registry.node_keywords("model history", [P("name", Text(), "history name")])
    registry.node_keywords("block history", [P("name", Text(), "history name")])
    # `fish history [name '<s>'] <var>` takes its name itself (commands.fish_cmds): a FISH variable may be called `name`
    # bare top-level forms seen in decks (3DEC accepts them as program commands)
    registry.alias("call", "program call")
    registry.alias("return", "program return")
    registry.alias("log", "program log")
    registry.alias("log-file", "program log-file")
    registry.alias("exit", "program exit")
    registry.alias("quit", "program quit")
    for name in _RANGE_UNSUPPORTED:
        if name not in registry.range_elements:
            registry.add_range_element(RangeElement(name, None, supported=False))
