"""The stores of the rigid engine's contacts and sub-contacts: their fields (what a contact and a
sub-contact keep, saved with the model), making them (``contact_stores``, which also brings a store
restored from an older save up to today's fields) and the width of the joint models' history
(``history_columns``) and of their property rows (``property_columns``). Detection itself: ``physics.contacts``."""
from __future__ import annotations

import numpy as np

from dec3d.kernels.joints import COMMON_MODELS, HISTORY_MODELS, NJHIST, model_mask, prop_width
from dec3d.model.groups import group_field
from dec3d.model.store import Field, Store

_F = np.float64
_I = np.int64

CONTACT_FIELDS = {
    "ida": Field((), _I, -1),            # block ids, A < B
    "idb": Field((), _I, -1),
    "a": Field((), _I, -1),              # block rows (refreshed at every detection)
    "b": Field((), _I, -1),
    "pos": Field((3,), _F, 0.0),         # c-p reference point [m]
    "normal": Field((3,), _F, 0.0),      # unit normal A → B
    "gap": Field((), _F, 0.0),           # [m], negative = overlap
    "type": Field((), _I, 0),            # CT_* (kernels.commonplane)
    "jmodel": Field((), _I, 1),          # joint model code (physics.jmodels)
    # kernel property row: as many columns as the joint models in use read (``property_columns``)
    "prop": Field((prop_width(COMMON_MODELS),), _F, 0.0),
    "own_props": Field((), np.uint8, 0), # 1: set by `block contact property`; 0: follows the defaults
    "sub_start": Field((), _I, 0),       # CSR into subcontacts
    "sub_count": Field((), _I, 0),
    # on a zoned (deformable) side: the gridpoints of the surface triangle the point moves with
    # and its interpolation weights (set at detection by gpcontact.surface_weights; -1: rigid side)
    "gp_a": Field((3,), _I, -1),
    "gw_a": Field((3,), _F, 0.0),
    "gp_b": Field((3,), _I, -1),
    "gw_b": Field((3,), _F, 0.0),
    "group": group_field(),
    # when the contact was last computed: its blocks' centroids [m] and turns (block field ``turn``) [m]
    "ref_ca": Field((3,), _F, 0.0),
    "ref_cb": Field((3,), _F, 0.0),
    "ref_ta": Field((), _F, 0.0),
    "ref_tb": Field((), _F, 0.0),
    # pore pressure given by `block contact apply pore-pressure` (summed) [Pa] (physics.water)
    "pp_apply": Field((), _F, 0.0),
}

SUBCONTACT_FIELDS = {
    "contact": Field((), _I, -1),
    "kind": Field((), _I, 0),            # 0 A-vertex/B-face, 1 B-vertex/A-face, 2 edge-edge, 3 point
    "key0": Field((), _I, -1),
    "key1": Field((), _I, -1),
    "pos": Field((3,), _F, 0.0),         # on the c-p [m]
    "area": Field((), _F, 0.0),          # [m²]
    "fn": Field((), _F, 0.0),            # normal force, compression positive [N]
    "fs": Field((3,), _F, 0.0),          # shear force on B [N]
    "un": Field((), _F, 0.0),            # normal displacement (starts at the gap) [m]
    "udil": Field((), _F, 0.0),          # dilation [m]
    "us": Field((3,), _F, 0.0),          # accumulated shear displacement [m]
    "state": Field((), _I, 0),           # ST_* bits (kernels.jointlaw)
    # the joint models' own history (kernels.joints: a model's first NHIST columns): NJHIST columns while a
    # contact's model keeps one, none otherwise (``history_columns``: a mohr-only model carries nothing)
    "hist": Field((0,), _F, 0.0),
    # on a zoned (deformable) side: the gridpoints of the surface triangle the point moves with
    # and its interpolation weights (set at detection by gpcontact.surface_weights; -1: rigid side)
    "gp_a": Field((3,), _I, -1),
    "gw_a": Field((3,), _F, 0.0),
    "gp_b": Field((3,), _I, -1),
    "gw_b": Field((3,), _F, 0.0),
    # pore pressure [Pa], positive pushes the blocks apart; worked out from its sources (physics.water)
    "pp": Field((), _F, 0.0),
    # its force p·A' [N] on the faces (A' from ``kernels.water.pressure_areas``), what the cycle applies
    "ppf": Field((), _F, 0.0),
}


def contact_stores(model) -> tuple[Store, Store]:
    """The ``contacts`` and ``subcontacts`` stores, made on first use, with the detection bookkeeping
    fields of vertices (``map_pos``, ``look_pos``, ``turn_pos``), blocks (``map_reach``, ``turn[_cen]``)."""
    stores = model.stores
    if "contacts" not in stores:
        model.add_store(Store("contacts", CONTACT_FIELDS, capacity=64))
    if "subcontacts" not in stores:
        model.add_store(Store("subcontacts", SUBCONTACT_FIELDS, capacity=256))
    # a model restored from an older save: fields added since (the joint models' ``hist``) start at
    # their fill value; the property rows are as wide as its contacts' models read (saves before
    # issue 27 had 10 columns, saves of its first version one column per property of the widest model)
    for store, fields in ((model.store("contacts"), CONTACT_FIELDS), (model.store("subcontacts"), SUBCONTACT_FIELDS)):
        for key, fld in fields.items():
            if key not in store:
                store.add_field(key, fld)
    cs = model.store("contacts")
    property_columns(cs, model_mask(cs["jmodel"]))
    for key in ("map_pos", "look_pos", "turn_pos"):
        if key not in model.vertices:
            model.vertices.add_field(key, Field((3,), _F, 0.0))
    for key, shape in (("map_reach", ()), ("turn", ()), ("turn_cen", (3,))):
        if key not in model.blocks:
            model.blocks.add_field(key, Field(shape, _F, 0.0))
    return model.store("contacts"), model.store("subcontacts")


def history_columns(ss, codes) -> None:
    """Give the sub-contacts' ``hist`` NJHIST columns when one of the joint-model ``codes`` (an int
    array) keeps a history, none otherwise (the columns are zero when added; dropping them loses
    nothing: only those models write them). Called by detection, by the commands that change
    contacts' models and before every run."""
    width = NJHIST if model_mask(np.asarray(codes, dtype=np.int64)) & HISTORY_MODELS else 0
    if ss.fields["hist"].shape != (width,):
        ss.resize_field("hist", (width,))


def property_columns(cs, mask: int) -> int:
    """Give the contacts' ``prop`` the columns the joint models of the bit ``mask`` read
    (``kernels.joints.prop_width``) and return that width. A column dropped is one no contact's
    model reads (the mask must hold the model of every contact kept); a column added is zero.
    Called by detection (the models of the contacts it makes), by the commands that change
    contacts' models, and when a model is restored."""
    width = prop_width(mask)
    if cs.fields["prop"].shape != (width,):
        cs.resize_field("prop", (width,))
    return width
