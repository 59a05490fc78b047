"""Host files of the joint models, one per model (``<name>.py``, same name as its kernel in
``dec3d/kernels/joints``); each calls ``physics.jmodels.jmodel`` once. ``physics.jmodels`` imports
every file found here."""
